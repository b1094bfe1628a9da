#pragma once
// Config: the flat key -> value settings of one command, from a scene file (TOML) and then
// `--set KEY=VALUE` overrides, applied in order. Typed getters validate and name the key and
// the value in every error (BadInput, exit status 2). Every key read is marked; keys nobody
// read are reported as unknown by check_all_used(). Every read also records the key with the
// default the reader fell back to (reads()): that record is the one source of which keys a
// command reads, for its --help, for the unknown-key message and for the effective defaults in
// result metadata (scene/commands/key_registry.hpp, metadata.hpp).
//
// Scene files: top-level `key = value` pairs; tables ([model], [floquet], ...) may group keys
// for readability and are flattened (a key may appear only once in the whole file). The one
// exception is [equations] (model = equations, equation_model.hpp): kept whole, as the TOML text
// of the table under the key `equations`.
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "scene/keys/closest_key.hpp"
#include "scene/keys/key_index.hpp"

namespace delayspec::cli {

class Config {
 public:
  // Parses a TOML scene file; BadInput when it cannot be read or parsed.
  static Config from_scene_file(const std::string& path);
  // Parses TOML text; `name` stands for the file in messages. BadInput when it cannot be parsed.
  static Config from_scene_text(const std::string& text, const std::string& name);
  // A scene already parsed (the Python module's dict scenes): flattened as a file's.
  static Config from_scene_table(const toml::table& table, const std::string& name);

  // Applies "KEY=VALUE" (BadInput when there is no '=' or the key is empty).
  void set_from_assignment(const std::string& assignment);
  void set(const std::string& key, const std::string& value, const std::string& origin);
  // A value read from the scene file `path`: a key of another command there is not an error
  // (check_all_used), since a scene is shared by the commands.
  void set_from_scene(const std::string& key, const std::string& value, const std::string& path);

  // Whether the key is given. Also records the key as read (without a default): a command that
  // asks knows the key.
  bool has(const std::string& key) const;
  // Where the key's value came from: the scene file's path, "--set", or a command that set it.
  const std::string& origin(const std::string& key) const { return origin_.at(key); }
  // Whether the key's value comes from a scene (file, text or table) and no --set replaced it.
  bool from_scene(const std::string& key) const { return scene_keys_.count(key) > 0; }
  double get_double(const std::string& key, double fallback);
  double require_double(const std::string& key);
  long get_int(const std::string& key, long fallback);
  // An integer that must lie in [lo, hi], checked on the parsed value before any narrowing cast
  // (so `4294967298` is rejected, not wrapped to 2): BadInput "`key = v`: must be between lo and hi".
  long get_int_in_range(const std::string& key, long fallback, long lo, long hi);
  std::string get_string(const std::string& key, const std::string& fallback);
  // A value that must be one of `allowed`.
  std::string get_choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed);
  // A value that names one of `choices` (the key's words, in the order messages and --help list
  // them), as the enum it stands for; the fallback's word is the default. BadInput as get_choice.
  template <class E>
  E get_enum(const std::string& key, E fallback, const std::vector<std::pair<std::string, E>>& choices) {
    std::string fallback_word;
    std::vector<std::string> words;
    for (const auto& [word, value] : choices) {
      words.push_back(word);
      if (value == fallback && fallback_word.empty()) fallback_word = word;
    }
    const std::string word = get_choice(key, fallback_word, words);
    for (const auto& [w, value] : choices)
      if (w == word) return value;
    return fallback;  // (not reached: get_choice accepted one of the words)
  }
  // An on/off key (error_bars, ...): true for "on".
  bool get_switch(const std::string& key, bool fallback) {
    return get_enum<bool>(key, fallback, {{"on", true}, {"off", false}});
  }
  std::vector<long> get_int_list(const std::string& key, const std::vector<long>& fallback);
  // A list of finite numbers ("1, 2.5" or a TOML array); empty when the key is absent
  // (fallback_text: what is used then, for --help).
  std::vector<double> get_double_list(const std::string& key, const std::string& fallback_text);

  // Marks a key as known without reading it (e.g. keys of another command in a shared scene).
  void mark_used(const std::string& key);
  // BadInput naming the first key that was given but never read (unread_key_message in
  // key_index.hpp): a key some command or model reads is "not read by READER"; any other gets
  // a did-you-mean, the closest key read so far, else the closest known key (closest_key()).
  void check_all_used() const;

  // Which command reads which key, given by the command runner (run_command, from the key
  // registry): the key store calls no command. Without one (a Config used on its own), every key
  // nobody read is unknown. Given as the function that builds it once per process, called only
  // when a key is asked about: the registry probes every command with every model (some 2 ms),
  // which a run whose keys are all read never needs.
  using KeyIndexSource = const KeyIndex& (*)();
  void set_key_index(KeyIndexSource index) { key_index_ = index; }
  const KeyIndex& key_index() const;

  // Keys read (or marked) so far.
  const std::set<std::string>& used_keys() const { return used_; }

  // One key a getter or has() asked for, in the order of the first request: `fallback` is the
  // default the getter fell back to (as text), or none when the key was given or only asked
  // about with has() / require_double().
  // `value`: the value a typed getter used, in the canonical spelling of effective_values()
  // (none after has() / mark-only reads). One record serves the key registry, the effective
  // defaults and the effective settings.
  struct Read {
    std::string key;
    std::optional<std::string> fallback;
    std::optional<std::string> value;
  };
  const std::vector<Read>& reads() const { return reads_; }
  // Keys read but not given, with the default used: the effective defaults of a run.
  std::map<std::string, std::string> effective_defaults() const;

  // The command reading this Config, for messages ("`nev` is not read by lyapunov").
  void set_reader(const std::string& command) { reader_ = command; }
  const std::string& reader() const { return reader_; }

  // Key collection for `delayspec run`: a scene validated before any analysis computes. When
  // on, check_all_used() throws KeysCollected (carrying the keys read so far) instead of
  // checking, which stops the command right before its heavy work.
  void collect_keys_only(bool on) { collect_keys_only_ = on; }

  // All key/value pairs, for metadata in outputs.
  const std::map<std::string, std::string>& values() const { return values_; }

  // The effective settings: every key read by a typed getter so far, with the value the command
  // used in one canonical spelling (numbers as the shortest text that reads back exactly, lists
  // joined by ","), the fallback included when the key was not given. `b = -2.0` and `b = -2`,
  // or a key stated at its default and the same key left out, give the same map: what --resume
  // compares.
  std::map<std::string, std::string> effective_values() const;

 private:
  std::optional<std::string> lookup(const std::string& key);
  // Records a read of `key`; `fallback` when the key is absent and the getter has a default.
  Read& note_read(const std::string& key, const std::optional<std::string>& fallback) const;
  // Records the value a typed getter used for `key` (canonical spelling).
  void note_value(const std::string& key, const std::string& value);
  std::map<std::string, std::string> values_;
  std::map<std::string, std::string> origin_;
  std::set<std::string> scene_keys_;  // keys whose value comes from the scene file (not overridden)
  mutable std::set<std::string> used_;
  mutable std::vector<Read> reads_;
  std::string reader_;
  bool collect_keys_only_ = false;
  KeyIndexSource key_index_ = nullptr;
};

// "a, b,,c" -> {"a", "b", "", "c"}: a list value's items, split at commas and trimmed of blanks
// (empty items kept: each reader says what it makes of them). The one splitting of a list key.
std::vector<std::string> split_items(const std::string& text);

// Thrown by check_all_used() in key-collection mode (not an error: not derived from
// std::exception so that no error handler mistakes it for one).
struct KeysCollected {
  std::set<std::string> keys;
};

}  // namespace delayspec::cli
