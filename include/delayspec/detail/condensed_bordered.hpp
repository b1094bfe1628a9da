#pragma once
// The bordered Newton matrix of the discrete periodic problem (orbit_newton.hpp, continuation.hpp)
//
//   [ F_x    F_p   ] [dx]   [r_x]
//   [ row_x  row_p ] [dp] = [r_p]
//
// solved matrix-free: condensed onto the history of the map and solved by GMRES (gmres.hpp) on
// the linearised map, as nested shooting solves (M - I) s = -G (orbit_shooting.hpp). No matrix
// is assembled or factored, so nothing fills in: UMFPACK's factors of F_x grow with a fractional
// delay (the delayed blocks couple columns m and m + 1 steps back), which made the sparse-LU
// corrector the whole cost of a branch at large N.
//
// Condensation. Row l of F_x dx = f is the linearised step (P_l, Q_l, R_l: the step map of step l
// at the iterate x, StepMap)
//
//   dx_{l+1} = P_l dx_l + Q_l dw0_l + R_l dw1_l + f_l,      l = 0 .. K - 1,
//
// with the delayed values dw interpolated from dx_{l-m-1 .. l-m+1} (HistoryGrid::delay_tap),
// all indices mod K. Given the history dU = (dx_{-M}, ..., dx_0) the rows are a forward
// recurrence (a "sweep", the monodromy's kernel plus f_l after each step); it gives the
// sequence dx_0 .. dx_{K-1} and the end history E(dU, f) = (dx_{K-M}, ..., dx_K). The sequence is
// periodic, i.e. solves the rows, exactly when E(dU, f) = dU. By linearity E(dU, f) = M dU + e(f)
// with M the monodromy at x and e(f) = E(0, f), and the sequence is S dU + s(f). With f = r_x -
// dp F_p the bordered system becomes, in n + 1 = d (M + 1) + 1 unknowns,
//
//   [ M - I      -e(F_p)                 ] [dU]   [ -e(r_x)            ]
//   [ row_x S    row_p - row_x . s(F_p)  ] [dp] = [ r_p - row_x . s(r_x) ]
//
// and dx is the sweep from dU with f = r_x - dp F_p. One GMRES product is one homogeneous sweep
// (O(K d^2), a few per cent of a map evaluation); each solve adds two forced sweeps. The
// condensed matrix is regular exactly when the bordered one is (a Schur complement of it), so
// the corrector passes folds as the sparse-LU one does: at a fold M - I is singular but the
// border is not.
//
// Why GMRES converges fast: M is compact-like (its spectrum accumulates at 0), so the matrix is
// -I plus a few large directions plus the border, a rank-two change: GMRES needs about as many
// products as the multipliers above the tolerance, as in shooting. A strongly unstable orbit
// (|mu| >> 1) makes the condensed system ill-conditioned (the sweep amplifies by |mu|); GMRES then
// fails to converge and says so (continue_solver = auto falls back to the sparse LU).
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/detail/block_kernel.hpp"
#include "delayspec/detail/branch_corrector.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/gmres.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/step_map.hpp"

namespace delayspec::continuation_detail {

struct GmresLimits {
  int restart = 40;           // basis vectors per cycle
  int max_iterations = 400;   // products per solve
};

template <int D, int DW = D>
class CondensedBordered final : public BorderedLinearisation {
 public:
  // The iterate's residual, step maps (one per step, PeriodicOrbitProblem::residual), F_p and
  // the border. p: named in a failure.
  CondensedBordered(Eigen::VectorXd residual, const HistoryGrid& grid, std::vector<StepMap<D, DW>> maps,
                    const Eigen::VectorXd& F_p, const Eigen::VectorXd& row_x, double row_p, double p,
                    const GmresLimits& limits)
      : grid_(grid), maps_(std::move(maps)), row_x_(row_x), row_p_(row_p), p_(p), limits_(limits),
        n_(grid.dimension(D)), work_(static_cast<size_t>((grid.M + 1 + grid.K) * D)), F_p_(F_p) {
    G = std::move(residual);
    if (static_cast<long>(maps_.size()) != grid_.K || G.size() != static_cast<long>(D) * grid_.K)
      throw BadInput("condensed bordered system: sizes do not match the grid");
    sweep(Eigen::VectorXd::Zero(n_), &F_p_);
    e_p_ = end_history();
    s_p_ = row_x_.dot(sequence());
  }

  std::optional<Eigen::VectorXd> solve(const Eigen::VectorXd& rhs_x, double rhs_p, double forcing,
                                       std::string& why) override {
    const long n = n_, K = grid_.K;
    // A border that fixes p (row_x = 0: Newton at a given parameter, the start and the end of a
    // branch) gives dp = r_p / row_p exactly, as the LU does, and leaves (M - I) dU = -e(r_x - dp
    // F_p): the branch lands exactly on its end.
    const bool fixes_p = row_x_.isZero(0.0);
    if (fixes_p && row_p_ == 0) {
      why = "the bordered system's border is zero";
      return std::nullopt;
    }
    const double dp_fixed = fixes_p ? rhs_p / row_p_ : 0.0;
    const long m = fixes_p ? n : n + 1;
    Eigen::VectorXd f = rhs_x - dp_fixed * F_p_;
    sweep(Eigen::VectorXd::Zero(n), &f);
    Eigen::VectorXd b(m);
    b.head(n) = -end_history();
    if (!fixes_p) b[n] = rhs_p - row_x_.dot(sequence());
    const double corner = row_p_ - s_p_;
    // `forcing` is relative to the right-hand side as given; the condensed one, b, is it carried
    // through the sweep, and may be larger or smaller (the forced sweep grows or decays with the
    // orbit's transients): GMRES is asked for the same absolute residual. (The sequence's
    // residual after the solve is the condensed one passed through one step: the periodicity
    // mismatch of the history enters the first rows as the delayed values do.)
    const double rhs_norm = std::hypot(rhs_x.norm(), rhs_p), b_norm = b.norm();
    const double tolerance = b_norm > 0 ? std::min(0.5, forcing * rhs_norm / b_norm) : forcing;
    const GmresResult g = gmres(
        [&](const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::VectorXd& out) {
          sweep(y.head(n), nullptr);
          out.resize(m);
          out.head(n) = end_history() - y.head(n);
          if (fixes_p) return;
          out.head(n) -= y[n] * e_p_;
          out[n] = row_x_.dot(sequence()) + y[n] * corner;
        },
        b, GmresOptions{tolerance, limits_.restart, limits_.max_iterations}, &basis_);
    products += g.iterations;
    if (!g.converged) {
      why = "GMRES on the condensed bordered system did not converge at parameter " + format_number(p_) +
            " (relative residual " + format_number(g.relative_residual) + " after " + std::to_string(g.iterations) +
            " products, asked " + format_number(tolerance) + ")";
      return std::nullopt;
    }
    const double dp = fixes_p ? dp_fixed : g.x[n];
    f = rhs_x - dp * F_p_;
    sweep(g.x.head(n), &f);
    Eigen::VectorXd z(static_cast<long>(D) * K + 1);
    z.head(static_cast<long>(D) * K) = sequence();
    z[static_cast<long>(D) * K] = dp;
    if (!z.allFinite()) {
      why = "the condensed bordered solve is not finite at parameter " + format_number(p_);
      return std::nullopt;
    }
    return z;
  }

 private:
  // The forward sweep from the history dU (oldest block first) with forcing f (null: none): after
  // it, slot M + l of the work buffer holds dx_l, l = 0 .. K.
  void sweep(const Eigen::Ref<const Eigen::VectorXd>& dU, const Eigen::VectorXd* f) {
    const long K = grid_.K, M = grid_.M;
    double* b = work_.data();
    std::copy(dU.data(), dU.data() + n_, b);
    if (!f) {  // the monodromy's kernel (Monodromy::perform_op)
      steps(0, K, b);
      return;
    }
    for (long l = 0; l < K; ++l) {
      steps(l, 1, b);
      for (int r = 0; r < D; ++r) b[(M + l + 1) * D + r] += (*f)[l * D + r];
    }
  }
  // Steps l0 .. l0 + count - 1 of the linearised map on the work buffer b (block_kernel.hpp).
  void steps(long l0, long count, double* b) const {
    const long M = grid_.M;
    if constexpr (DW != D) multi_delay_steps<D, DW>(maps_.data() + l0, count, M + l0, grid_.delays, b, 1);
    else single_steps<D>(maps_.data() + l0, count, M + l0, grid_.delayed_slot(l0), grid_.theta, b);
  }
  Eigen::Map<const Eigen::VectorXd> sequence() const {  // dx_0 .. dx_{K-1}
    return {work_.data() + grid_.M * D, static_cast<long>(D) * grid_.K};
  }
  Eigen::Map<const Eigen::VectorXd> end_history() const {  // dx_{K-M} .. dx_K
    return {work_.data() + grid_.K * D, n_};
  }

  HistoryGrid grid_;
  std::vector<StepMap<D, DW>> maps_;
  const Eigen::VectorXd& row_x_;
  double row_p_, p_;
  GmresLimits limits_;
  long n_;
  std::vector<double> work_;  // the sweep's slots, (M + 1 + K) d
  Eigen::VectorXd F_p_;
  Eigen::VectorXd e_p_;  // e(F_p)
  double s_p_ = 0;       // row_x . s(F_p)
  Eigen::MatrixXd basis_;  // GMRES' workspace, kept between the solves of one iterate
};

}  // namespace delayspec::continuation_detail
