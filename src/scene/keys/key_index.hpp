#pragma once
// What the key store knows of the commands: which command reads which key with which models.
// The key registry (scene/commands/key_registry.hpp) finds it by probing the commands from above
// and the command runner hands it to the Config (Config::set_key_index); the key store itself
// calls no command. It serves the unknown-key message and the names an equation model may not
// give its parameters.
#include <map>
#include <set>
#include <string>
#include <vector>

namespace delayspec::cli {

// "a, b, c": the items joined by `sep`.
std::string join(const std::vector<std::string>& items, const std::string& sep);

struct KeyIndex {
  // For every key some command reads: command -> the models with which it reads the key.
  std::map<std::string, std::map<std::string, std::set<std::string>>> readers;
  std::vector<std::string> models;  // the built-in models, the default first
};

// The message for a given key nobody read. `readers`: the commands that read the Config (empty:
// unknown); `model`: the model given ("" = the default). A key some command reads is "not read
// by READERS" (naming who reads it); any other key is "unknown", with a did-you-mean among
// `read_keys` and every known key.
std::string unread_key_message(const KeyIndex& index, const std::string& key, const std::string& value_note,
                               const std::vector<std::string>& readers, const std::string& model,
                               const std::set<std::string>& read_keys);

// The keys the engine reads whatever the model (N, nev, seed, ...): read by some command with
// every built-in model.
std::vector<std::string> keys_of_every_model(const KeyIndex& index);

}  // namespace delayspec::cli
