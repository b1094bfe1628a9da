#pragma once
// The processes of one delayspec run: one without MPI, R when started by an MPI launcher
// (`mpirun -n R delayspec ...`, `srun delayspec ...`) in a build with DELAYSPEC_MPI.
//
// Rank 0 (the lead) is the program as it runs alone: it reads and checks the input, owns the
// --out directory, prints, and writes every file except the other ranks' point logs. The other ranks
// (workers) read the same input, then only compute points inside distributed_points
// (distributed_points.hpp) and append those points to their logs; their stdout and stderr are kept
// in memory (main.cpp), so a message is printed once.
//
// Synchronisation is one collective of one integer, broadcast by the lead, at two places:
//  * when a point loop starts (enter_point_loop): -1 = "a loop starts", followed by a gather of
//    each worker's compute thread count (the lead's dispatcher serves that many requesters);
//  * when the lead's command has returned (finish_ranks): its exit status >= 0.
// A worker waiting at a loop start that receives a status instead (the lead stopped before the
// loop, e.g. on bad input detected on the lead only) throws RankStop and exits with that status;
// a worker that finished early and receives "a loop starts" takes part in it without computing.
// So every rank takes part in the same sequence of broadcasts and ends with the lead's status.
#include "modules/mpi/mpi_module.hpp"

namespace delayspec::cli {

// main(): if this process was started by an MPI launcher (OpenMPI, MPICH/Hydra, PMIx or PMI
// environment), loads the MPI module (libdelayspec_mpi, src/modules/mpi/mpi_module.hpp: exit 2 naming
// the file when it is missing) and initialises MPI (thread level MPI_THREAD_SERIALIZED);
// otherwise, and in builds without DELAYSPEC_MPI, a run of one rank.
void start_ranks(int* argc, char*** argv);

int this_rank();   // 0 without MPI
int rank_count();  // 1 without MPI
inline bool is_lead_rank() { return this_rank() == 0; }

// The lead's exit status on every rank (broadcast; see above), then MPI_Finalize. `status` is
// this rank's own status; `stopped` says the rank already received the lead's status (RankStop).
int finish_ranks(int status, bool stopped = false);

// At the start of every point loop, on every rank (distributed_points), with this rank's
// compute threads. Returns, on the lead, the sum of the workers' threads (0 on a worker).
// Throws RankStop on a worker when the lead finished its command instead of starting the loop.
long enter_point_loop(int threads);

// The MPI module (src/modules/mpi/mpi_module.hpp; builds with DELAYSPEC_MPI), which start_ranks loads
// under a launcher: there whenever rank_count() > 1.
const MpiModule& mpi_module();

// Control flow of the worker ranks, deliberately not std::exception (run_cli's handlers do not
// catch it): caught in main.cpp, and in command_run between analyses. (RankStop, thrown by the
// module too, is in mpi_module.hpp.)
struct WorkerPointsDone {};  // a worker's points of one loop are computed and sent

}  // namespace delayspec::cli
