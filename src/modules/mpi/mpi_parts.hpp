#pragma once
// The functions of the MPI module's table (mpi_module.hpp), one file each: mpi_ranks.cpp (start,
// the lead's broadcasts, finish) and mpi_points.cpp (the distributed point loop).
#include <functional>
#include <vector>

#include "modules/mpi/mpi_module.hpp"

namespace delayspec::cli::mpi {

void start(int* argc, char*** argv, int* rank, int* ranks);
int finish(int status, bool stopped);
long enter_point_loop(int threads);
void lead_points(const std::vector<long>& todo, int threads, long worker_threads, const PointTasks& tasks,
                 const std::function<void()>& point_done);
void worker_points(int threads, const PointTasks& tasks, const std::function<void()>& point_done);

}  // namespace delayspec::cli::mpi
