#pragma once
// MPI (OpenMPI: libmpi, libopen-rte, libopen-pal, hwloc, libevent, libudev) is a shared module of
// its own, libdelayspec_mpi.so, which the program loads with dlopen only when an MPI launcher
// started it (src/cli/ranks.cpp; module_loader.hpp). Linked into the program, those libraries
// cost every command about 1.3 ms of start-up (docs/benchmarks.md, "Start-up"), `--version` and
// every run without mpirun included.
//
// The module is the MPI half of ranks.hpp and distributed_points.hpp: the program keeps the
// state every command reads (this rank, the number of ranks) and the loop without MPI; the
// module makes every MPI call. Its entry point mpi_module_symbol returns this table.
#include <functional>
#include <vector>

#include "distributed_points.hpp"

namespace delayspec::cli {

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
