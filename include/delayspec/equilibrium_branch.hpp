#pragma once
// The branch of equilibria of an autonomous model in one parameter p, and its fold and Hopf
// points located on the exact characteristic function (issue 35, item 2).
//
// The branch: pseudo-arclength on F(y, p) = f(y, ..., y; p) = 0 in x = (y, p), d + 1 unknowns:
// tangent t from [F_y F_p] t = 0 (F_y = A + sum B_i, F_p by central differences in p with
// delta = eps^(1/3) (1 + |p|): an error ~eps^(2/3) in the corrector's Jacobian, which slows
// Newton by nothing measurable and leaves its solution exact), predictor x + h t, corrector Newton
// on [F(x); t . (x - x_pred)] = 0. It passes folds (where p turns back). At each point the
// rightmost roots come from find_equilibrium's stages 2-3 (equilibrium.hpp), so they are exact.
//
// Bifurcations: where the count of roots with Re lambda > 0 changes between two points, each root
// that crossed (each root at the later point followed back to the earlier one by Newton on c;
// those whose real part changed sign) is followed along the segment between them, and Re lambda = 0 is
// solved by the Illinois method in the arclength; every evaluation is a corrected branch point
// and a root refined on c there, so the location has no discretisation error and its bracket in
// p shrinks to `tolerance`. A complex pair is a Hopf point (omega = Im lambda, the period of the
// orbit born 2 pi / omega); a real root a fold when p turns back on the segment, else a branch
// point (a transcritical or pitchfork crossing). A root that crosses twice within one segment
// (out and back) is not seen: steps are limited by step_max.
//
// Nothing is printed that was not checked (issue 61: Newton on c from a root far away converges to
// another root, and a location bracketed between two different roots is not a bifurcation):
//  * every point tracks `nroots` roots and at least kRootMargin more than it has with Re >= 0, so
//    a root about to cross is among them;
//  * following back must be one to one (no two roots of the later point onto one root of the
//    earlier) and land on a root the earlier point lists (or stay in the left half-plane at both
//    ends, where it is no crossing whichever root it reached), and the crossings found must
//    account for the change in the count of roots with Re > 0 (a pair counts 2, a real root 1);
//  * a segment with more than one crossing is halved (each is located on its own only once the
//    step is down to step_min);
//  * while locating, every refined root lies within half the bracket's spread of the root
//    interpolated between its ends, and at the end the two ends' roots have closed in with the
//    bracket: the same root on both sides, on the axis.
// A segment failing a check is halved and redone; at step_min the branch ends in a failure that
// names the check.
#include <complex>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/continuation.hpp"
#include "delayspec/equilibrium.hpp"
#include "delayspec/hopf_normal_form.hpp"

namespace delayspec {

// The model at parameter p: its values on a constant history, and its equilibrium near a guess
// with its `nroots` rightmost roots (find_equilibrium with EquilibriumOptions::nroots = nroots);
// its Jacobian [A B] on any history (current state y, delayed states `delayed`), for the normal
// form of each Hopf point (hopf_normal_form.hpp; empty: no normal forms).
struct EquilibriumFamily {
  std::function<ConstantHistory(const Eigen::VectorXd& y, double p)> at;
  std::function<EquilibriumResult(const Eigen::VectorXd& guess, double p, int nroots)> equilibrium;
  std::function<Eigen::MatrixXd(const Eigen::VectorXd& y, const Eigen::VectorXd& delayed, double p)> jacobian;
};

// Roots tracked beyond those with Re >= 0: a complex pair and a real root about to cross, and one
// more for the ordering of roots of nearly equal real part.
inline constexpr int kRootMargin = 4;

struct EquilibriumBranchOptions : BranchRange {  // the range and steps as continue_orbit's
  double newton_tolerance = 1e-12;  // corrector: |dx|_inf <= this (1 + |x|_inf)
  int newton_iterations = 10;       // corrector iterations per point
  int nroots = 6;                   // roots tracked at least (more where more are unstable: above)
  std::function<void()> on_point;   // after every accepted point; may be empty
};

enum class EquilibriumBifurcationType { fold, hopf, branch_point };
// "fold", "hopf", "branch_point".
std::string to_string(EquilibriumBifurcationType type);

struct EquilibriumBifurcation {
  EquilibriumBifurcationType type = EquilibriumBifurcationType::fold;
  double parameter = 0;
  double parameter_bound = 0;  // the final bracket's width in p (<= tolerance), or less where Re lambda hit 0
  Eigen::VectorXd state;       // the equilibrium there
  CharacteristicRoot root;     // the critical root (Im >= 0), refined there
  double omega = 0, period = 0;  // Hopf: Im lambda and 2 pi / omega (0 otherwise)
  std::optional<HopfNormalForm> normal_form;  // Hopf, where the family has a Jacobian: l1 and criticality
  int evaluations = 0;           // branch points computed to locate it
};

struct EquilibriumPoint {
  double parameter = 0;
  EquilibriumResult equilibrium;  // the state and its rightmost roots
  int corrector_iterations = 0;
};

struct EquilibriumBranch {
  std::vector<EquilibriumPoint> points;
  std::vector<EquilibriumBifurcation> bifurcations;  // in order along the branch
  BranchEnd end = BranchEnd::max_points;
  std::string failure;  // when end == failure: where and why
};

// BadInput for options out of range; NumericalFailure when the start has no equilibrium. A step
// that cannot be corrected even at step_min ends the branch (end = failure, the points so far).
EquilibriumBranch continue_equilibrium(const EquilibriumFamily& family, const Eigen::VectorXd& guess,
                                       const EquilibriumBranchOptions& options);

}  // namespace delayspec
