#pragma once
// PeriodicOrbit: a periodic orbit of the stroboscopic map, as found by simulation
// (orbit_simulation.hpp) or by Newton on the discrete periodic problem (orbit_newton.hpp).
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/grid.hpp"

namespace delayspec {

// How an orbit was found: by simulation (orbit_simulation.hpp), by sparse-LU Newton on the
// discrete periodic problem (orbit_newton.hpp), by Newton-Krylov shooting (orbit_shooting.hpp),
// or it is the zero orbit of a linear model.
enum class OrbitFoundBy { simulate, newton, shooting, zero };
// "simulate", "newton", "shooting", "zero".
std::string to_string(OrbitFoundBy method);

struct PeriodicOrbit {
  Eigen::VectorXd history;  // U with P(U) ~ U (the history the Monodromy is taken at)
  double residual = NAN;    // |P(U) - U|_inf, one application of the stroboscopic map
  long maps = 0;            // stroboscopic maps simulated (simulate: to settle; newton: for the guess)
  OrbitFoundBy method = OrbitFoundBy::simulate;

  // Newton only (empty / zero otherwise).
  int newton_iterations = 0;                   // linear solves performed
  std::vector<double> newton_residuals;        // |F(x_i)|_inf of each iterate, the guess first
  std::vector<double> newton_step_fractions;   // line-search fraction of each Newton step (1 = full)
  double jacobian_reciprocal_condition = NAN;  // UMFPACK's estimate at the last factorisation
  long jacobian_nonzeros = 0;                  // nonzeros of the assembled periodic Jacobian
  long factor_nonzeros = 0;                    // nonzeros of its L and U factors

  // Shooting only (orbit_shooting.hpp; empty / zero otherwise).
  long linear_iterations = 0;  // GMRES iterations (applications of M - I), all levels
  struct Level {
    int N = 0;                                     // steps per delay at this level
    OrbitFoundBy method = OrbitFoundBy::shooting;  // newton (sparse LU) only at the coarsest level
    int newton_iterations = 0;
    long linear_iterations = 0;
    double residual = NAN;  // |P(U) - U|_inf at the level's orbit
    double seconds = 0;
  };
  std::vector<Level> levels;  // coarsest first; the last is the orbit returned
};

// The states of a periodic orbit over one map, x = (u_0, ..., u_{K-1}), u_l = y(l h), d each
// (PeriodicOrbitProblem's unknowns), carried to another resolution: the K_to states at l h_to
// over the same map period, by periodic cubic interpolation (4-point Lagrange, u_{l+K} = u_l;
// linear below 4 states). A Newton guess for the orbit at another N: its distance to that orbit is
// O(h^4) where the orbit is smooth, O(h^2) near a contact (the acceleration jumps there), plus
// the orbit's own change with N, O(h^2), which dominates: measured on the paper's orbit from
// N = 100 to 800, the first residual |P(U) - U| is 1.2e-3 from linear and 1.3e-3 from cubic
// interpolation; from N = 12500 to 1e5 it is 9e-8.
// BadInput: d < 1, K_to < 1, or x.size() not a positive multiple of d.
Eigen::VectorXd prolong_periodic_sequence(const Eigen::VectorXd& x, int d, long K_to);
// The same from the grid `from` (x has from.K states) to the grid `to`, for grids with
// breakpoints (grid.hpp): each state of `to` interpolated linearly in time between the states of
// `from` around it (the pieces share their ends, and the orbit's derivative jumps there, so no
// stencil crosses one; linear costs nothing against the orbit's own O(h^2) change with N, above).
// Grids without breakpoints: the uniform version above. BadInput as above, or x not from.K states.
Eigen::VectorXd prolong_periodic_sequence(const Eigen::VectorXd& x, int d, const HistoryGrid& from,
                                          const HistoryGrid& to);

}  // namespace delayspec
