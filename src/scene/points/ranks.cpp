#include "scene/points/ranks.hpp"

#include <cstdlib>
#include <iostream>
#include <string>

#ifdef DELAYSPEC_MPI
#include "delayspec/errors.hpp"
#include "scene/loading/module_loader.hpp"
#include "modules/mpi/mpi_module.hpp"
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

// Loaded by start_ranks under a launcher; null in a plain run.
const MpiModule* mpi = nullptr;

// Set by the launchers: OpenMPI's mpirun, PMIx (OpenMPI 5, `srun --mpi=pmix`), MPICH's Hydra and
// Slurm's PMI/PMI2. Without one, this is a plain run: no MPI module and no MPI_Init (it would
// cost a singleton start-up and is not wanted in scripts, the doc-test or the gtest binary,
// which calls run_cli).
bool started_by_mpi_launcher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name)) return true;
  return false;
}

// This process's rank as the launcher's environment gives it, before MPI_Init: whether it is the
// lead, which alone prints a message (true when no variable tells).
bool launcher_says_lead() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
    if (const char* value = std::getenv(name)) return std::string(value) == "0";
  return true;
}

}  // namespace

void start_ranks(int* argc, char*** argv) {
  if (!started_by_mpi_launcher()) return;
  try {
    mpi = &load_module<MpiModule>(
        module_file(mpi_module_file), mpi_module_symbol,
        {"a run under an MPI launcher", "delayspec's MPI transport", "OpenMPI, Debian package libopenmpi3"});
  } catch (const BadInput& e) {
    // Every rank stops with exit 2 (bad input, as run_cli's), the lead with the message.
    if (launcher_says_lead()) std::cerr << "delayspec: bad input: " << e.what() << "\n";
    std::exit(2);
  }
  mpi->start(argc, argv, &rank, &ranks);
}

int finish_ranks(int status, bool stopped) { return mpi ? mpi->finish(status, stopped) : status; }

long enter_point_loop(int threads) { return ranks == 1 ? 0 : mpi->enter_point_loop(threads); }

const MpiModule& mpi_module() { return *mpi; }

#else

void start_ranks(int*, char***) {}
int finish_ranks(int status, bool) { return status; }
long enter_point_loop(int) { return 0; }

#endif

}  // namespace delayspec::cli
