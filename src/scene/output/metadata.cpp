#include "scene/output/metadata.hpp"

#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <sstream>

#include "delayspec/errors.hpp"
#include "delayspec/version.hpp"

namespace delayspec::cli {

std::string utc_now_iso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buf;
}

OutputMetadata make_metadata(const std::string& command, const std::optional<std::string>& scene, const Config& config,
                             const nlohmann::json& result, double wall_seconds) {
  OutputMetadata m;
  m.command = command;
  m.scene = scene;
  m.parameters = config.values();
  m.defaults = config.effective_defaults();
  m.wall_seconds = wall_seconds;
  auto text = [&](const char* key, const std::string& fallback) {
    if (result.is_object() && result.contains(key) && result[key].is_string()) return result[key].get<std::string>();
    auto it = m.parameters.find(key);
    return it != m.parameters.end() ? it->second : fallback;
  };
  // A result that names its model and state (floquet, continue) names them in its files too, even
  // when `run` writes them from its JSON alone.
  if (result.is_object() && result.contains("model") && result["model"].is_string() && result.contains("state_names") &&
      result["state_names"].is_array()) {
    std::vector<std::string> names;
    for (const auto& name : result["state_names"])
      if (name.is_string()) names.push_back(name.get<std::string>());
    name_model(m, model_label(result["model"].get<std::string>(), names, scene), names);
  }
  m.events = text("events", "on");
  m.jacobian = text("jacobian", "consistent");
  if (result.is_object() && result.contains("N") && result["N"].is_number_integer()) {
    m.N = result["N"].get<long>();
  } else if (auto it = m.parameters.find("N"); it != m.parameters.end()) {
    m.N = std::strtol(it->second.c_str(), nullptr, 10);
  }
  return m;
}

nlohmann::json metadata_json(const OutputMetadata& m) {
  nlohmann::json j;
  j["delayspec_version"] = DELAYSPEC_VERSION;
  j["source_revision"] = DELAYSPEC_REVISION;
  j["command"] = m.command;
  j["scene"] = m.scene ? nlohmann::json(*m.scene) : nlohmann::json(nullptr);
  j["parameters"] = m.parameters;
  j["defaults"] = m.defaults;
  if (m.N > 0) j["N"] = m.N;
  j["events"] = m.events;
  j["jacobian"] = m.jacobian;
  if (!m.model_label.empty()) j["model_label"] = m.model_label;
  if (!m.state_names.empty()) j["state_names"] = m.state_names;
  j["wall_seconds"] = m.wall_seconds;
  j["finished_utc"] = utc_now_iso8601();
  return j;
}

namespace {

// A value on one comment line: newlines would end the comment.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

}  // namespace

std::string metadata_comment_lines(const OutputMetadata& m) {
  std::ostringstream out;
  out << "# delayspec " << DELAYSPEC_VERSION << "\n";
  out << "# source_revision: " << DELAYSPEC_REVISION << "\n";
  out << "# command: " << m.command << "\n";
  out << "# scene: " << (m.scene ? one_line(*m.scene) : "(none)") << "\n";
  for (const auto& [key, value] : m.parameters) out << "# " << one_line(key) << " = " << one_line(value) << "\n";
  for (const auto& [key, value] : m.defaults) out << "# default: " << one_line(key) << " = " << one_line(value) << "\n";
  if (m.N > 0) out << "# N: " << m.N << "\n";
  out << "# events: " << m.events << "\n";
  out << "# jacobian: " << m.jacobian << "\n";
  // after the keys: a parameter of that name (an [equations] model's) cannot hide them from plot
  if (!m.model_label.empty()) out << "# model_label = " << one_line(m.model_label) << "\n";
  if (!m.state_names.empty()) {
    out << "# state_names = ";
    for (size_t i = 0; i < m.state_names.size(); ++i) out << (i ? "," : "") << m.state_names[i];
    out << "\n";
  }
  out << "# wall_seconds: " << m.wall_seconds << "\n";
  out << "# finished_utc: " << utc_now_iso8601() << "\n";
  return out.str();
}

std::string model_label(const std::string& model, const std::vector<std::string>& state_names,
                        const std::optional<std::string>& scene) {
  if (model != "equations") return model;
  if (scene) {
    const std::string stem = std::filesystem::path(*scene).stem().string();
    if (!stem.empty()) return one_line(stem);
  }
  std::string names;
  for (const std::string& name : state_names) names += (names.empty() ? "" : ", ") + name;
  return "equations in " + names;
}

void name_model(OutputMetadata& m, const std::string& label, const std::vector<std::string>& state_names) {
  m.model_label = label;
  m.state_names = state_names;
}

size_t state_component(const std::string& key, const std::string& value, const std::vector<std::string>& names) {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == value) return i;
  // a 1-based index: digits only, so that "1e0" or " 2" are not read as one
  if (!value.empty() && value.size() < 10 && value.find_first_not_of("0123456789") == std::string::npos) {
    const unsigned long index = std::stoul(value);
    if (index >= 1 && index <= names.size()) return index - 1;
  }
  std::string choices;
  for (const std::string& name : names) choices += (choices.empty() ? "" : ", ") + name;
  throw BadInput("`" + key + " = " + value + "`: not a state component (a name of " + choices + ", or 1.." +
                 std::to_string(names.size()) + ")");
}

}  // namespace delayspec::cli
