#include "scene/points/distributed_points.hpp"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <functional>
#include <string>

#include "delayspec/parallel_points.hpp"
#include "scene/points/ranks.hpp"

#ifdef DELAYSPEC_MPI
#include "modules/mpi/mpi_module.hpp"
#endif

namespace delayspec::cli {

namespace {

// DELAYSPEC_TEST_KILL_RANK=R:K (see the header): the number of points after which this rank
// kills itself, 0 = never.
long kill_after_points() {
  const char* hook = std::getenv("DELAYSPEC_TEST_KILL_RANK");
  if (!hook) return 0;
  char* end = nullptr;
  const long r = std::strtol(hook, &end, 10);
  if (*end != ':' || r != this_rank()) return 0;
  return std::strtol(end + 1, nullptr, 10);
}

// Counts this rank's finished points for the test hook (thread-safe).
class KillHook {
 public:
  KillHook() : after_(kill_after_points()) {}
  void point_done() {
    if (after_ > 0 && done_.fetch_add(1) + 1 == after_) std::raise(SIGKILL);
  }

 private:
  long after_;
  std::atomic<long> done_{0};
};

}  // namespace

void distributed_points(const std::vector<long>& todo, int threads, const PointTasks& tasks) {
  KillHook hook;
#ifdef DELAYSPEC_MPI
  if (rank_count() > 1) {
    // More than one rank: start_ranks has loaded the MPI module, which runs the loop.
    const MpiModule& mpi = mpi_module();
    const std::function<void()> point_done = [&hook] { hook.point_done(); };
    const long worker_threads = enter_point_loop(threads);
    if (!is_lead_rank()) {
      mpi.worker_points(threads, tasks, point_done);
      throw WorkerPointsDone{};
    }
    // As parallel_points: no more threads than points.
    const long local = std::clamp<long>(threads, 1, std::max<long>(static_cast<long>(todo.size()), 1));
    mpi.lead_points(todo, static_cast<int>(local), worker_threads, tasks, point_done);
    return;
  }
#endif
  parallel_points(static_cast<long>(todo.size()), threads, [&](long i) {
    tasks.compute(todo[static_cast<size_t>(i)]);
    hook.point_done();
  });
}

}  // namespace delayspec::cli
