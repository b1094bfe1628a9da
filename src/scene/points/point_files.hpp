#pragma once
// The point logs of a run over many independent points (sweep, chart, basin) in `--out DIR`,
// so that an interrupted run loses only the points in flight and `--resume` completes it, with
// any number of threads or MPI ranks (docs/parallel.md):
//   DIR/NAME_settings.json       the effective settings of the run (resume refuses other settings)
//   DIR/POINTS/rank_RRRRR.jsonl  one line per finished point, the point's record with the
//                                settings_hash of its run (resume refuses a point of another
//                                run), appended by the threads of rank R (append_log.hpp)
// where POINTS is `points` for sweep and NAME_points otherwise, so that the analyses of one `run`
// keep their points apart. A resumed run appends to the logs there; a point recorded twice (a
// rank killed after its line was written but before the lead heard of it) is the same record.
// One log per rank, not one file per point (as until 2026-11-28): with a file per point (created,
// written, renamed) the lobe chart (milling_lobes.toml, 20000 points of 0.1 ms) with --out took
// 1 / 0.57 of the time it takes with the logs (farm-bench, docs/milling.md), and loaded a cluster
// file system's metadata server.
//
// Example (command_sweep.cpp):
//     PointFiles files(dir, "sweep", resume_settings(config, {key}));
//     for (auto& [index, record] : files.start(inv.resume, count)) ...;   // the lead, before the points
//     files.write(record);                                         // as each point finishes
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/keys/config.hpp"
#include "scene/output/append_log.hpp"
#include "scene/output/invocation.hpp"

namespace delayspec::cli {

// The settings a resumed run must share with the interrupted one: the effective values (a key
// stated at its default equals the key left out), except the thread count (results do not
// depend on it), the scene-level keys of `run` (analyses, title), and the `per_point` keys
// (null: their value is per point).
nlohmann::json resume_settings(const Config& config, const std::vector<std::string>& per_point);

// FNV-1a (64 bit) of the settings' JSON text, as 16 hex digits: a point record's label of the
// run it belongs to.
std::string settings_hash(const nlohmann::json& settings);

class PointFiles {
 public:
  // The files of `command` in the run's --out directory (inv.out_dir), written through its
  // OutputDirectory (inv.output) where it has one.
  PointFiles(const Invocation& inv, std::string command, nlohmann::json settings);

  // On the lead, before any point is computed. A new run: BadInput if DIR already holds a run
  // of this command, else writes the settings. --resume: BadInput unless the stored settings
  // equal these (naming each differing key with both values) or a logged point belongs to other
  // settings (naming the log and the line); returns the records of the finished points
  // 0..count-1 by index (a line that does not parse, cut short by a kill, or a record without
  // its index, is left out: its point is computed again).
  std::map<long, nlohmann::json> start(bool resume, long count) const;

  // Appends a point's record (which carries its "index"), with this run's settings_hash added,
  // to this rank's log (opened at the first point). Thread-safe.
  void write(nlohmann::json record);

  const std::string& hash() const { return hash_; }  // settings_hash of the settings
  std::filesystem::path settings_path() const;
  std::filesystem::path points_path() const;  // DIR/POINTS
  std::filesystem::path log_path(int rank) const;  // DIR/POINTS/rank_RRRRR.jsonl

 private:
  const Invocation& inv_;
  std::filesystem::path dir_;
  std::string command_;
  nlohmann::json settings_;
  std::string hash_;
  std::unique_ptr<AppendLog> log_;  // this rank's, from the first point on
  std::mutex open_mutex_;           // (the first points of several threads)
};

}  // namespace delayspec::cli
