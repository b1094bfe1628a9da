#pragma once
// The point logs of a sweep, chart or basin in --out DIR (src/scene/points/point_files.hpp:
// DIR/POINTS/rank_RRRRR.jsonl, a record per line), read and edited as an interrupted run would
// leave them, for the tests of --resume.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace delayspec::testing {

// The logs in `points` (DIR/points or DIR/NAME_points), sorted by name.
inline std::vector<std::filesystem::path> point_logs(const std::filesystem::path& points) {
  std::vector<std::filesystem::path> logs;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(points, ec))
    if (entry.path().extension() == ".jsonl") logs.push_back(entry.path());
  std::sort(logs.begin(), logs.end());
  return logs;
}

// The indices of the points logged in `points` (each once, however often it was logged).
inline std::set<long> logged_points(const std::filesystem::path& points) {
  std::set<long> indices;
  for (const auto& log : point_logs(points)) {
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);)
      if (const auto record = nlohmann::json::parse(line, nullptr, false); record.is_object())
        indices.insert(record.at("index").get<long>());
  }
  return indices;
}

// How many records the logs in `points` hold (a point logged twice counts twice).
inline long logged_records(const std::filesystem::path& points) {
  long count = 0;
  for (const auto& log : point_logs(points)) {
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);)
      count += nlohmann::json::parse(line, nullptr, false).is_object();
  }
  return count;
}

// Removes the records of `drop` from every log in `points`, as if those points had not finished.
inline void forget_points(const std::filesystem::path& points, const std::set<long>& drop) {
  for (const auto& log : point_logs(points)) {
    std::ifstream in(log);
    std::string kept;
    for (std::string line; std::getline(in, line);) {
      const auto record = nlohmann::json::parse(line, nullptr, false);
      if (!record.is_object() || !drop.count(record.at("index").get<long>())) kept += line + "\n";
    }
    in.close();
    std::ofstream(log, std::ios::trunc) << kept;
  }
}

// The line of point `index` in the logs of `points` (empty if none).
inline std::string logged_line(const std::filesystem::path& points, long index) {
  for (const auto& log : point_logs(points)) {
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);)
      if (const auto record = nlohmann::json::parse(line, nullptr, false);
          record.is_object() && record.at("index").get<long>() == index)
        return line;
  }
  return "";
}

}  // namespace delayspec::testing
