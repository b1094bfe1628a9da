#pragma once
// Small helpers shared by the tests.
#include <complex>
#include <cstdlib>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "delayspec/floquet.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec::testing {

// Leading multipliers of a linear model (zero orbit) at resolution N with the dense solver.
template <class Model>
std::vector<std::complex<double>> dense_multipliers(const Model& model, int N, int nev, int periods_per_map = 1) {
  HistoryGrid grid = make_grid(model.tau(), model.period(), N, periods_per_map);
  TrapezoidStepper<Model> stepper(model);
  StroboscopicMap<Model> map(stepper, grid);
  auto op = map.monodromy(Eigen::VectorXd::Zero(map.dimension()));
  FloquetOptions options;
  options.nev = nev;
  options.solver = FloquetSolver::dense_lapack;
  return floquet_multipliers(op, options).multipliers;
}

// A rows x cols matrix of standard normal entries, reproducible from `seed`.
inline Eigen::MatrixXd random_matrix(long rows, long cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  Eigen::MatrixXd X(rows, cols);
  for (long j = 0; j < cols; ++j)
    for (long i = 0; i < rows; ++i) X(i, j) = g(rng);
  return X;
}

// Distance from `target` to the nearest entry of `values`.
inline double distance_to_nearest(const std::vector<std::complex<double>>& values, std::complex<double> target) {
  double best = INFINITY;
  for (auto v : values) best = std::min(best, std::abs(v - target));
  return best;
}

// Sets DELAYSPEC_KERNEL (kernel_dispatch.hpp) for the scope (unset when value is empty) and
// restores the old value: how the tests force the portable kernel path, as a user would.
class KernelEnv {
 public:
  explicit KernelEnv(const std::string& value) {
    if (const char* old = std::getenv("DELAYSPEC_KERNEL")) old_ = old;
    if (value.empty()) unsetenv("DELAYSPEC_KERNEL");
    else setenv("DELAYSPEC_KERNEL", value.c_str(), 1);
  }
  ~KernelEnv() {
    if (old_) setenv("DELAYSPEC_KERNEL", old_->c_str(), 1);
    else unsetenv("DELAYSPEC_KERNEL");
  }
  KernelEnv(const KernelEnv&) = delete;
  KernelEnv& operator=(const KernelEnv&) = delete;

 private:
  std::optional<std::string> old_;
};

}  // namespace delayspec::testing
