#include "scene/points/point_loop.hpp"

#include <map>
#include <optional>

#include "scene/points/distributed_points.hpp"
#include "scene/points/point_files.hpp"
#include "scene/output/progress.hpp"
#include "scene/points/ranks.hpp"

namespace delayspec::cli {

namespace {

// The indices of 0..count-1 still to compute. Without files, and on a worker rank under mpirun,
// all of them; on the lead, files->start(resume, count) first, then take(index, record) for each
// finished point (false, or an exception reading the record: the point is computed again).
std::vector<long> points_to_do(const std::optional<PointFiles>& files, bool resume, long count,
                               const std::function<bool(long, const nlohmann::json&)>& take) {
  std::map<long, nlohmann::json> finished;
  // Only the lead reads and writes DIR before the points: the workers' views of DIR could
  // differ, and the lead alone decides which points are still to do.
  if (files && is_lead_rank()) finished = files->start(resume, count);
  std::vector<long> todo;
  for (long index = 0; index < count; ++index) {
    const auto it = finished.find(index);
    bool kept = false;
    try {
      kept = it != finished.end() && take(index, it->second);
    } catch (const std::exception&) {
      // a record without the fields of its point: compute the point again
    }
    if (!kept) todo.push_back(index);
  }
  return todo;
}

}  // namespace

long run_point_loop(const PointLoop& loop, const Config& config, const Invocation& inv) {
  std::optional<PointFiles> files;
  if (inv.out_dir) files.emplace(inv, loop.command, resume_settings(config, loop.per_point_keys));
  const std::vector<long> todo = points_to_do(files, inv.resume, loop.count, loop.take);
  const long todo_count = static_cast<long>(todo.size());
  if (!inv.quiet && inv.resume)
    inv.err << loop.command << ": resuming, " << (loop.count - todo_count) << " of " << loop.count
            << " points already done\n";
  Progress progress(inv.err, loop.command, todo_count, inv.quiet);
  PointTasks tasks;
  tasks.compute = [&](long index) {
    loop.compute(index);
    if (files) files->write(loop.record(index));
    progress.add();
  };
  tasks.encode = [&](long index) { return loop.record(index).dump(); };
  tasks.decode = [&](long index, const std::string& text) {
    loop.take(index, nlohmann::json::parse(text));
    progress.add();
  };
  distributed_points(todo, loop.threads, tasks);
  progress.finish();
  return todo_count;
}

}  // namespace delayspec::cli
