// The ranks of an MPI run (ranks.hpp describes the protocol): MPI_Init, the lead's broadcasts at
// each loop start and at the end, MPI_Finalize.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <thread>
#include <vector>

#include "modules/mpi/mpi_parts.hpp"

namespace delayspec::cli::mpi {

namespace {

int rank = 0;
int ranks = 1;

// The lead's broadcast at a loop start; any exit status is >= 0.
constexpr int loop_starts = -1;

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

void start(int* argc, char*** argv, int* this_rank, int* rank_count) {
  // Serialized: on the lead only the dispatcher thread calls MPI during a loop, on a worker the
  // compute threads take turns under a mutex (mpi_points.cpp).
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (provided < MPI_THREAD_SERIALIZED) {
    if (rank == 0) std::cerr << "delayspec: the MPI library does not support MPI_THREAD_SERIALIZED\n";
    MPI_Abort(MPI_COMM_WORLD, 3);
  }
  *this_rank = rank;
  *rank_count = ranks;
}

int finish(int status, bool stopped) {
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
  const int lead = broadcast_from_lead(loop_starts);
  if (lead != loop_starts) throw RankStop{lead};
  return gather_threads(threads);
}

}  // namespace delayspec::cli::mpi
