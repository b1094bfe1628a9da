#include "config.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <toml++/toml.h>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

// TOML value -> the string spelling --set would use.
std::string to_text(const toml::node& node, const std::string& key, const std::string& path) {
  if (auto v = node.value<std::string>(); v && node.is_string()) return *v;
  if (node.is_integer()) return std::to_string(*node.value<int64_t>());
  if (node.is_floating_point()) return format_number(*node.value<double>());
  if (node.is_boolean()) return *node.value<bool>() ? "true" : "false";
  if (const toml::array* arr = node.as_array()) {
    std::string out;
    for (const auto& element : *arr) {
      if (!out.empty()) out += ",";
      out += to_text(element, key, path);
    }
    return out;
  }
  throw BadInput(path + ": key `" + key + "` has a value of an unsupported type");
}

void flatten(const toml::table& table, Config& config, const std::string& path, std::set<std::string>& seen) {
  for (const auto& [k, node] : table) {
    const std::string key(k.str());
    if (const toml::table* sub = node.as_table()) {
      flatten(*sub, config, path, seen);
      continue;
    }
    if (!seen.insert(key).second) throw BadInput(path + ": key `" + key + "` is given twice");
    config.set(key, to_text(node, key, path), path);
  }
}

}  // namespace

Config Config::from_scene_file(const std::string& path) {
  Config config;
  try {
    toml::table table = toml::parse_file(path);
    std::set<std::string> seen;
    flatten(table, config, path, seen);
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << "scene `" << path << "`: " << e.description();
    if (e.source().begin) msg << " (line " << e.source().begin.line << ", column " << e.source().begin.column << ")";
    throw BadInput(msg.str());
  }
  return config;
}

void Config::set_from_assignment(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos) throw BadInput("`--set " + assignment + "`: expected KEY=VALUE");
  const std::string key = trim(assignment.substr(0, eq));
  if (key.empty()) throw BadInput("`--set " + assignment + "`: the key is empty");
  set(key, trim(assignment.substr(eq + 1)), "--set");
}

void Config::set(const std::string& key, const std::string& value, const std::string& origin) {
  values_[key] = value;
  origin_[key] = origin;
}

bool Config::has(const std::string& key) const { return values_.count(key) > 0; }

std::optional<std::string> Config::lookup(const std::string& key) {
  used_.insert(key);
  auto it = values_.find(key);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

void Config::mark_used(const std::string& key) { used_.insert(key); }

double Config::get_double(const std::string& key, double fallback) {
  auto text = lookup(key);
  if (!text) return fallback;
  const std::string& s = *text;
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE)
    throw BadInput("`" + key + " = " + s + "`: not a number");
  if (!std::isfinite(value)) throw BadInput("`" + key + " = " + s + "`: must be a finite number");
  return value;
}

double Config::require_double(const std::string& key) {
  if (!has(key)) throw BadInput("missing key `" + key + "`");
  return get_double(key, 0);
}

long Config::get_int(const std::string& key, long fallback) {
  auto text = lookup(key);
  if (!text) return fallback;
  const std::string& s = *text;
  errno = 0;
  char* end = nullptr;
  const long value = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE)
    throw BadInput("`" + key + " = " + s + "`: not an integer");
  return value;
}

std::string Config::get_string(const std::string& key, const std::string& fallback) {
  auto text = lookup(key);
  return text ? *text : fallback;
}

std::string Config::get_choice(const std::string& key, const std::string& fallback,
                               const std::vector<std::string>& allowed) {
  const std::string value = get_string(key, fallback);
  for (const auto& a : allowed)
    if (a == value) return value;
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  throw BadInput("`" + key + " = " + value + "`: must be one of " + list);
}

std::vector<long> Config::get_int_list(const std::string& key, const std::vector<long>& fallback) {
  auto text = lookup(key);
  if (!text) return fallback;
  std::vector<long> out;
  std::stringstream ss(*text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = trim(item);
    errno = 0;
    char* end = nullptr;
    const long value = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || end != item.c_str() + item.size() || errno == ERANGE)
      throw BadInput("`" + key + " = " + *text + "`: `" + item + "` is not an integer");
    out.push_back(value);
  }
  if (out.empty()) throw BadInput("`" + key + " = " + *text + "`: empty list");
  return out;
}

void Config::check_all_used() const {
  for (const auto& [key, value] : values_)
    if (!used_.count(key))
      throw BadInput("unknown key `" + key + "` (= " + value + ", from " + origin_.at(key) + ")");
}

}  // namespace delayspec::cli
