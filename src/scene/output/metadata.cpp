#include "scene/output/metadata.hpp"

#include <cstdlib>
#include <ctime>
#include <sstream>

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
  out << "# wall_seconds: " << m.wall_seconds << "\n";
  out << "# finished_utc: " << utc_now_iso8601() << "\n";
  return out.str();
}

}  // namespace delayspec::cli
