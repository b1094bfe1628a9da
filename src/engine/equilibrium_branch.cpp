// The branch of equilibria and its fold and Hopf points (equilibrium_branch.hpp for the method).
#include "delayspec/equilibrium_branch.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Dense>

#include "delayspec/detail/illinois.hpp"
#include "delayspec/errors.hpp"

namespace delayspec {

std::string to_string(EquilibriumBifurcationType type) {
  switch (type) {
    case EquilibriumBifurcationType::fold: return "fold";
    case EquilibriumBifurcationType::hopf: return "hopf";
    case EquilibriumBifurcationType::branch_point: return "branch_point";
  }
  return "?";
}

namespace {

// x = (y, p) on the branch, with the unit tangent there.
struct OnBranch {
  Eigen::VectorXd x, tangent;
  double p() const { return x(x.size() - 1); }
  Eigen::VectorXd y() const { return x.head(x.size() - 1); }
};

class Tracer {
 public:
  Tracer(const EquilibriumFamily& family, const EquilibriumBranchOptions& o) : family_(family), o_(o) {}

  // [F_y F_p] at x, F_p by central differences (header comment).
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& x, Eigen::VectorXd* F = nullptr) const {
    const long d = x.size() - 1;
    const Eigen::VectorXd y = x.head(d);
    const double p = x(d), delta = std::cbrt(std::numeric_limits<double>::epsilon()) * (1 + std::abs(p));
    const ConstantHistory h = family_.at(y, p);
    if (F) *F = h.f;
    Eigen::MatrixXd DF(d, d + 1);
    DF.leftCols(d) = h.jacobian();
    DF.col(d) = (family_.at(y, p + delta).f - family_.at(y, p - delta).f) / (2 * delta);
    return DF;
  }

  // The unit null vector of DF, on the side of `previous`.
  static Eigen::VectorXd tangent(const Eigen::MatrixXd& DF, const Eigen::VectorXd& previous) {
    const long n = DF.cols();
    Eigen::MatrixXd M(n, n);
    M << DF, previous.transpose();
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
    rhs(n - 1) = 1;
    Eigen::VectorXd t = Eigen::FullPivLU<Eigen::MatrixXd>(M).solve(rhs);
    return t / t.norm();
  }

  // Corrects the predictor x_pred = from.x + h from.tangent onto the branch (Newton on
  // [F; t . (x - x_pred)]); false when it does not converge.
  bool correct(const OnBranch& from, double h, OnBranch& out, int& iterations) const {
    const Eigen::VectorXd x_pred = from.x + h * from.tangent;
    Eigen::VectorXd x = x_pred;
    const long n = x.size();
    for (iterations = 1; iterations <= o_.newton_iterations; ++iterations) {
      Eigen::VectorXd F;
      const Eigen::MatrixXd DF = jacobian(x, &F);
      Eigen::MatrixXd M(n, n);
      M << DF, from.tangent.transpose();
      Eigen::VectorXd G(n);
      G << F, from.tangent.dot(x - x_pred);
      const Eigen::FullPivLU<Eigen::MatrixXd> lu(M);
      if (!lu.isInvertible() || !G.allFinite()) return false;
      const Eigen::VectorXd dx = lu.solve(G);
      x -= dx;
      if (!x.allFinite()) return false;
      if (dx.lpNorm<Eigen::Infinity>() <= o_.newton_tolerance * (1 + x.lpNorm<Eigen::Infinity>())) {
        out.x = x;
        out.tangent = tangent(jacobian(x), from.tangent);
        return true;
      }
    }
    return false;
  }

  const EquilibriumFamily& family() const { return family_; }
  const EquilibriumBranchOptions& options() const { return o_; }

 private:
  const EquilibriumFamily& family_;
  const EquilibriumBranchOptions& o_;
};

// Roots are refined with the equilibrium's own tolerance.
EquilibriumOptions root_options(const Tracer& tracer) {
  EquilibriumOptions o;
  o.tolerance = tracer.options().newton_tolerance;
  return o;
}

// The roots of `b` (Im >= 0) that crossed the imaginary axis between a and b, each followed back
// to a by Newton on c there: {at a, at b} per root. Empty when none crossed (a count changed by
// roots beyond the ones returned).
std::vector<std::pair<std::complex<double>, std::complex<double>>> crossing_roots(const Tracer& tracer,
                                                                                const OnBranch& a,
                                                                                const EquilibriumResult& rb) {
  const ConstantHistory ha = tracer.family().at(a.y(), a.p());
  std::vector<std::pair<std::complex<double>, std::complex<double>>> crossed;
  for (const CharacteristicRoot& root : rb.roots) {
    if (root.value.imag() < 0) continue;
    CharacteristicRoot back;
    try {
      back = refined_root(ha, root.value, root_options(tracer));
    } catch (const NumericalFailure&) {
      continue;
    }
    if ((back.value.real() > 0) != (root.value.real() > 0)) crossed.emplace_back(back.value, root.value);
  }
  return crossed;
}

// Locates Re lambda = 0 on the segment from a (arclength 0) to b (arclength h, the corrected
// point there), lambda the root followed from lambda_a to lambda_b: Illinois on the arclength s.
// `s` receives the arclength of the location (the order along the segment).
EquilibriumBifurcation locate(const Tracer& tracer, const OnBranch& a, double h, const OnBranch& b,
                              std::complex<double> lambda_a, std::complex<double> lambda_b, double tolerance,
                              double& s_located) {
  struct End {
    double s, p;
    std::complex<double> lambda;
  };
  End lo{0, a.p(), lambda_a}, hi{h, b.p(), lambda_b};
  // (the end a is hi: a value of hi's sign replaces it, as before illinois.hpp)
  detail::IllinoisValues illinois{hi.lambda.real(), lo.lambda.real()};
  EquilibriumBifurcation out;
  OnBranch at;
  CharacteristicRoot root;
  for (out.evaluations = 1; out.evaluations <= 100; ++out.evaluations) {
    const double s = illinois.root(hi.s, lo.s);
    int its = 0;
    if (!tracer.correct(a, s, at, its))
      throw NumericalFailure("a point inside the segment could not be corrected while locating the crossing");
    s_located = s;
    const double w = (s - lo.s) / (hi.s - lo.s);
    root = refined_root(tracer.family().at(at.y(), at.p()), (1 - w) * lo.lambda + w * hi.lambda,
                        root_options(tracer));
    const double g = root.value.real();
    const End c{s, at.p(), root.value};
    // On the axis to rounding: the slope gives the bound. (Not to the root's error_bound, Newton's
    // last step: the root is far more accurate than that, and the bracket goes on shrinking.)
    const double rounding = 4 * std::numeric_limits<double>::epsilon() * (1 + std::abs(root.value));
    if (std::abs(g) <= rounding) {
      out.parameter_bound = rounding * std::abs(hi.p - lo.p) / std::abs(illinois.a - illinois.b);
      break;
    }
    (illinois.replace(g) < 0 ? hi : lo) = c;
    out.parameter_bound = std::abs(hi.p - lo.p);
    if (out.parameter_bound <= tolerance) break;
  }
  if (out.parameter_bound > tolerance)
    throw NumericalFailure("the crossing near p = " + format_number(at.p()) + " was not located to " +
                           format_number(tolerance) + " in 100 evaluations (bracket " +
                           format_number(out.parameter_bound) + ")");
  out.parameter = at.p();
  out.state = at.y();
  out.root = root;
  if (root.value.imag() > root.error_bound) {
    out.type = EquilibriumBifurcationType::hopf;
    out.omega = root.value.imag();
    out.period = 2 * std::numbers::pi / out.omega;
  }
  return out;
}

}  // namespace

EquilibriumBranch continue_equilibrium(const EquilibriumFamily& family, const Eigen::VectorXd& guess,
                                       const EquilibriumBranchOptions& options) {
  EquilibriumBranchOptions o = options;
  static_cast<BranchRange&>(o) = checked_range(options);
  const double direction = o.to > o.from ? 1 : -1;
  const Tracer tracer(family, o);

  EquilibriumBranch branch;
  EquilibriumPoint first{o.from, family.equilibrium(guess, o.from), 0};
  const long d = first.equilibrium.state.size();
  OnBranch here;
  here.x.resize(d + 1);
  here.x << first.equilibrium.state, o.from;
  Eigen::VectorXd along_p = Eigen::VectorXd::Zero(d + 1);
  along_p(d) = direction;
  here.tangent = Tracer::tangent(tracer.jacobian(here.x), along_p);
  branch.points.push_back(std::move(first));
  if (o.on_point) o.on_point();

  double h = o.step;
  while (static_cast<int>(branch.points.size()) < o.max_points) {
    OnBranch next;
    int iterations = 0;
    if (!tracer.correct(here, h, next, iterations)) {
      h /= 2;
      if (h < o.step_min) {
        branch.end = BranchEnd::failure;
        branch.failure = "at p = " + format_number(here.p()) + " no step down to continue_step_min = " +
                         format_number(o.step_min) + " could be corrected onto the branch";
        return branch;
      }
      continue;
    }
    // Past `to`: land on it (Newton at p = to from the point interpolated there); past `from`
    // (the branch turned back): stop.
    const bool past_to = (next.p() - o.to) * direction > 0, past_from = (next.p() - o.from) * direction < 0;
    EquilibriumPoint point{next.p(), {}, iterations};
    if (past_to) {
      const double w = (o.to - here.p()) / (next.p() - here.p());
      point.parameter = o.to;
      point.equilibrium = family.equilibrium((1 - w) * here.y() + w * next.y(), o.to);
    } else {
      point.equilibrium = family.equilibrium(next.y(), next.p());
    }
    const EquilibriumResult& previous = branch.points.back().equilibrium;
    if (point.equilibrium.unstable != previous.unstable) {
      // every root that crossed, each located on its own, in order of arclength along the segment
      std::vector<std::pair<double, EquilibriumBifurcation>> found;
      try {
        for (const auto& [at_here, at_next] : crossing_roots(tracer, here, point.equilibrium)) {
          double s = 0;
          EquilibriumBifurcation b = locate(tracer, here, h, next, at_here, at_next, o.tolerance, s);
          if (b.type != EquilibriumBifurcationType::hopf)
            b.type = here.tangent(d) * next.tangent(d) < 0 ? EquilibriumBifurcationType::fold
                                                           : EquilibriumBifurcationType::branch_point;
          if (!past_to || (b.parameter - o.to) * direction <= 0) found.emplace_back(s, std::move(b));
        }
      } catch (const NumericalFailure& e) {  // the branch so far stands; the failure is named
        branch.end = BranchEnd::failure;
        branch.failure = "locating a crossing after p = " + format_number(here.p()) + ": " + e.what();
        return branch;
      }
      std::sort(found.begin(), found.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      for (auto& [s, b] : found) branch.bifurcations.push_back(std::move(b));
    }
    branch.points.push_back(std::move(point));
    if (o.on_point) o.on_point();
    if (past_to) {
      branch.end = BranchEnd::to;
      return branch;
    }
    if (past_from) {
      branch.end = BranchEnd::from;
      return branch;
    }
    here = next;
    if (iterations <= 3) h = std::min(1.5 * h, o.step_max);
  }
  branch.end = BranchEnd::max_points;
  return branch;
}

}  // namespace delayspec
