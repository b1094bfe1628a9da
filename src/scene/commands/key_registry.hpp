#pragma once
// Which keys each command reads, with their defaults, found by running the command itself in
// key-collection mode (Config::collect_keys_only) for every model: Config records each key a
// getter asks for and the default it falls back to (Config::reads()), so this registry cannot
// drift from the code. It serves `delayspec COMMAND --help`, the unknown-key message ("`nev` is
// not read by lyapunov" for a key of another command, a did-you-mean for a misspelt one), and
// `run`, which finds the command a scene without `analyses` belongs to.
//
// The only hand-kept part is the one-line meaning of each key (key_meanings()); a test checks
// that every key some command reads has one and that no meaning is left for a key nobody reads.
#include <map>
#include <set>
#include <string>
#include <vector>

#include "scene/keys/config.hpp"
#include "scene/keys/key_index.hpp"
#include "scene/commands/commands.hpp"

namespace delayspec::cli {

// What `command` reads given `config` (its scene and --set values), found by running it in
// key-collection mode: it stops right before its work (Config::check_all_used).
struct Probe {
  std::vector<Config::Read> reads;  // the keys read, with their defaults (Config::reads())
  std::set<std::string> keys;       // the keys read or marked as its own (Config::used_keys())
};
// A BadInput the command raises while validating (e.g. chart's default axes with a model that
// lacks them) either ends the probe, with what was read up to there (the key registry), or is
// rethrown (`run`, which validates a scene before any analysis computes).
enum class OnBadInput { stop, rethrow };
Probe probe_command(const std::string& command, Config config, OnBadInput on_bad_input = OnBadInput::stop);

// Which command reads which key with which models (key_index.hpp): run_command gives it to the
// Config, which knows no command.
const KeyIndex& key_index();

// One line per key: what it means (with its unit or range where that helps).
const std::map<std::string, std::string>& key_meanings();

// The keys `command` reads, its defaults and their meanings (the tail of `COMMAND --help`):
// keys every model shares first, then the keys of each model. BadInput naming the command and
// listing the commands when it is not one (command_spec).
std::string command_keys_help(const std::string& command);

}  // namespace delayspec::cli
