// Stages 1 and 3 of equilibrium.hpp: Newton for the equilibrium, and Newton on the exact
// characteristic function c(lambda) = det Delta(lambda) for each root.
#include "delayspec/equilibrium.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "delayspec/errors.hpp"
#include "engine/linalg/linear_algebra.hpp"

namespace delayspec {

Eigen::MatrixXd ConstantHistory::jacobian() const {
  const long d = A.rows();
  Eigen::MatrixXd j = A;
  for (size_t i = 0; i < taus.size(); ++i) j += B.middleCols(static_cast<long>(i) * d, d);
  return j;
}

Eigen::MatrixXcd ConstantHistory::delta(std::complex<double> l, Eigen::MatrixXcd* derivative) const {
  const long d = A.rows();
  Eigen::MatrixXcd value = l * Eigen::MatrixXcd::Identity(d, d) - A.cast<std::complex<double>>();
  if (derivative) *derivative = Eigen::MatrixXcd::Identity(d, d);
  for (size_t i = 0; i < taus.size(); ++i) {
    const std::complex<double> e = std::exp(-l * taus[i]);
    const Eigen::MatrixXcd bi = B.middleCols(static_cast<long>(i) * d, d).cast<std::complex<double>>();
    value -= e * bi;
    if (derivative) *derivative += taus[i] * e * bi;
  }
  return value;
}

std::complex<double> ConstantHistory::newton_step(std::complex<double> l) const {
  Eigen::MatrixXcd derivative;
  const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(delta(l, &derivative));
  // Delta exactly singular (a zero pivot): lambda is a root to the last bit, and the step is 0.
  // The solve would divide by that pivot and give inf - inf = NaN in the trace (issue 61: the
  // Lang-Kobayashi carrier root -1/Tc, a decoupled linear decay, is hit exactly). A pivot that is
  // merely tiny gives a huge trace and a tiny step, as it should.
  if (lu.matrixLU().diagonal().cwiseAbs().minCoeff() == 0 && std::isfinite(std::abs(l))) return 0;
  return 1.0 / lu.solve(derivative).trace();
}

namespace {

// The singular values of a (descending) and, when last_right is given, a right singular vector of
// the smallest: LAPACK's zgesvd through the loaded table (linear_algebra.hpp). Not Eigen's
// JacobiSVD: its real and complex instantiations took 24 s of this unit's 32 s of compile, on the
// program's path to its first number (docs/benchmarks.md, "Build time"); these matrices are d x d.
Eigen::VectorXd singular_values(Eigen::MatrixXcd a, Eigen::VectorXcd* last_right = nullptr) {
  const int m = static_cast<int>(a.rows()), n = static_cast<int>(a.cols()), ldvt = last_right ? n : 1;
  Eigen::VectorXd s(std::min(m, n));
  Eigen::MatrixXcd vt(ldvt, last_right ? n : 1);
  std::vector<double> rwork(5 * static_cast<size_t>(std::min(m, n)));
  std::complex<double> query, u;
  const int one = 1;
  int lwork = -1, info = 0;
  const char* jobvt = last_right ? "A" : "N";
  const auto zgesvd = detail::lapack().zgesvd;
  zgesvd("N", jobvt, &m, &n, a.data(), &m, s.data(), &u, &one, vt.data(), &ldvt, &query, &lwork, rwork.data(), &info);
  lwork = std::max(1, static_cast<int>(query.real()));
  std::vector<std::complex<double>> work(static_cast<size_t>(lwork));
  zgesvd("N", jobvt, &m, &n, a.data(), &m, s.data(), &u, &one, vt.data(), &ldvt, work.data(), &lwork, rwork.data(),
         &info);
  if (info != 0)
    throw NumericalFailure("equilibrium: the SVD of a " + std::to_string(m) + " x " + std::to_string(n) +
                           " matrix (LAPACK zgesvd) failed, info = " + std::to_string(info));
  if (last_right) *last_right = vt.row(n - 1).adjoint();  // A = U S V^H: V's last column
  return s;
}

double largest_singular_value(const Eigen::MatrixXd& m) {
  return m.size() == 1 ? std::abs(m(0, 0)) : singular_values(m.cast<std::complex<double>>())(0);
}

}  // namespace

Eigen::VectorXcd ConstantHistory::null_vector(std::complex<double> l) const {
  Eigen::VectorXcd v;
  singular_values(delta(l), &v);
  // A convention of our own rather than the SVD's: the entry of largest modulus real and positive
  Eigen::Index largest = 0;
  v.cwiseAbs().maxCoeff(&largest);
  return v * (std::abs(v[largest]) / v[largest]);
}

double ConstantHistory::residual(std::complex<double> l) const {
  const long d = A.rows();
  double scale = std::abs(l) + largest_singular_value(A);
  for (size_t i = 0; i < taus.size(); ++i)
    scale += largest_singular_value(B.middleCols(static_cast<long>(i) * d, d));
  const Eigen::MatrixXcd value = delta(l);
  const double smallest = d == 1 ? std::abs(value(0, 0)) : singular_values(value)(d - 1);
  return smallest / scale;
}

void equilibrium_state(const std::function<ConstantHistory(const Eigen::VectorXd&)>& at, Eigen::VectorXd y,
                       const EquilibriumOptions& o, EquilibriumResult& r) {
  for (;; ++r.newton_iterations) {
    const ConstantHistory h = at(y);
    r.residual = h.f.lpNorm<Eigen::Infinity>();
    const Eigen::MatrixXd jacobian = h.jacobian();
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(jacobian);
    // A singular Jacobian at an iterate that already solves f to the tolerance (a Newton step
    // would move it by less, in every direction the Jacobian sees): an equilibrium where the
    // branch of equilibria bifurcates (a pitchfork or transcritical point, e.g. a zero-Hopf point
    // of a Hopf curve). Accepted as it is; not isolated, so nothing else to solve for.
    if (!lu.isInvertible() &&
        r.residual <= o.tolerance * jacobian.lpNorm<Eigen::Infinity>() * (1 + y.lpNorm<Eigen::Infinity>()))
      break;
    if (!lu.isInvertible())
      throw NumericalFailure("equilibrium: the Jacobian A + sum B of f(y, ..., y) is singular at the iterate " +
                             std::to_string(r.newton_iterations) + " (|f|_inf = " + format_number(r.residual) +
                             "): no isolated equilibrium there");
    const Eigen::VectorXd step = lu.solve(h.f);
    if (!y.allFinite() || !step.allFinite() || r.newton_iterations >= o.max_iterations)
      throw NumericalFailure("equilibrium: Newton did not converge from the guess (|f(y, ..., y)|_inf = " +
                             format_number(r.residual) + " after " + std::to_string(r.newton_iterations) +
                             " iterations)");
    y -= step;
    if (step.lpNorm<Eigen::Infinity>() <= o.tolerance * (1 + y.lpNorm<Eigen::Infinity>())) {
      r.residual = at(y).f.lpNorm<Eigen::Infinity>();
      ++r.newton_iterations;
      break;
    }
  }
  r.state = y;
}

namespace {

// Newton on c from l (refined_root's iteration).
CharacteristicRoot newton_on_c(const ConstantHistory& h, std::complex<double> l, const EquilibriumOptions& o) {
  CharacteristicRoot root;
  root.discretised = l;
  for (root.iterations = 1;; ++root.iterations) {
    const std::complex<double> step = h.newton_step(l);
    l -= step;
    root.last_step = std::abs(step);
    if (!std::isfinite(l.real()) || !std::isfinite(l.imag()) || root.iterations >= o.max_iterations)
      throw NumericalFailure("equilibrium: the characteristic root near " + format_complex(root.discretised) +
                             " did not converge on det(lambda I - A - sum B e^(-lambda tau)) (last step " +
                             format_number(root.last_step) + ")");
    if (root.last_step <= o.tolerance * (1 + std::abs(l))) break;
  }
  root.value = l;
  root.residual = h.residual(l);
  root.error_bound = std::max(root.last_step, 4 * std::numeric_limits<double>::epsilon() * (1 + std::abs(l)));
  return root;
}

}  // namespace

CharacteristicRoot refined_root(const ConstantHistory& h, std::complex<double> l, const EquilibriumOptions& o) {
  try {
    return newton_on_c(h, l, o);
  } catch (const NumericalFailure&) {
    // c has real coefficients, so Newton from a real start never leaves the real axis. Near a
    // double real root the discretisation may give two real roots where the exact ones are a
    // complex pair of small imaginary part (x' = 1.5 x - 1.648722 x(t - 1): 0.5000003 +- 9.4e-4 i,
    // the N = 100 roots real); Newton then wanders on the axis. Once more from just above it (the
    // conjugate comes with the root, refine_multipliers); the first failure stands otherwise.
    if (l.imag() != 0) throw;
    try {
      CharacteristicRoot root = newton_on_c(h, {l.real(), 1e-3 * (1 + std::abs(l))}, o);
      root.discretised = l;
      return root;
    } catch (const NumericalFailure&) {
    }
    throw;
  }
}

namespace {

// Two refined roots are one root refined twice when their distance is within the sum of their
// bounds (each within its error_bound of the root; issue 61: a distance of 1e3 tolerance (1 +
// |lambda|) merged a complex pair with its conjugate at equilibrium_tolerance = 1e-3, and whole sets
// of distinct roots at 2e-4 .. 5e-4).
bool same_root(const CharacteristicRoot& a, const CharacteristicRoot& b) {
  return std::abs(a.value - b.value) <= a.error_bound + b.error_bound;
}

}  // namespace

void refine_multipliers(const ConstantHistory& h, const Multipliers& mu, double T, const EquilibriumOptions& o,
                        EquilibriumResult& r) {
  const double two_pi = 2 * std::numbers::pi;
  const int branches = o.N / 2 + 1;  // frequencies the grid resolves: |Im lambda| T / 2 pi < N / 2
  for (const std::complex<double>& m : mu) {
    if (std::abs(m) == 0) continue;
    std::complex<double> start;
    double shortest = INFINITY;
    for (int k = -branches; k <= branches; ++k) {
      const std::complex<double> l(std::log(std::abs(m)) / T, (std::arg(m) + two_pi * k) / T);
      const double step = std::abs(h.newton_step(l));
      if (step < shortest) shortest = step, start = l;
    }
    const CharacteristicRoot root = refined_root(h, start, o);
    if (std::none_of(r.roots.begin(), r.roots.end(), [&](const CharacteristicRoot& other) { return same_root(other, root); }))
      r.roots.push_back(root);
  }
  // Conjugates together: c has real coefficients, so conj(lambda) is a root with lambda, as
  // accurate; one missing (its multiplier merged or not returned) is added.
  const size_t found = r.roots.size();
  for (size_t i = 0; i < found; ++i) {
    CharacteristicRoot conjugate = r.roots[i];
    if (!(std::abs(conjugate.value.imag()) > conjugate.error_bound)) continue;  // real to its bound
    conjugate.value = std::conj(conjugate.value);
    conjugate.discretised = std::conj(conjugate.discretised);
    if (std::none_of(r.roots.begin(), r.roots.end(), [&](const CharacteristicRoot& other) { return same_root(other, conjugate); }))
      r.roots.push_back(conjugate);
  }
  std::sort(r.roots.begin(), r.roots.end(), [](const CharacteristicRoot& p, const CharacteristicRoot& q) {
    return p.value.real() != q.value.real() ? p.value.real() > q.value.real() : p.value.imag() > q.value.imag();
  });
  // The nroots rightmost, a pair not cut in two (the partner of the last kept comes with it)
  size_t keep = std::min(r.roots.size(), static_cast<size_t>(o.nroots));
  if (keep < r.roots.size() && keep > 0 && r.roots[keep - 1].value.imag() > r.roots[keep - 1].error_bound) {
    CharacteristicRoot partner = r.roots[keep - 1];
    partner.value = std::conj(partner.value);
    if (same_root(r.roots[keep], partner)) ++keep;
  }
  r.roots.resize(keep);
  r.note.clear();
  if (static_cast<int>(r.roots.size()) < o.nroots)
    r.note = std::to_string(r.roots.size()) + " of the " + std::to_string(o.nroots) +
             " roots asked for: the monodromy at N = " + std::to_string(o.N) + " gave " + std::to_string(mu.size()) +
             " multipliers (at most its dimension less 2), each refined to a root, the same root counted once; "
             "a grid of N steps per tau_max resolves |Im lambda| < pi N / tau_max: raise N for more";
  else if (static_cast<int>(r.roots.size()) > o.nroots)
    r.note = "the last root's conjugate is returned with it (" + std::to_string(r.roots.size()) + " roots for nroots = " +
             std::to_string(o.nroots) + "): a pair is not cut in two";
  r.unstable = r.critical = 0;
  for (const CharacteristicRoot& c : r.roots) {
    if (c.value.real() > c.error_bound) ++r.unstable;
    else if (c.value.real() >= -c.error_bound) ++r.critical;
  }
}

}  // namespace delayspec
