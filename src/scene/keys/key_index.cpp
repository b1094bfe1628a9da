#include "scene/keys/key_index.hpp"

#include <cctype>

#include "scene/keys/closest_key.hpp"

namespace delayspec::cli {

std::string join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : sep) + item;
  return out;
}

std::string unread_key_message(const KeyIndex& index, const std::string& key, const std::string& value_note,
                               const std::vector<std::string>& readers, const std::string& model,
                               const std::set<std::string>& read_keys) {
  const auto known = index.readers.find(key);
  if (known == index.readers.end()) {
    // The closest key this command reads, else the closest key of any command.
    std::string suggestion = closest_key(key, std::vector<std::string>(read_keys.begin(), read_keys.end()));
    if (suggestion.empty()) {
      std::vector<std::string> all;
      for (const auto& [k, by] : index.readers) all.push_back(k);
      suggestion = closest_key(key, all);
    }
    return "unknown key `" + key + "` " + value_note +
           (suggestion.empty() ? "" : "; did you mean `" + suggestion + "`?");
  }
  // A key of another command or model: say so, not a did-you-mean to a different key; only a
  // key differing in case from one this command reads (`n` for `N`) gets a suggestion.
  const std::string model_name = model.empty() ? (index.models.empty() ? std::string() : index.models.front()) : model;
  std::string message = "`" + key + "` " + value_note + " is not read by " +
                        (readers.empty() ? std::string("this command") : join(readers, ", "));
  std::set<std::string> other_models;
  for (const auto& reader : readers)
    if (auto it = known->second.find(reader); it != known->second.end())
      other_models.insert(it->second.begin(), it->second.end());
  if (!other_models.empty()) {
    message += " with model = " + model_name +
               " (only with model = " + join(std::vector<std::string>(other_models.begin(), other_models.end()), ", ") +
               ")";
  } else {
    std::vector<std::string> commands;
    for (const auto& [command, models] : known->second) commands.push_back(command);
    message += " (it is a key of " + join(commands, ", ") + ")";
  }
  auto lower = [](std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  };
  std::vector<std::string> same_case(read_keys.begin(), read_keys.end());
  for (const auto& [k, by] : index.readers) same_case.push_back(k);
  std::erase_if(same_case, [&](const std::string& k) { return k == key || lower(k) != lower(key); });
  if (!same_case.empty()) message += "; did you mean `" + same_case.front() + "`?";
  if (readers.size() == 1) message += "; `delayspec " + readers.front() + " --help` lists the keys it reads";
  return message;
}

std::vector<std::string> keys_of_every_model(const KeyIndex& index) {
  std::vector<std::string> keys;
  for (const auto& [key, by_command] : index.readers)
    for (const auto& [command, models] : by_command)
      if (models.size() == index.models.size()) {
        keys.push_back(key);
        break;
      }
  return keys;
}

}  // namespace delayspec::cli
