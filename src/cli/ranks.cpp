#include "ranks.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <thread>
#include <vector>

#ifdef DELAYSPEC_MPI
#include <mpi.h>
#endif

namespace delayspec::cli {

namespace {

int rank = 0;
int ranks = 1;

}  // namespace

int this_rank() { return rank; }
int rank_count() { return ranks; }

#ifdef DELAYSPEC_MPI

namespace {

bool mpi_started = false;

// The lead's broadcast at a loop start; any exit status is >= 0.
constexpr int loop_starts = -1;

// Set by the launchers: OpenMPI's mpirun, PMIx (OpenMPI 5, `srun --mpi=pmix`), MPICH's Hydra and
// Slurm's PMI/PMI2. Without one, this is a plain run: no MPI_Init (it would cost a singleton
// start-up and is not wanted in scripts, the doc-test or the gtest binary, which calls run_cli).
bool started_by_mpi_launcher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name)) return true;
  return false;
}

// MPI_Bcast would spin on a worker while the lead works alone (OpenMPI polls: a core at 100%,
// taken from the lead when ranks share a node, e.g. during `run`'s floquet analysis): the
// workers test a non-blocking broadcast and sleep in between, up to 1 ms.
int broadcast_from_lead(int value) {
  using namespace std::chrono_literals;
  MPI_Request request;
  MPI_Ibcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD, &request);
  auto pause = 20us;
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return value;
    std::this_thread::sleep_for(pause);
    pause = std::min<std::chrono::microseconds>(2 * pause, 1000us);
  }
}

long gather_threads(int threads) {
  std::vector<int> all(rank == 0 ? static_cast<size_t>(ranks) : 0);
  MPI_Gather(&threads, 1, MPI_INT, all.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  long workers = 0;
  for (int r = 1; r < static_cast<int>(all.size()); ++r) workers += all[r];
  return workers;
}

}  // namespace

void start_ranks(int* argc, char*** argv) {
  if (!started_by_mpi_launcher()) return;
  // Serialized: on the lead only the dispatcher thread calls MPI during a loop, on a worker the
  // compute threads take turns under a mutex (distributed_points.cpp).
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
  mpi_started = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (provided < MPI_THREAD_SERIALIZED) {
    if (rank == 0) std::cerr << "delayspec: the MPI library does not support MPI_THREAD_SERIALIZED\n";
    MPI_Abort(MPI_COMM_WORLD, 3);
  }
}

int finish_ranks(int status, bool stopped) {
  if (!mpi_started) return status;
  if (rank == 0) {
    broadcast_from_lead(status);
  } else if (!stopped) {
    // A worker that left its command early (its own failure) still answers the lead's loops.
    int lead;
    while ((lead = broadcast_from_lead(0)) == loop_starts) gather_threads(0);
    status = lead;
  }
  MPI_Finalize();
  return status;
}

long enter_point_loop(int threads) {
  if (ranks == 1) return 0;
  const int lead = broadcast_from_lead(loop_starts);
  if (lead != loop_starts) throw RankStop{lead};
  return gather_threads(threads);
}

#else

void start_ranks(int*, char***) {}
int finish_ranks(int status, bool) { return status; }
long enter_point_loop(int) { return 0; }

#endif

}  // namespace delayspec::cli
