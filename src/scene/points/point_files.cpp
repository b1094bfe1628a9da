#include "scene/points/point_files.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>

#include "scene/output/output_directory.hpp"
#include "scene/points/ranks.hpp"
#include "delayspec/errors.hpp"

namespace delayspec::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// BadInput naming each key whose value differs between `settings` and `stored` (both values; a
// missing key shows as null).
[[noreturn]] void settings_differ(const json& settings, const json& stored, const std::string& command) {
  std::string diff;
  auto add = [&](const std::string& k) {
    diff += (diff.empty() ? "`" : ", `") + k + "` (now " + settings.value(k, json()).dump() + ", the " + command +
            "'s " + (stored.is_object() ? stored.value(k, json()) : json()).dump() + ")";
  };
  for (const auto& [k, v] : settings.items())
    if (!stored.is_object() || !stored.contains(k) || stored[k] != v) add(k);
  if (stored.is_object())
    for (const auto& [k, v] : stored.items())
      if (!settings.contains(k)) add(k);
  throw BadInput("`--resume`: the settings differ from the interrupted " + command + " in " + diff);
}

std::string points_directory(const std::string& command) { return command == "sweep" ? "points" : command + "_points"; }

}  // namespace

// nlohmann::json keeps object keys sorted, so the text hashed is canonical.
std::string settings_hash(const json& settings) {
  std::uint64_t hash = 14695981039346656037ull;
  for (const unsigned char c : settings.dump()) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

json resume_settings(const Config& config, const std::vector<std::string>& per_point) {
  json settings = json::object();
  for (const auto& [k, v] : config.effective_values())
    if (k != "threads" && k != "analyses" && k != "title") settings[k] = v;
  for (const auto& key : per_point) settings[key] = nullptr;
  return settings;
}

PointFiles::PointFiles(const Invocation& inv, std::string command, json settings)
    : inv_(inv),
      dir_(inv.out_dir.value()),
      command_(std::move(command)),
      settings_(std::move(settings)),
      hash_(settings_hash(settings_)) {}

fs::path PointFiles::settings_path() const { return dir_ / (command_ + "_settings.json"); }

fs::path PointFiles::points_path() const { return dir_ / points_directory(command_); }

fs::path PointFiles::log_path(int rank) const {
  char name[32];
  std::snprintf(name, sizeof name, "rank_%05d.jsonl", rank);
  return points_path() / name;
}

void PointFiles::write(json record) {
  record["settings_hash"] = hash_;
  {
    std::lock_guard<std::mutex> guard(open_mutex_);
    if (!log_) {
      const fs::path path = log_path(this_rank());
      // The lead tells its output directory (lock, complete.json, what abandon() removes); a
      // worker rank has none (output_directory.hpp).
      if (inv_.output) inv_.output->note_write(path);
      log_ = std::make_unique<AppendLog>(path);
    }
  }
  log_->append(record.dump());
}

std::map<long, json> PointFiles::start(bool resume, long count) const {
  if (!resume) {
    if (fs::exists(settings_path()) || fs::exists(points_path())) {
      // A finished run (its complete.json, output_directory.hpp) has nothing to resume: a new
      // run, with other keys say, needs a directory of its own.
      if (fs::exists(dir_ / OutputDirectory::marker_name))
        throw BadInput("`--out " + dir_.string() + "` already holds a finished " + command_ +
                       " (complete.json): choose another directory for this one");
      throw BadInput("`--out " + dir_.string() + "` already holds a " + command_ +
                     ": add --resume to complete it, or choose another directory");
    }
    write_output(inv_, settings_path(), settings_.dump(2) + "\n");
    return {};
  }
  std::ifstream in(settings_path());
  if (!in)
    throw BadInput("`--resume`: `" + settings_path().string() + "` not found (no " + command_ + " to resume there)");
  json stored;
  try {
    stored = json::parse(in);
  } catch (const std::exception&) {
    throw BadInput("`--resume`: `" + settings_path().string() + "` is not valid JSON");
  }
  if (stored != settings_) settings_differ(settings_, stored, command_);
  // The settings are part of the resumed run's files (complete.json lists them; it did not after
  // --resume, issue 61 item 9). An existing file: abandon() leaves it for the next --resume.
  if (inv_.output) inv_.output->note_write(settings_path());

  std::map<long, json> finished;
  std::error_code ec;
  std::vector<fs::path> logs;  // every rank's, of this run and of the runs it resumes
  for (const auto& entry : fs::directory_iterator(points_path(), ec))
    if (entry.path().extension() == ".jsonl") logs.push_back(entry.path());
  std::sort(logs.begin(), logs.end());
  for (const fs::path& path : logs) {
    std::ifstream in_log(path);
    std::string line;
    for (long number = 1; std::getline(in_log, line); ++number) {
      json record;
      try {
        record = json::parse(line);
      } catch (const std::exception&) {
        continue;  // a line cut short by a killed run: its point is computed again
      }
      // A point of another run (other settings) is never merged into this one.
      const json stored_hash = record.is_object() ? record.value("settings_hash", json()) : json();
      if (stored_hash != hash_)
        throw BadInput("`--resume`: `" + path.string() + "` line " + std::to_string(number) + " belongs to a " +
                       command_ + " with other settings (settings_hash " +
                       (stored_hash.is_string() ? stored_hash.get<std::string>() : std::string("missing")) +
                       ", this " + command_ + " " + hash_ + ", settings in " + settings_path().string() +
                       "): remove the log, or resume with the settings it was computed with");
      const json stored_index = record.value("index", json());
      if (!stored_index.is_number_integer()) continue;
      const long index = stored_index.get<long>();
      if (index >= 0 && index < count) finished.emplace(index, std::move(record));
    }
  }
  return finished;
}

}  // namespace delayspec::cli
