#include "scene/keys/config.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <toml++/toml.h>

#include "delayspec/errors.hpp"
#include "delayspec/printable.hpp"

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
      // Joined by commas, [[25], [50]] would read as [25, 50]: a list key's value is a flat list.
      if (element.is_array() || element.is_table())
        throw BadInput(path + ": key `" + key + "` is a nested array (an array or table inside its array); give a flat "
                       "list of numbers, strings or booleans");
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
      if (key == "equations") {  // a model's equations: kept whole, as TOML text (equation_model.hpp)
        if (!seen.insert(key).second) throw BadInput(path + ": key `" + key + "` is given twice");
        std::ostringstream text;
        text << *sub;
        config.set_from_scene(key, text.str(), path);
        continue;
      }
      flatten(*sub, config, path, seen);
      continue;
    }
    if (!seen.insert(key).second) throw BadInput(path + ": key `" + key + "` is given twice");
    config.set_from_scene(key, to_text(node, key, path), path);
  }
}

}  // namespace

namespace {

// TOML 1.0 allows non-ASCII only inside strings and comments. Rejecting it elsewhere before
// toml++ sees the text is correct TOML, and it also guards against a bug of toml++ 3.3.0 (Debian
// 12): its non-ASCII whitespace test reaches TOML_UNREACHABLE (undefined behaviour) for many
// code points, e.g. U+00A1 or U+FEFB after `=` (found by tests/fuzz_scene.cpp, docs/fuzzing.md).
// Inside basic strings toml++ runs the same test on the character after a backslash, and in
// multi-line basic strings on the first character after a line-ending backslash: a non-ASCII
// character there is rejected too (after a backslash it is invalid TOML anyway).
// A quote starts a string only where TOML allows one (after `=`, `[`, `{`, `,`, `.` or at the
// start of a line, white space aside), and never inside a bare value: toml++ classifies a bare
// value (one not starting with a quote, `[` or `{`) by scanning up to ~127 characters to the next
// space, `,`, `]`, `}` or `#`, running the same test on each, so `x = 0'''\u00a1` or
// `x = 0""."\u00a1` must not hide the U+00A1 behind a "string" that TOML does not have there
// (both found by the fuzzer, within seconds, once the backslash case was closed). This rejects a
// few invalid files more than toml++ would, never a valid one.
void require_ascii_outside_strings(const std::string& text, const std::string& path) {
  enum class State { code, comment, basic, literal, multi_basic, multi_literal } state = State::code;
  long line = 1, column = 0;
  char last = '\n';         // the last character in code state other than space or tab
  bool bare_value = false;  // inside a bare value (toml++ scans it to a terminator)
  auto terminates_bare_value = [](char t) {
    return t == ' ' || t == '\t' || t == '\r' || t == ',' || t == ']' || t == '}' || t == '#';
  };
  auto may_open_string = [&]() {
    return last == '=' || last == '[' || last == '{' || last == ',' || last == '.' || last == '\n';
  };
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    ++column;
    auto starts = [&](const char* token) { return text.compare(i, std::char_traits<char>::length(token), token) == 0; };
    auto non_ascii_at = [&](size_t j) { return j < text.size() && static_cast<unsigned char>(text[j]) >= 0x80; };
    auto reject_after_backslash = [&]() {
      throw BadInput("scene `" + path + "`: non-ASCII character after a backslash in a string (line " +
                     std::to_string(line) + ", column " + std::to_string(column) + ")");
    };
    if (c == '\n') {
      ++line;
      column = 0;
      if (state == State::comment || state == State::basic || state == State::literal) state = State::code;
      if (state == State::code) last = '\n', bare_value = false;
      continue;
    }
    switch (state) {
      case State::code:
        if (static_cast<unsigned char>(c) >= 0x80)
          throw BadInput("scene `" + path + "`: non-ASCII character outside a string or comment (line " +
                         std::to_string(line) + ", column " + std::to_string(column) + ")");
        if (bare_value && !terminates_bare_value(c)) {
          last = c;  // quotes included: no string starts inside a bare value
          break;
        }
        bare_value = false;
        if ((last == '=' || last == '[' || last == ',') && c != ' ' && c != '\t' && c != '"' && c != '\'' && c != '[' &&
            c != '{' && !terminates_bare_value(c) && c != '\r') {
          bare_value = true;  // a value not starting with a quote, `[` or `{`
          last = c;
          break;
        }
        if (c == '#') state = State::comment;
        else if ((c == '"' || c == '\'') && !may_open_string()) last = c;  // not a string in TOML: stays code
        else if (starts("\"\"\"")) state = State::multi_basic, i += 2, column += 2;
        else if (starts("'''")) state = State::multi_literal, i += 2, column += 2;
        else if (c == '"') state = State::basic;
        else if (c == '\'') state = State::literal;
        else if (c != ' ' && c != '\t') last = c;
        break;
      case State::comment: break;
      case State::basic:
        if (c == '\\' && non_ascii_at(i + 1)) reject_after_backslash();
        if (c == '\\') ++i, ++column;  // an escape: skip the escaped character
        else if (c == '"') state = State::code, last = c;
        break;
      case State::literal:
        if (c == '\'') state = State::code, last = c;
        break;
      case State::multi_basic:
        if (c == '\\') {
          if (non_ascii_at(i + 1)) reject_after_backslash();
          // A line-ending backslash: toml++ skips the white space and line breaks after it and
          // tests the next character with its non-ASCII whitespace function.
          size_t j = i + 1;
          while (j < text.size() && (text[j] == ' ' || text[j] == '\t' || text[j] == '\r' || text[j] == '\n')) ++j;
          if (j > i + 1 && non_ascii_at(j)) reject_after_backslash();
          if (i + 1 < text.size() && text[i + 1] != '\n') ++i, ++column;  // skip the escaped character
        } else if (starts("\"\"\"")) state = State::code, last = c, i += 2, column += 2;
        break;
      case State::multi_literal:
        if (starts("'''")) state = State::code, last = c, i += 2, column += 2;
        break;
    }
  }
}

Config parse_scene(const std::string& path, const std::string* text) {
  Config config;
  std::string file_text;
  if (!text) {
    // Only a regular file: opening a FIFO would block until someone writes to it, a device may
    // never end.
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
      throw BadInput("scene `" + path + "`: not a regular file (a directory, FIFO or device)");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw BadInput("scene `" + path + "`: cannot be read (missing file or no permission)");
    std::ostringstream ss;
    ss << in.rdbuf();
    file_text = ss.str();
    text = &file_text;
  }
  require_ascii_outside_strings(*text, path);
  try {
    toml::table table = toml::parse(*text, path);
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

}  // namespace

Config Config::from_scene_file(const std::string& path) { return parse_scene(path, nullptr); }

Config Config::from_scene_text(const std::string& text, const std::string& name) { return parse_scene(name, &text); }

Config Config::from_scene_table(const toml::table& table, const std::string& name) {
  Config config;
  std::set<std::string> seen;
  flatten(table, config, name, seen);
  return config;
}

void Config::set_from_assignment(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos) throw BadInput("`--set " + assignment + "`: expected KEY=VALUE");
  const std::string key = trim(assignment.substr(0, eq));
  if (key.empty()) throw BadInput("`--set " + assignment + "`: the key is empty");
  set(key, trim(assignment.substr(eq + 1)), "--set");
}

void Config::set_from_scene(const std::string& key, const std::string& value, const std::string& path) {
  set(key, value, path);
  scene_keys_.insert(key);
}

void Config::set(const std::string& key, const std::string& value, const std::string& origin) {
  values_[key] = value;
  origin_[key] = origin;
  scene_keys_.erase(key);
}

bool Config::has(const std::string& key) const {
  note_read(key, std::nullopt);
  return values_.count(key) > 0;
}

Config::Read& Config::note_read(const std::string& key, const std::optional<std::string>& fallback) const {
  auto it = std::find_if(reads_.begin(), reads_.end(), [&](const Read& r) { return r.key == key; });
  if (it == reads_.end()) it = reads_.insert(reads_.end(), Read{key, std::nullopt, std::nullopt});
  if (fallback && !values_.count(key)) it->fallback = fallback;  // the latest reader's default counts
  return *it;
}

void Config::note_value(const std::string& key, const std::string& value) {
  note_read(key, std::nullopt).value = value;  // the latest typed read counts
}

std::map<std::string, std::string> Config::effective_values() const {
  std::map<std::string, std::string> out;
  for (const auto& r : reads_)
    if (r.value) out[r.key] = *r.value;
  return out;
}

std::map<std::string, std::string> Config::effective_defaults() const {
  std::map<std::string, std::string> out;
  for (const auto& r : reads_)
    if (r.fallback && !values_.count(r.key)) out[r.key] = *r.fallback;
  return out;
}

std::optional<std::string> Config::lookup(const std::string& key) {
  used_.insert(key);
  note_read(key, std::nullopt);
  auto it = values_.find(key);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

void Config::mark_used(const std::string& key) { used_.insert(key); }

namespace {

// `item` (all of `text`, or one item of the list `text`) as a finite double; BadInput naming the key.
double parse_finite_number(const std::string& key, const std::string& text, const std::string& item) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(item.c_str(), &end);
  const std::string what = item == text ? "" : "`" + item + "` is ";
  // ERANGE also flags underflow (subnormal results, or 0): those are numbers; only overflow is not.
  if (item.empty() || end != item.c_str() + item.size() || (errno == ERANGE && std::abs(value) == HUGE_VAL))
    throw BadInput("`" + key + " = " + text + "`: " + what + "not a number");
  if (!std::isfinite(value)) throw BadInput("`" + key + " = " + text + "`: " + (what.empty() ? "must be" : what + "not") + " a finite number");
  return value;
}

}  // namespace

double Config::get_double(const std::string& key, double fallback) {
  auto text = lookup(key);
  if (!text) {
    note_value(key, format_number(fallback));
    note_read(key, format_number(fallback));
    return fallback;
  }
  const double value = parse_finite_number(key, *text, *text);
  note_value(key, format_number(value));
  return value;
}

std::vector<double> Config::get_double_list(const std::string& key, const std::string& fallback_text) {
  auto text = lookup(key);
  if (!text) {
    note_read(key, fallback_text);
    return {};
  }
  std::vector<double> out;
  std::string shown;
  for (const std::string& item : split_items(*text)) {
    out.push_back(parse_finite_number(key, *text, item));
    shown.append(shown.empty() ? "" : ",").append(format_number(out.back()));
  }
  note_value(key, shown);
  return out;
}

double Config::require_double(const std::string& key) {
  if (!has(key)) throw BadInput("missing key `" + key + "`");
  return get_double(key, 0);
}

long Config::get_int(const std::string& key, long fallback) {
  auto text = lookup(key);
  if (!text) {
    note_value(key, std::to_string(fallback));
    note_read(key, std::to_string(fallback));
    return fallback;
  }
  const std::string& s = *text;
  errno = 0;
  char* end = nullptr;
  long value = std::strtol(s.c_str(), &end, 10);
  if (!s.empty() && end != s.c_str() + s.size() && errno != ERANGE) {
    // An exact integer in exponent notation (`1e7`, as --help writes the ranges) is that integer;
    // 1.5e0 or 1e30 are not (issue 61 item 9).
    char* real_end = nullptr;
    const double real = std::strtod(s.c_str(), &real_end);
    if (real_end == s.c_str() + s.size() && std::isfinite(real) && real == std::floor(real) &&
        std::abs(real) <= 9e15) {
      value = static_cast<long>(real);
      end = real_end;
    }
  }
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE)
    throw BadInput("`" + key + " = " + s + "`: not an integer");
  note_value(key, std::to_string(value));
  return value;
}

long Config::get_int_in_range(const std::string& key, long fallback, long lo, long hi) {
  const long value = get_int(key, fallback);
  if (value < lo || value > hi)
    throw BadInput("`" + key + " = " + std::to_string(value) + "`: must be between " + std::to_string(lo) + " and " +
                   std::to_string(hi));
  return value;
}

std::string Config::get_string(const std::string& key, const std::string& fallback) {
  auto text = lookup(key);
  const std::string value = text ? *text : fallback;
  if (!text) note_read(key, fallback);
  note_value(key, value);
  return value;
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

std::vector<std::string> split_items(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) items.push_back(trim(item));
  return items;
}

std::vector<long> Config::get_int_list(const std::string& key, const std::vector<long>& fallback) {
  auto join = [](const std::vector<long>& list) {
    std::string out;
    for (long v : list)
      out.append(out.empty() ? "" : ",").append(std::to_string(v));  // (append: GCC 12 warns falsely on "," + string)
    return out;
  };
  auto text = lookup(key);
  if (!text) {
    note_value(key, join(fallback));
    note_read(key, join(fallback));
    return fallback;
  }
  std::vector<long> out;
  for (const std::string& item : split_items(*text)) {
    errno = 0;
    char* end = nullptr;
    const long value = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || end != item.c_str() + item.size() || errno == ERANGE)
      throw BadInput("`" + key + " = " + *text + "`: `" + item + "` is not an integer");
    out.push_back(value);
  }
  if (out.empty()) throw BadInput("`" + key + " = " + *text + "`: empty list");
  note_value(key, join(out));
  return out;
}

namespace {

// Text for a message: at most 80 characters, a longer text cut with its length stated.
// A key or value in a message: cut to 80 characters, control bytes escaped (printable.hpp: a
// scene's key is not echoed raw to a terminal, issue 61 item 9).
std::string shortened(const std::string& text) {
  if (text.size() <= 80) return printable(text);
  return printable(text.substr(0, 60)) + "... (" + std::to_string(text.size()) + " characters)";
}

}  // namespace

const KeyIndex& Config::key_index() const {
  static const KeyIndex none;
  return key_index_ ? key_index_() : none;
}

void Config::check_all_used() const {
  if (collect_keys_only_) throw KeysCollected{used_};
  for (const auto& [key, value] : values_) {
    if (used_.count(key)) continue;
    // A scene file is shared by the commands (the default scene carries floquet's nev and solver
    // and is run with lyapunov, simulate, ...): a key of another command given there is not an
    // error. On the command line (--set) every key must be one this command reads.
    if (scene_keys_.count(key) && key_index().readers.count(key)) continue;
    const auto model = values_.find("model");
    throw BadInput(unread_key_message(key_index(), shortened(key), "(= " + shortened(value) + ", from " + origin_.at(key) + ")",
                                      reader_.empty() ? std::vector<std::string>{} : std::vector<std::string>{reader_},
                                      model == values_.end() ? "" : model->second, used_));
  }
}

}  // namespace delayspec::cli
