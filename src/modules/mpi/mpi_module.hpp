#pragma once
// MPI (OpenMPI: libmpi, libopen-rte, libopen-pal, hwloc, libevent, libudev) is a shared module of
// its own, libdelayspec_mpi.so, which the program loads with dlopen only when an MPI launcher
// started it (src/scene/points/ranks.cpp; module_loader.hpp). Linked into the program, those libraries
// cost every command about 1.3 ms of start-up (docs/benchmarks.md, "Start-up"), `--version` and
// every run without mpirun included.
//
// The module is the MPI half of ranks.hpp and distributed_points.hpp: the program keeps the
// state every command reads (this rank, the number of ranks) and the loop without MPI; the
// module makes every MPI call. Its entry point mpi_module_symbol returns this table.
#include <functional>
#include <string>
#include <vector>

namespace delayspec::cli {

// The work of one point loop (distributed_points.hpp), as the program hands it to the module.
struct PointTasks {
  // Computes point `index` and keeps its result (any rank; concurrently for distinct indices).
  std::function<void(long index)> compute;
  // A worker: the result compute(index) kept, as bytes for the lead.
  std::function<std::string(long index)> encode;
  // The lead: stores the result of `index` that a worker computed (called on one thread, while
  // the lead's threads compute other points; exactly once per index of todo not computed here).
  std::function<void(long index, const std::string& bytes)> decode;
};

// A worker rank waiting at a loop start that receives the lead's exit status instead (ranks.hpp):
// control flow, deliberately not std::exception (run_cli's handlers do not catch it), caught in
// main.cpp and in command_run between analyses.
struct RankStop {
  int status;  // the lead's exit status
};

struct MpiModule {
  // DELAYSPEC_VERSION " " DELAYSPEC_REVISION of the module's build (module_loader.hpp).
  const char* version = nullptr;
  // MPI_Init_thread at MPI_THREAD_SERIALIZED; this process's rank and the number of ranks.
  // MPI_Abort (exit 3, one message) when the library lacks that thread level.
  void (*start)(int* argc, char*** argv, int* rank, int* ranks) = nullptr;
  // finish_ranks (ranks.hpp) after start: the lead's status on every rank, then MPI_Finalize.
  int (*finish)(int status, bool stopped) = nullptr;
  // enter_point_loop (ranks.hpp) with more than one rank.
  long (*enter_point_loop)(int threads) = nullptr;
  // distributed_points (distributed_points.hpp) with more than one rank, after enter_point_loop:
  // on the lead its loop over `todo` with `worker_threads` requesters, on a worker its requests.
  // point_done: called after each point this rank computed (the test hook's counter).
  void (*lead_points)(const std::vector<long>& todo, int threads, long worker_threads, const PointTasks& tasks,
                      const std::function<void()>& point_done) = nullptr;
  void (*worker_points)(int threads, const PointTasks& tasks, const std::function<void()>& point_done) = nullptr;
};

// The module's file name, beside libdelayspec.
inline constexpr char mpi_module_file[] = "libdelayspec_mpi.so";
// extern "C" const MpiModule* delayspec_mpi_module(): the table, static in the module.
inline constexpr char mpi_module_symbol[] = "delayspec_mpi_module";

}  // namespace delayspec::cli
