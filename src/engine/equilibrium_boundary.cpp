// Hopf curves of an equilibrium in two parameters: the method is in equilibrium_boundary.hpp.
#include "delayspec/equilibrium_boundary.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <utility>

#include <Eigen/Dense>
#include <Eigen/SVD>

#include "delayspec/detail/illinois.hpp"
#include "delayspec/errors.hpp"

namespace delayspec {

std::string to_string(FoldCodim2Kind kind) {
  return kind == FoldCodim2Kind::bogdanov_takens ? "bogdanov_takens" : "cusp";
}

std::string to_string(HopfCodim2Kind kind) {
  switch (kind) {
    case HopfCodim2Kind::generalised_hopf: return "generalised_hopf";
    case HopfCodim2Kind::double_hopf: return "double_hopf";
    case HopfCodim2Kind::zero_hopf: return "zero_hopf";
  }
  return "generalised_hopf";
}

namespace {

using cd = std::complex<double>;

// g(x, y) = Re lambda of the root followed (header comment). Every successful evaluation is kept:
// the next one starts Newton from the nearest in the scaled plane (the tracer comes back to its
// start for the curve's second half, and its trial points jump about a point).
class HopfTest {
 public:
  HopfTest(const EquilibriumFamily2& family, const HopfCurveOptions& o, double x, double y, Eigen::VectorXd state,
           cd root)
      : family_(family), o_(o) {
    known_.push_back({x, y, std::move(state), root});
  }

  BoundarySample operator()(double x, double y) {
    BoundarySample s;
    HopfCurvePoint p;
    s.reason = evaluate(x, y, p, false);
    s.defined = s.reason.empty();
    if (s.defined) s.value = p.root.value.real();
    return s;
  }

  // The point at (x, y) with its normal form; the reason when g is undefined there.
  std::string point(double x, double y, HopfCurvePoint& p) { return evaluate(x, y, p, true); }

  // The last (x, y) where the pair turned real (omega -> 0), if any
  const std::optional<std::pair<double, double>>& turned_real() const { return turned_real_; }

 private:
  struct Known {
    double x, y;
    Eigen::VectorXd state;
    cd root;
  };

  const Known& nearest(double x, double y) const {
    const double sx = std::abs(o_.boundary.x_to - o_.boundary.x_from), sy = std::abs(o_.boundary.y_to - o_.boundary.y_from);
    const Known* best = &known_.front();
    double least = std::numeric_limits<double>::infinity();
    for (const Known& k : known_) {
      const double d = std::hypot((k.x - x) / sx, (k.y - y) / sy);
      if (d < least) least = d, best = &k;
    }
    return *best;
  }

  std::string evaluate(double x, double y, HopfCurvePoint& p, bool with_normal_form) {
    const Known& from = nearest(x, y);
    const cd start = from.root;
    try {
      EquilibriumResult r;
      equilibrium_state([&](const Eigen::VectorXd& s) { return family_.at(s, x, y); }, from.state, o_.equilibrium, r);
      const ConstantHistory h = family_.at(r.state, x, y);
      const CharacteristicRoot root = refined_root(h, start, o_.equilibrium);
      const double moved = std::abs(root.value - start);
      if (moved > 0.1 * std::abs(start) && moved > 0.1)
        return "the root followed jumped from " + format_complex(start) + " to " + format_complex(root.value) +
               " at (" + format_number(x) + ", " + format_number(y) + ")";
      if (!(root.value.imag() > 1e-8 * (1 + std::abs(root.value)))) {
        turned_real_ = {x, y};
        return "the critical pair turned real at (" + format_number(x) + ", " + format_number(y) +
               "): omega = " + format_number(root.value.imag()) + " (a Bogdanov-Takens or zero-Hopf point)";
      }
      p.x = x, p.y = y, p.state = r.state, p.root = root;
      if (with_normal_form && family_.jacobian)
        p.normal_form = hopf_normal_form(
            [&](const Eigen::VectorXd& s, const Eigen::VectorXd& w) { return family_.jacobian(s, w, x, y); }, h,
            r.state, root);
      if (known_.size() < 100000) known_.push_back({x, y, r.state, root.value});
      return "";
    } catch (const NumericalFailure& e) {
      return std::string("at (") + format_number(x) + ", " + format_number(y) + "): " + e.what();
    }
  }

  const EquilibriumFamily2& family_;
  const HopfCurveOptions& o_;
  std::vector<Known> known_;
  std::optional<std::pair<double, double>> turned_real_;
};

bool decided(const HopfCurvePoint& p) {
  return p.normal_form && std::isfinite(p.normal_form->l1) && std::abs(p.normal_form->l1) > p.normal_form->l1_bound;
}

// A scalar along the curve at a point (a trial moved onto it): its value and a bound on its
// error; nullopt with the reason when it cannot be had there.
using CurveValue = std::function<std::optional<std::pair<double, double>>(const HopfCurvePoint&, std::string&)>;

// The codim-2 point between curve points a and b where `value` changes sign (va, vb: its values at
// them): Illinois in the position t along the chord, each trial moved onto the curve along the
// chord's normal. Its bound: the final bracket plus how far the value's own error moves its zero
// (error / |dvalue/dt|, the slope the chord's secant), and the curve's tolerance.
std::optional<HopfCodim2Point> locate_between(HopfTest& test, const HopfCurvePoint& a, const HopfCurvePoint& b,
                                              double va, double vb, const CurveValue& value, const BoundaryOptions& o,
                                              std::string& why) {
  const double sx = std::abs(o.x_to - o.x_from), sy = std::abs(o.y_to - o.y_from);
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double chord = std::hypot(dx / sx, dy / sy);  // scaled
  // the normal in the scaled plane, back in the plane's units
  const double nx = -dy / sy / chord * sx, ny = dx / sx / chord * sy;
  const BoundaryFunction g = [&test](double x, double y) { return test(x, y); };
  HopfCodim2Point out;
  HopfCurvePoint at;
  double lo = 0, hi = 1, error = 0;
  detail::IllinoisValues illinois{va, vb};
  for (int k = 0; k < 60 && (hi - lo) * chord > o.tolerance; ++k) {
    const double t = std::clamp(illinois.root(lo, hi), lo + 0.01 * (hi - lo), hi - 0.01 * (hi - lo));
    const double x0 = a.x + t * dx, y0 = a.y + t * dy;
    const double s = boundary_offset_along(g, x0, y0, nx, ny, 1e-3 * chord, o.tolerance);
    if (!std::isfinite(s)) {
      why = "no point of the curve on the chord's normal at t = " + format_number(t);
      return std::nullopt;
    }
    if (const std::string reason = test.point(x0 + s * nx, y0 + s * ny, at); !reason.empty()) {
      why = reason;
      return std::nullopt;
    }
    const auto v = value(at, why);
    if (!v) return std::nullopt;
    ++out.evaluations;
    error = v->second;
    if (v->first == 0) {
      lo = hi = t;
      break;
    }
    (illinois.replace(v->first) < 0 ? lo : hi) = t;
  }
  out.x = at.x, out.y = at.y, out.state = at.state, out.omega = at.root.value.imag();
  const double t_spread = (hi - lo) + error / std::abs(vb - va);
  out.bound = std::max(std::abs(dx), std::abs(dy)) * t_spread + o.tolerance * std::max(sx, sy);
  return out;
}

// The roots of the equilibrium at a curve point other than the critical pair, rightmost first.
std::vector<CharacteristicRoot> other_roots(const EquilibriumFamily2& family, const HopfCurvePoint& p,
                                            const EquilibriumOptions& o) {
  std::vector<CharacteristicRoot> out;
  const cd c = p.root.value;
  for (const CharacteristicRoot& r : family.equilibrium(p.state, p.x, p.y, o.nroots).roots)
    if (std::abs(r.value - c) > 1e-6 * (1 + std::abs(c)) && std::abs(r.value - std::conj(c)) > 1e-6 * (1 + std::abs(c)))
      out.push_back(r);
  return out;
}

int count_right(const std::vector<CharacteristicRoot>& roots) {
  return static_cast<int>(std::count_if(roots.begin(), roots.end(), [](const CharacteristicRoot& r) {
    return r.value.real() > 0 && r.value.imag() >= 0;  // a pair counted once
  }));
}

// Along one traced curve: the generalised Hopf points (l1 changes sign between two decided points)
// and where another root crosses the axis (the count of the other roots with Re > 0 changes): a
// double Hopf point (a second pair) or a zero-Hopf point (a real root), each located between the
// two points (locate_between).
void codim2_points(HopfTest& test, const EquilibriumFamily2& family, const HopfCurveOptions& o, HopfCurve& curve) {
  const auto note = [&](const HopfCurvePoint& p, const HopfCurvePoint& q, const std::string& what, const std::string& why) {
    curve.notes.push_back(what + " between (" + format_number(p.x) + ", " + format_number(p.y) + ") and (" +
                          format_number(q.x) + ", " + format_number(q.y) + "), not located: " + why);
  };
  std::vector<std::vector<CharacteristicRoot>> others;
  for (const HopfCurvePoint& p : curve.points) {
    try {
      others.push_back(other_roots(family, p, o.equilibrium));
    } catch (const NumericalFailure& e) {
      others.emplace_back();
      curve.notes.push_back("the other roots at (" + format_number(p.x) + ", " + format_number(p.y) + "): " + e.what());
    }
  }
  for (size_t i = 0; i + 1 < curve.points.size(); ++i) {
    const HopfCurvePoint &p = curve.points[i], &q = curve.points[i + 1];
    std::string why;
    if (decided(p) && decided(q) && (p.normal_form->l1 > 0) != (q.normal_form->l1 > 0)) {
      const CurveValue l1 = [](const HopfCurvePoint& at, std::string& reason) -> std::optional<std::pair<double, double>> {
        if (!at.normal_form || !std::isfinite(at.normal_form->l1)) {
          reason = at.normal_form ? at.normal_form->note : "no normal form";
          return std::nullopt;
        }
        return std::pair{at.normal_form->l1, at.normal_form->l1_bound};
      };
      if (auto gh = locate_between(test, p, q, p.normal_form->l1, q.normal_form->l1, l1, o.boundary, why)) {
        gh->kind = HopfCodim2Kind::generalised_hopf;
        curve.codim2.push_back(std::move(*gh));
      } else {
        note(p, q, "l1 changes sign", why);
      }
    }
    if (others[i].empty() || others[i + 1].empty() || count_right(others[i]) == count_right(others[i + 1])) continue;
    // the root that crossed: of q's others the one nearest the axis, followed back to p
    const CharacteristicRoot* crossing = &others[i + 1].front();
    for (const CharacteristicRoot& r : others[i + 1])
      if (r.value.imag() >= 0 && std::abs(r.value.real()) < std::abs(crossing->value.real())) crossing = &r;
    cd followed = crossing->value;
    const CurveValue re = [&](const HopfCurvePoint& at, std::string& reason) -> std::optional<std::pair<double, double>> {
      try {
        const CharacteristicRoot r = refined_root(family.at(at.state, at.x, at.y), followed, o.equilibrium);
        followed = r.value;
        return std::pair{r.value.real(), r.error_bound};
      } catch (const NumericalFailure& e) {
        reason = e.what();
        return std::nullopt;
      }
    };
    const auto at_p = re(p, why);
    const double vq = crossing->value.real();
    followed = crossing->value;
    if (!at_p || (at_p->first > 0) == (vq > 0)) {
      note(p, q, "another root crosses the axis", at_p ? "the root followed back does not change sign" : why);
      continue;
    }
    if (auto point = locate_between(test, p, q, at_p->first, vq, re, o.boundary, why)) {
      point->second_root = followed;
      point->kind = std::abs(followed.imag()) > 1e-6 * (1 + std::abs(followed)) ? HopfCodim2Kind::double_hopf
                                                                                : HopfCodim2Kind::zero_hopf;
      curve.codim2.push_back(std::move(*point));
    } else {
      note(p, q, "another root crosses the axis", why);
    }
  }
}


// The lines x = const searched for starts (scan_lines of them across the range, or x_from) and the
// branch of equilibria in y along each (its bifurcations located and checked, equilibrium_branch.hpp):
// `visit(x, branch)` for each; a line whose branch cannot start is noted (the first one throws).
template <class Visit>
void search_lines(const EquilibriumFamily2& family, const Eigen::VectorXd& guess, const HopfCurveOptions& o,
                  std::vector<std::string>& notes, Visit visit) {
  const BoundaryOptions& b = o.boundary;
  if (o.scan_lines < 1) throw BadInput("`HopfCurveOptions::scan_lines = " + std::to_string(o.scan_lines) + "`: must be >= 1");
  if (b.x_from == b.x_to || b.y_from == b.y_to) throw BadInput("equilibrium curves: an empty range");
  Eigen::VectorXd line_guess = guess;
  for (int line = 0; line < o.scan_lines; ++line) {
    const double x = o.scan_lines == 1 ? b.x_from : b.x_from + (b.x_to - b.x_from) * line / (o.scan_lines - 1);
    const EquilibriumFamily along{
        [&family, x](const Eigen::VectorXd& s, double y) { return family.at(s, x, y); },
        [&family, x](const Eigen::VectorXd& g, double y, int nroots) { return family.equilibrium(g, x, y, nroots); },
        nullptr};
    EquilibriumBranchOptions bo;
    bo.from = b.y_from, bo.to = b.y_to;
    bo.newton_tolerance = o.equilibrium.tolerance;
    bo.nroots = o.equilibrium.nroots;
    EquilibriumBranch branch;
    try {
      branch = continue_equilibrium(along, line_guess, bo);
    } catch (const NumericalFailure& e) {
      if (line == 0) throw;
      notes.push_back("the line x = " + format_number(x) + ": " + e.what());
      continue;
    }
    line_guess = branch.points.front().equilibrium.state;
    if (branch.end == BranchEnd::failure) notes.push_back("the line x = " + format_number(x) + ": " + branch.failure);
    visit(x, branch);
  }
}

}  // namespace

HopfCurves hopf_curves(const EquilibriumFamily2& family, const Eigen::VectorXd& guess, const HopfCurveOptions& o) {
  const BoundaryOptions& b = o.boundary;
  HopfCurves out;
  std::vector<BoundaryCurve> traced;
  search_lines(family, guess, o, out.notes, [&](double x, const EquilibriumBranch& branch) {
    for (const EquilibriumBifurcation& h : branch.bifurcations) {
      if (h.type != EquilibriumBifurcationType::hopf) continue;
      if (on_boundary_curve(traced, x, h.parameter, 1e-3 * std::abs(b.y_to - b.y_from))) continue;  // as orbit curves
      HopfTest test(family, o, x, h.parameter, h.state, h.root.value);
      const BoundaryFunction g = [&test](double px, double py) { return test(px, py); };
      BoundaryCurve c;
      try {
        c = trace_boundary_both_ways(g, b, x, h.parameter);
      } catch (const NumericalFailure& e) {
        out.notes.push_back("the Hopf point at (" + format_number(x) + ", " + format_number(h.parameter) + "): " + e.what());
        continue;
      }
      HopfCurve curve;
      curve.end = c.end;
      curve.note = c.note;
      // A curve that could go no further because its pair turned real right ahead (within 1e-3
      // of the range) ends at a Bogdanov-Takens or zero-Hopf point, not in a failure; the point
      // is named, not located (omega -> 0 leaves no scalar that changes sign there).
      if (const auto& at = test.turned_real(); c.end == BoundaryEnd::failure && at && !c.points.empty() &&
                                                std::hypot((at->first - c.points.back().x) / (b.x_to - b.x_from),
                                                           (at->second - c.points.back().y) / (b.y_to - b.y_from)) < 1e-3) {
        curve.end = BoundaryEnd::codim2;
        curve.note = "omega -> 0 at (" + format_number(at->first) + ", " + format_number(at->second) +
                     "): a Bogdanov-Takens point (or zero-Hopf where omega stays away from 0), not located";
      }
      for (const BoundaryPoint& bp : c.points) {
        HopfCurvePoint p;
        if (const std::string why = test.point(bp.x, bp.y, p); !why.empty()) {
          curve.notes.push_back("a point left out: " + why);
          continue;
        }
        curve.points.push_back(std::move(p));
      }
      codim2_points(test, family, o, curve);
      traced.push_back(std::move(c));
      out.curves.push_back(std::move(curve));
    }
  });
  return out;
}

namespace {

// The extended system of a fold curve (equilibrium_boundary.hpp) in z = (y*, u, v), u and v the
// parameters scaled to [0, 1] by the ranges.
class FoldSystem {
 public:
  FoldSystem(const EquilibriumFamily2& family, const BoundaryOptions& o, long d) : family_(family), o_(o), d_(d) {}

  double x(const Eigen::VectorXd& z) const { return o_.x_from + z[d_] * (o_.x_to - o_.x_from); }
  double y(const Eigen::VectorXd& z) const { return o_.y_from + z[d_ + 1] * (o_.y_to - o_.y_from); }
  Eigen::VectorXd z_of(const Eigen::VectorXd& state, double x, double y) const {
    Eigen::VectorXd z(d_ + 2);
    z << state, (x - o_.x_from) / (o_.x_to - o_.x_from), (y - o_.y_from) / (o_.y_to - o_.y_from);
    return z;
  }

  // The borders: J's singular vectors of its least singular value at z (fixed for a curve).
  void set_borders(const Eigen::VectorXd& z) {
    const Eigen::MatrixXd J = family_.at(z.head(d_), x(z), y(z)).jacobian();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullU | Eigen::ComputeFullV);
    left_ = svd.matrixU().col(d_ - 1);
    right_ = svd.matrixV().col(d_ - 1);
  }

  // (f, g) at z: d + 1 values
  Eigen::VectorXd F(const Eigen::VectorXd& z) const {
    const ConstantHistory h = family_.at(z.head(d_), x(z), y(z));
    Eigen::VectorXd out(d_ + 1);
    out << h.f, bordered(h).fullPivLu().solve(unit_last())[d_];
    return out;
  }

  // The Bogdanov-Takens test p^T Delta'(0) q at z (equilibrium_boundary.hpp), q and p the first d
  // entries of the bordered solves [J b; c^T 0] (q, g) = (0, 1) and its transpose's.
  double bogdanov_takens_test(const Eigen::VectorXd& z) const {
    const ConstantHistory h = family_.at(z.head(d_), x(z), y(z));
    const Eigen::MatrixXd M = bordered(h);
    const Eigen::VectorXd q = M.fullPivLu().solve(unit_last()).head(d_);
    const Eigen::VectorXd p = M.transpose().fullPivLu().solve(unit_last()).head(d_);
    Eigen::MatrixXcd derivative;
    h.delta(0.0, &derivative);
    return p.dot(derivative.real() * q);
  }

  // The cusp test p^T D^2 F(y*)(q, q) at z (equilibrium_boundary.hpp); NaN without a Jacobian.
  double cusp_test(const Eigen::VectorXd& z) const {
    if (!family_.jacobian) return NAN;
    const Eigen::VectorXd state = z.head(d_);
    const ConstantHistory h = family_.at(state, x(z), y(z));
    const Eigen::MatrixXd M = bordered(h);
    const Eigen::VectorXd q = M.fullPivLu().solve(unit_last()).head(d_);
    const Eigen::VectorXd p = M.transpose().fullPivLu().solve(unit_last()).head(d_);
    const long copies = static_cast<long>(h.taus.size());
    const auto repeated = [&](const Eigen::VectorXd& v, long n) {
      Eigen::VectorXd r(d_ * n);
      for (long k = 0; k < n; ++k) r.segment(k * d_, d_) = v;
      return r;
    };
    const double e = 1e-4 * (1 + state.norm()) / q.norm();
    const auto J = [&](double s) {
      const Eigen::VectorXd at = state + s * q;
      return family_.jacobian(at, repeated(at, copies), x(z), y(z));
    };
    const Eigen::VectorXd second = (J(e) - J(-e)) * repeated(q, copies + 1) / (2 * e);
    return p.dot(second);
  }

  // dF/dz by central differences, relative step 1e-7
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& z) const {
    Eigen::MatrixXd D(d_ + 1, d_ + 2);
    for (long i = 0; i < d_ + 2; ++i) {
      const double delta = 1e-7 * (1 + std::abs(z[i]));
      Eigen::VectorXd a = z, b = z;
      a[i] += delta, b[i] -= delta;
      D.col(i) = (F(a) - F(b)) / (a[i] - b[i]);
    }
    return D;
  }

  // The unit tangent (kernel of dF/dz), oriented along `previous` (or towards u increasing)
  Eigen::VectorXd tangent(const Eigen::VectorXd& z, const Eigen::VectorXd* previous) const {
    const Eigen::MatrixXd D = jacobian(z);
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(D, Eigen::ComputeFullV);
    Eigen::VectorXd t = svd.matrixV().col(d_ + 1);
    if (previous ? t.dot(*previous) < 0 : t[d_] < 0) t = -t;
    return t;
  }

  // Newton on (F, row . z - target) from z; nullopt when it does not converge in 8 iterations
  std::optional<Eigen::VectorXd> correct(Eigen::VectorXd z, const Eigen::VectorXd& row, double target, int& iterations) const {
    for (iterations = 1; iterations <= 8; ++iterations) {
      Eigen::MatrixXd M(d_ + 2, d_ + 2);
      M.topRows(d_ + 1) = jacobian(z);
      M.row(d_ + 1) = row.transpose();
      Eigen::VectorXd r(d_ + 2);
      r << F(z), row.dot(z) - target;
      const Eigen::VectorXd dz = M.fullPivLu().solve(r);
      if (!dz.allFinite()) return std::nullopt;
      z -= dz;
      if (dz.lpNorm<Eigen::Infinity>() <= o_.tolerance * (1 + z.lpNorm<Eigen::Infinity>())) return z;
    }
    return std::nullopt;
  }

  long d() const { return d_; }

 private:
  // [J b; c^T 0], J = A + sum B_i at h, b and c the borders
  Eigen::MatrixXd bordered(const ConstantHistory& h) const {
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(d_ + 1, d_ + 1);
    M.topLeftCorner(d_, d_) = h.jacobian();
    M.topRightCorner(d_, 1) = left_;
    M.bottomLeftCorner(1, d_) = right_.transpose();
    return M;
  }
  // (0, ..., 0, 1): the bordered systems' right-hand side
  Eigen::VectorXd unit_last() const { return Eigen::VectorXd::Unit(d_ + 1, d_); }

  const EquilibriumFamily2& family_;
  const BoundaryOptions& o_;
  long d_;
  Eigen::VectorXd left_, right_;
};

// The codim-2 points of `kind` on a traced fold curve (equilibrium_boundary.hpp): each sign change
// of its test between consecutive points located by Illinois along the chord.
void fold_codim2_points(FoldSystem& sys, const BoundaryOptions& o, FoldCodim2Kind kind, FoldCurve& curve) {
  const long d = sys.d();
  const double sx = std::abs(o.x_to - o.x_from), sy = std::abs(o.y_to - o.y_from);
  const auto test_at = [&](const Eigen::VectorXd& z) {
    return kind == FoldCodim2Kind::bogdanov_takens ? sys.bogdanov_takens_test(z) : sys.cusp_test(z);
  };
  std::vector<double> test;
  for (const FoldCurvePoint& p : curve.points) test.push_back(test_at(sys.z_of(p.state, p.x, p.y)));
  for (size_t i = 0; i + 1 < curve.points.size(); ++i) {
    if (!(test[i] * test[i + 1] < 0)) continue;  // (a NaN too: nothing to locate)
    const FoldCurvePoint &a = curve.points[i], &b = curve.points[i + 1];
    const Eigen::VectorXd za = sys.z_of(a.state, a.x, a.y), zb = sys.z_of(b.state, b.x, b.y);
    const Eigen::VectorXd row = (zb - za).normalized();
    FoldCodim2Point out;
    out.kind = kind;
    Eigen::VectorXd at = za;
    double lo = 0, hi = 1;
    bool located = true;
    detail::IllinoisValues illinois{test[i], test[i + 1]};
    for (int k = 0; k < 60 && std::max((hi - lo) * std::abs(b.x - a.x) / sx, (hi - lo) * std::abs(b.y - a.y) / sy) >
                                  o.tolerance;
         ++k) {
      const double t = std::clamp(illinois.root(lo, hi), lo + 0.01 * (hi - lo), hi - 0.01 * (hi - lo));
      const Eigen::VectorXd trial = za + t * (zb - za);
      int iterations = 0;
      const std::optional<Eigen::VectorXd> on_curve = sys.correct(trial, row, row.dot(trial), iterations);
      const double v = on_curve ? test_at(*on_curve) : NAN;
      if (!std::isfinite(v)) {
        curve.notes.push_back(std::string(kind == FoldCodim2Kind::cusp ? "a cusp" : "a Bogdanov-Takens point") +
                              " between (" + format_number(a.x) + ", " + format_number(a.y) +
                              ") and (" + format_number(b.x) + ", " + format_number(b.y) +
                              "): not located (no point of the curve at t = " + format_number(t) + " along the chord)");
        located = false;
        break;
      }
      at = *on_curve;
      ++out.evaluations;
      if (v == 0) {
        lo = hi = t;
        break;
      }
      (illinois.replace(v) < 0 ? lo : hi) = t;
    }
    if (!located) continue;
    out.x = sys.x(at), out.y = sys.y(at), out.state = at.head(d);
    out.bound = (hi - lo) * std::max(std::abs(b.x - a.x), std::abs(b.y - a.y)) + o.tolerance * std::max(sx, sy);
    curve.codim2.push_back(std::move(out));
  }
}

// One way from z0 along +-t0: the points after z0, the end and its note.
FoldCurve trace_fold_one_way(FoldSystem& sys, const BoundaryOptions& o, const Eigen::VectorXd& z0,
                             Eigen::VectorXd t, bool& ok) {
  const long d = sys.d();
  FoldCurve out;
  Eigen::VectorXd z = z0;
  double ds = o.step;
  const auto point_of = [&](const Eigen::VectorXd& q) { return FoldCurvePoint{sys.x(q), sys.y(q), q.head(d)}; };
  ok = true;
  while (static_cast<int>(out.points.size()) < o.max_points) {
    int iterations = 0;
    const Eigen::VectorXd predicted = z + ds * t;
    const auto next = sys.correct(predicted, t, t.dot(predicted), iterations);
    if (!next || (*next - z).norm() > 2 * ds) {
      ds /= 2;
      if (ds < o.step_min) {
        out.end = BoundaryEnd::failure;
        out.note = "no step could be corrected onto the fold curve at (" + format_number(sys.x(z)) + ", " +
                   format_number(sys.y(z)) + "), down to boundary_step_min = " + format_number(o.step_min);
        ok = false;
        return out;
      }
      continue;
    }
    // out of the box [0, 1]^2 in (u, v): the crossed coordinate fixed at its edge, the point
    // corrected there, the curve's end
    const double u = (*next)[d], v = (*next)[d + 1];
    if (u > 1 || u < 0 || v > 1 || v < 0) {
      const bool in_u = u > 1 || u < 0;
      const long k = in_u ? d : d + 1;
      const double edge = (in_u ? u : v) > 1 ? 1 : 0;
      const double w = (edge - z[k]) / ((*next)[k] - z[k]);
      Eigen::VectorXd row = Eigen::VectorXd::Zero(d + 2);
      row[k] = 1;
      int it = 0;
      if (const auto landed = sys.correct(z + w * (*next - z), row, edge, it)) out.points.push_back(point_of(*landed));
      out.end = !in_u ? BoundaryEnd::y_range : edge == 1 ? BoundaryEnd::to : BoundaryEnd::from;
      if (out.end == BoundaryEnd::y_range)
        out.note = "left the y range at x = " + format_number(out.points.empty() ? sys.x(z) : out.points.back().x);
      return out;
    }
    const Eigen::VectorXd t_new = sys.tangent(*next, &t);
    z = *next;
    t = t_new;
    out.points.push_back(point_of(z));
    if (iterations <= 3) ds = std::min(1.5 * ds, o.step_max);
  }
  out.end = BoundaryEnd::max_points;
  return out;
}

}  // namespace

FoldCurves fold_curves(const EquilibriumFamily2& family, const Eigen::VectorXd& guess, const HopfCurveOptions& o) {
  const BoundaryOptions& b = o.boundary;
  FoldCurves out;
  std::vector<BoundaryCurve> traced;  // for on_boundary_curve
  search_lines(family, guess, o, out.notes, [&](double x, const EquilibriumBranch& branch) {
    for (const EquilibriumBifurcation& f : branch.bifurcations) {
      if (f.type != EquilibriumBifurcationType::fold) continue;
      if (on_boundary_curve(traced, x, f.parameter, 1e-3 * std::abs(b.y_to - b.y_from))) continue;
      const long d = f.state.size();
      FoldSystem sys(family, b, d);
      Eigen::VectorXd z = sys.z_of(f.state, x, f.parameter);
      sys.set_borders(z);
      int iterations = 0;
      Eigen::VectorXd t = sys.tangent(z, nullptr);
      const auto start = sys.correct(z, t, t.dot(z), iterations);
      if (!start) {
        out.notes.push_back("the fold at (" + format_number(x) + ", " + format_number(f.parameter) +
                            "): not corrected onto the extended system");
        continue;
      }
      z = *start;
      t = sys.tangent(z, &t);
      bool ok_forward = true, ok_back = true;
      FoldCurve forward = trace_fold_one_way(sys, b, z, t, ok_forward);
      FoldCurve back = trace_fold_one_way(sys, b, z, -t, ok_back);
      FoldCurve curve;
      for (auto it = back.points.rbegin(); it != back.points.rend(); ++it) curve.points.push_back(*it);
      curve.points.push_back({sys.x(z), sys.y(z), z.head(d)});
      curve.points.insert(curve.points.end(), forward.points.begin(), forward.points.end());
      // the worse half's end (a failure first)
      const FoldCurve& worse = !ok_back ? back : forward;
      curve.end = worse.end;
      curve.note = worse.note;
      for (FoldCodim2Kind kind : {FoldCodim2Kind::bogdanov_takens, FoldCodim2Kind::cusp})
        fold_codim2_points(sys, b, kind, curve);
      BoundaryCurve as_boundary;
      for (const FoldCurvePoint& p : curve.points) as_boundary.points.push_back({p.x, p.y, NAN, 0});
      traced.push_back(std::move(as_boundary));
      out.curves.push_back(std::move(curve));
    }
  });
  return out;
}

}  // namespace delayspec
