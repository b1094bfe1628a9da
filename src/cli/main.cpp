// The delayspec program: run_cli on the lead rank (the only rank without MPI); under mpirun the
// worker ranks run it with their output kept in memory (ranks.hpp), and every rank exits with
// the lead's status.
#include <csignal>
#include <iostream>
#include <sstream>

#include "cli/run_cli.hpp"
#include "cli/freed_memory.hpp"
#include "scene/points/ranks.hpp"

int main(int argc, char** argv) {
  using namespace delayspec::cli;
  // A write past the file-size limit (`ulimit -f`) raises SIGXFSZ, whose default action kills the
  // process mid-write. Ignored, the write fails with EFBIG instead and the output layer reports it
  // as bad input naming the file (atomic_file.cpp), exit 2, leaving no half-written result.
  // (CPython ignores SIGXFSZ itself at start-up, so the Python module needs nothing of this.)
  std::signal(SIGXFSZ, SIG_IGN);
  keep_freed_memory();
  start_ranks(&argc, &argv);
  if (is_lead_rank()) return finish_ranks(run_cli(argc, argv, std::cout, std::cerr));
  std::ostringstream out, err;
  int status = 0;
  try {
    status = run_cli(argc, argv, out, err);
  } catch (const RankStop& stop) {
    return finish_ranks(stop.status, true);
  } catch (const WorkerPointsDone&) {
    status = 0;  // its points are with the lead, which writes the results
  }
  const int lead = finish_ranks(status);
  // A failure of this worker alone (the lead's messages cover a shared one) is shown once.
  if (status != 0 && status != lead) std::cerr << "delayspec (rank " << this_rank() << "): " << err.str();
  return lead;
}
