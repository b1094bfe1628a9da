#pragma once
// PeriodicOrbit: a periodic orbit of the stroboscopic map, as found by simulation
// (orbit_simulation.hpp) or by Newton on the discrete periodic problem (orbit_newton.hpp).
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace delayspec {

struct PeriodicOrbit {
  Eigen::VectorXd history;  // U with P(U) ~ U (the history the Monodromy is taken at)
  double residual = NAN;    // |P(U) - U|_inf, one application of the stroboscopic map
  long maps = 0;            // stroboscopic maps simulated (simulate: to settle; newton: for the guess)
  std::string method = "simulate";  // "simulate" | "newton" | "zero" (linear models)

  // Newton only (empty / zero otherwise).
  int newton_iterations = 0;               // linear solves performed
  std::vector<double> newton_residuals;    // |F(x_i)|_inf of each iterate, the guess first
  std::vector<double> newton_step_fractions;  // line-search fraction of each Newton step (1 = full)
  double jacobian_reciprocal_condition = NAN; // UMFPACK's estimate at the last factorisation
  long jacobian_nonzeros = 0;              // nonzeros of the assembled periodic Jacobian
  long factor_nonzeros = 0;                // nonzeros of its L and U factors
};

}  // namespace delayspec
