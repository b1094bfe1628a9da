#pragma once
// The point loop of a command over many independent points (sweep, chart, basin): with
// `--out DIR` the point logs and `--resume` (point_files.hpp), the progress report, and the
// distribution over threads and MPI ranks (distributed_points.hpp). The command says how to
// compute a point and how a point's result reads and writes as its JSON record; the record is
// the point's line in the log and, under mpirun, the message that brings a worker's point to rank 0, so a
// point read back (resumed, or from another rank) is the point computed here, double for double.
//
// Example (command_chart.cpp):
//     PointLoop loop{.command = "chart", .count = count, .threads = threads,
//                    .per_point_keys = {x.name, y.name}, .compute = ..., .record = ..., .take = ...};
//     run_point_loop(loop, config, inv);   // then every point's result is in place (rank 0)
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/keys/config.hpp"
#include "scene/output/invocation.hpp"

namespace delayspec::cli {

struct PointLoop {
  std::string command;  // names the point logs (point_files.hpp) and the progress report
  long count = 0;       // points 0..count-1
  int threads = 1;
  std::vector<std::string> per_point_keys;                // keys whose value differs per point (resume_settings)
  std::function<void(long index)> compute = {};           // computes the point and keeps its result
  std::function<nlohmann::json(long index)> record = {};  // the kept result as a record with "index"
  // Keeps the result a record holds (a resumed point, or a worker's); false (or an exception)
  // when the record does not fit the point: it is computed again.
  std::function<bool(long index, const nlohmann::json& record)> take = {};
};

// Runs the points not finished yet; returns how many were computed now. On a worker rank under
// mpirun it throws WorkerPointsDone after its points (ranks.hpp).
long run_point_loop(const PointLoop& loop, const Config& config, const Invocation& inv);

}  // namespace delayspec::cli
