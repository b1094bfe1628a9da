#pragma once
// Hopf curves of an equilibrium in two parameters (issue 60, item 1), on the exact characteristic
// function, with the criticality along them and the generalised Hopf points where it changes
// (item 3).
//
// The curve is the zero set of g(x, y) = Re lambda(x, y), lambda the critical root followed from
// the start: at each evaluation the equilibrium by Newton from the last one (equilibrium_state)
// and lambda by Newton on c(lambda) = det Delta(lambda) from the last root (refined_root), so g
// carries no discretisation error and the curve is located to the tracer's tolerance. g is
// followed by the boundary tracer (boundary.hpp: pseudo-arclength in the scaled plane, step
// control by the chord, turning points passed), which ends the curve at x_to, back at x_from, or
// where it leaves the y range. g is undefined (the tracer halves its step) where Newton fails or
// the root followed jumps (moves by more than a tenth of its size and 0.1 in one evaluation: it
// would be another root), and where the pair turns real (omega -> 0: a Bogdanov-Takens or
// zero-Hopf point ends the curve there, a failure named).
//
// Starts: on the line x = x_from (and with scan_lines > 1 on scan_lines lines x = const across
// the range), the branch of equilibria in y (continue_equilibrium, every Hopf point located and
// checked as in one parameter); each Hopf point not already on a traced curve starts one, traced
// both ways (trace_boundary_both_ways).
//
// Along each curve every point gets omega and, with a Jacobian in the family, its first Lyapunov
// coefficient (hopf_normal_form.hpp), and its other rightmost roots (the family's equilibrium,
// nroots of them). Codim-2 points between two consecutive points: a generalised Hopf point where
// l1 changes sign, each decided (|l1| > l1_bound); a double Hopf point (a second pair) or a
// zero-Hopf point (a real root) where the count of the other roots with Re > 0 changes, the root
// that crossed followed back by Newton on c. Each is located by Illinois on its scalar (l1, or Re
// of the other root) along the chord between the two points, each trial point moved onto the
// curve along the chord's normal (boundary_offset_along); its bound is the final bracket plus the
// scalar's own error over its slope (how far that error moves the zero), in the plane's units.
#include <complex>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/boundary.hpp"
#include "delayspec/equilibrium.hpp"
#include "delayspec/equilibrium_branch.hpp"
#include "delayspec/hopf_normal_form.hpp"

namespace delayspec {

// The model at the parameter pair (x, y), as EquilibriumFamily is at one parameter.
struct EquilibriumFamily2 {
  std::function<ConstantHistory(const Eigen::VectorXd& state, double x, double y)> at;
  std::function<EquilibriumResult(const Eigen::VectorXd& guess, double x, double y, int nroots)> equilibrium;
  // [A B] on any history (hopf_normal_form.hpp); empty: no l1 along the curves
  std::function<Eigen::MatrixXd(const Eigen::VectorXd& state, const Eigen::VectorXd& delayed, double x, double y)>
      jacobian;
};

struct HopfCurveOptions {
  BoundaryOptions boundary;       // the ranges, steps and tolerance of the tracer (scaled plane)
  EquilibriumOptions equilibrium;  // Newton's tolerance, nroots and N of the starting roots
  int scan_lines = 1;              // lines x = const searched for starts (1: x_from only)
};

struct HopfCurvePoint {
  double x = 0, y = 0;
  Eigen::VectorXd state;
  CharacteristicRoot root;  // the critical root, Im > 0
  std::optional<HopfNormalForm> normal_form;
};

enum class HopfCodim2Kind {
  generalised_hopf,  // l1 = 0
  double_hopf,       // a second pair on the axis
  zero_hopf          // a real root at 0 (fold-Hopf)
};
// "generalised_hopf", "double_hopf", "zero_hopf".
std::string to_string(HopfCodim2Kind kind);

struct HopfCodim2Point {
  HopfCodim2Kind kind = HopfCodim2Kind::generalised_hopf;
  double x = 0, y = 0;
  double bound = 0;  // on its distance from the exact point, in the plane's units (max over x and y)
  Eigen::VectorXd state;
  double omega = 0;                 // the curve's pair
  std::complex<double> second_root;  // double and zero Hopf: the other root on the axis
  int evaluations = 0;
};

struct HopfCurve {
  std::vector<HopfCurvePoint> points;
  BoundaryEnd end = BoundaryEnd::max_points;
  std::string note;
  std::vector<HopfCodim2Point> codim2;  // in order along the curve
  std::vector<std::string> notes;       // a change that could not be located, a point left out: where and why
};

struct HopfCurves {
  std::vector<HopfCurve> curves;
  std::vector<std::string> notes;  // a line whose equilibria could not be followed: where and why
};

// BadInput for options out of range (boundary.hpp's, scan_lines < 1); NumericalFailure when the
// equilibrium at (x_from, y_from) cannot be found from `guess`.
HopfCurves hopf_curves(const EquilibriumFamily2& family, const Eigen::VectorXd& guess, const HopfCurveOptions& options);

// Fold curves: where the equilibrium itself folds (a real root at 0, J = A + sum B_i singular),
// the nested form above cannot work (on one side of the curve there is no equilibrium to solve
// for), so the curve is traced on the extended system in z = (y*, x, y), d + 2 unknowns:
//
//   f(y*, ..., y*; x, y) = 0   (d equations),   g(y*; x, y) = 0,
//
// g the last entry of the bordered solve [J b; c^T 0] (v, g) = (0, 1) (Govaerts), b and c the
// left and right singular vectors of J's least singular value at the start: g is smooth, vanishes
// exactly where J is singular, and is of J's scale. Pseudo-arclength in (y*, u, v), u and v the
// parameters scaled to [0, 1] by the ranges; the extended system's Jacobian by central differences
// (relative step 1e-7: a Jacobian error ~1e-7 slows Newton, not its solution); predictor along the
// tangent (the kernel of that Jacobian, oriented as before), corrector Newton with the arclength
// row, converged at |dz| <= tolerance; a failed correction halves the step, an easy one (<= 3
// iterations) grows it by 1.5 up to step_max. Ends: a point past x_to, back past x_from or out of
// the y range is corrected onto the edge (the crossed coordinate fixed) and ends the curve there;
// max_points; a step below step_min (failure, named). Starts: the folds of the branch of
// equilibria in y at x_from (and scan lines), each not already on a curve, traced both ways.
//
// Bogdanov-Takens points on a fold curve (issue 60 item 3): where the fold's zero root is double,
// c(lambda) = det Delta(lambda) has c'(0) = 0 too. With q and p the null vectors of J and J^T from
// the bordered systems above (so normalised smoothly along the curve: c^T q = 1, b^T p = 1), the
// test function
//
//   bt = p^T Delta'(0) q,   Delta'(0) = I + sum_i tau_i B_i,
//
// vanishes exactly there (p^T Delta'(0) q is c'(0) up to a nonzero factor where the zero root is
// simple in J's kernel). A sign change of bt between two curve points is located by Illinois
// along the chord, each trial corrected onto the curve in the hyperplane normal to the chord
// (Newton on the extended system); the bound is the final bracket in the plane's units plus the
// corrector's tolerance over the ranges (as for the Hopf curves' codim-2 points).
//
// Cusp points, where the fold's quadratic coefficient vanishes (two folds meet), the same way on
// the test p^T D^2 F(y*)(q, q), F(y) = f(y, ..., y) on constant histories (the zero root's
// eigenfunction is the constant q), its second derivative as the central difference of the
// family's Jacobian [A B] along q (step 1e-4 (1 + |y*|) / |q|: an O(1e-8) relative error, far
// below the test's change near a transversal zero). Only with a Jacobian in the family.
struct FoldCurvePoint {
  double x = 0, y = 0;
  Eigen::VectorXd state;
};

enum class FoldCodim2Kind {
  bogdanov_takens,  // the zero root double
  cusp              // the fold's quadratic coefficient zero
};
// "bogdanov_takens", "cusp".
std::string to_string(FoldCodim2Kind kind);

struct FoldCodim2Point {
  FoldCodim2Kind kind = FoldCodim2Kind::bogdanov_takens;
  double x = 0, y = 0;
  double bound = 0;  // on its distance from the exact point, in the plane's units (max over x and y)
  Eigen::VectorXd state;
  int evaluations = 0;
};

struct FoldCurve {
  std::vector<FoldCurvePoint> points;
  BoundaryEnd end = BoundaryEnd::max_points;
  std::string note;
  std::vector<FoldCodim2Point> codim2;  // in order along the curve, kind by kind
  std::vector<std::string> notes;                    // a sign change that could not be located: where and why
};

struct FoldCurves {
  std::vector<FoldCurve> curves;
  std::vector<std::string> notes;
};

FoldCurves fold_curves(const EquilibriumFamily2& family, const Eigen::VectorXd& guess, const HopfCurveOptions& options);

}  // namespace delayspec
