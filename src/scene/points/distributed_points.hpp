#pragma once
// distributed_points: the point loop of sweep, chart and basin, over the threads of this
// process and, under mpirun, over MPI ranks (ranks.hpp). One rank: exactly parallel_points over
// `todo`. R ranks: dynamic scheduling from the lead (rank 0): a thread of a worker rank asks the
// lead for a chunk of indices of `todo` (about 20 ms of work at its measured cost per point, at
// least 1) when it has finished the previous one, and sends the finished points' results with
// that request; the lead's own threads take single indices from the same counter, so rank 0
// computes too. After the loop the lead holds every point's result (decode), as after a run of
// one rank, and assembles the output with the same code; a worker throws WorkerPointsDone.
//
// Per chunk and thread: one request (the encoded results, plus 20 bytes per point) and one
// reply (8 bytes per index). A point whose compute throws stops the hand-out on every rank, and
// the first such exception is rethrown on the lead, with its type (BadInput, NumericalFailure,
// bad_alloc, other) and message, as parallel_points does. docs/parallel.md: use and scaling.
//
// Test hook (for the tests of resuming a killed run, tests/mpi_test.py; not a user setting):
// DELAYSPEC_TEST_KILL_RANK=R:K makes rank R (0 without MPI) kill itself with SIGKILL right
// after it has computed its K-th point of a loop (its line in the point log, if any, written).
#include <vector>

#include "modules/mpi/mpi_module.hpp"  // PointTasks

namespace delayspec::cli {

// Computes every index of `todo` (the lead's list; ignored on the workers) once.
void distributed_points(const std::vector<long>& todo, int threads, const PointTasks& tasks);

}  // namespace delayspec::cli
