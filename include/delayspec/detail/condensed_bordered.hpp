#pragma once
// The bordered Newton matrix of the discrete periodic problem (orbit_newton.hpp, continuation.hpp)
//
//   [ F_x  C ] [dx]   [r_x]        C: D K x k columns (F_p; for an orbit of unknown period F_T, F_p)
//   [ R    E ] [dy] = [r_y]        R: k x D K rows (the arclength row; the phase row), E: k x k
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
// C dy the bordered system becomes, in d (M + 1) + k unknowns,
//
//   [ M - I     -e(C)          ] [dU]   [ -e(r_x)         ]
//   [ R S       E - R s(C)     ] [dy] = [ r_y - R s(r_x)  ]
//
// (e(C), s(C): column by column) and dx is the sweep from dU with f = r_x - C dy. One GMRES
// product is one homogeneous sweep (O(K d^2), a few per cent of a map evaluation); each solve
// adds two forced sweeps. The condensed matrix is regular exactly when the bordered one is (a
// Schur complement of it), so the corrector passes folds as the sparse-LU one does: at a fold
// M - I is singular but the border is not.
//
// A last border row that fixes its unknown (R's last row zero, E's last row zero but its
// diagonal: Newton at a given parameter, the start and the end of a branch) is solved exactly,
// dy_last = r_y,last / E_last,last, as the LU does, and GMRES takes the rest: the branch lands
// exactly on its end.
//
// Why GMRES converges fast: M is compact-like (its spectrum accumulates at 0), so the matrix is
// -I plus a few large directions plus the borders, a change of rank 2 k: GMRES needs about as many
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
  int restart = 40;          // basis vectors per cycle
  int max_iterations = 400;  // products per solve
};

// The borders of the condensed system (header): C, R, E.
struct Borders {
  Eigen::MatrixXd columns;  // C, D K x k
  Eigen::MatrixXd rows;     // R, k x D K
  Eigen::MatrixXd corner;   // E, k x k
};

template <int D, int DW = D>
class CondensedBordered final : public BorderedLinearisation {
 public:
  // The iterate's residual (D K + k - 1 entries: the tracer's G, the last border row's residual
  // being the corrector's own g), its step maps (one per step, PeriodicOrbitProblem::residual),
  // the borders. p: named in a failure.
  CondensedBordered(Eigen::VectorXd residual, const HistoryGrid& grid, std::vector<StepMap<D, DW>> maps,
                    Borders borders, double p, const GmresLimits& limits)
      : grid_(grid), maps_(std::move(maps)), b_(std::move(borders)), p_(p), limits_(limits), n_(grid.dimension(D)),
        nx_(static_cast<long>(D) * grid.K), k_(b_.columns.cols()),
        work_(static_cast<size_t>((grid.M + 1 + grid.K) * D)) {
    G = std::move(residual);
    if (static_cast<long>(maps_.size()) != grid_.K || G.size() != nx_ + k_ - 1 || b_.columns.rows() != nx_ ||
        b_.rows.rows() != k_ || b_.rows.cols() != nx_ || b_.corner.rows() != k_ || b_.corner.cols() != k_ || k_ < 1)
      throw BadInput("condensed bordered system: sizes do not match the grid");
    // The last unknown is fixed by its row (header) when that row has nothing but its diagonal.
    fixes_last_ = b_.rows.row(k_ - 1).isZero(0.0) && b_.corner.row(k_ - 1).head(k_ - 1).isZero(0.0) &&
                  b_.corner(k_ - 1, k_ - 1) != 0;
    e_C_.resize(n_, k_);
    s_C_.resize(k_, k_);
    for (long j = 0; j < k_; ++j) {
      const Eigen::VectorXd column = b_.columns.col(j);
      sweep(Eigen::VectorXd::Zero(n_), &column);
      e_C_.col(j) = end_history();
      s_C_.col(j) = b_.rows * sequence();
    }
  }

  std::optional<Eigen::VectorXd> solve(const Eigen::VectorXd& rhs_x, double rhs_p, double forcing,
                                       std::string& why) override {
    const long n = n_, k = k_;
    Eigen::VectorXd rhs(nx_ + k);
    rhs << rhs_x, rhs_p;
    Eigen::VectorXd r_y = rhs.tail(k);
    Eigen::VectorXd f = rhs.head(nx_);
    // kf: the border unknowns GMRES solves for; a fixed last one is eliminated first.
    const long kf = fixes_last_ ? k - 1 : k;
    double fixed = 0;
    if (fixes_last_) {
      fixed = r_y[k - 1] / b_.corner(k - 1, k - 1);
      f -= fixed * b_.columns.col(k - 1);
      r_y.head(kf) -= fixed * b_.corner.col(k - 1).head(kf);
    }
    sweep(Eigen::VectorXd::Zero(n), &f);
    Eigen::VectorXd b(n + kf);
    b.head(n) = -end_history();
    b.tail(kf) = r_y.head(kf) - b_.rows.topRows(kf) * sequence();
    const Eigen::MatrixXd corner = b_.corner.topLeftCorner(kf, kf) - s_C_.topLeftCorner(kf, kf);
    // `forcing` is relative to the right-hand side as given; the condensed one, b, is it carried
    // through the sweep, and may be larger or smaller (the forced sweep grows or decays with the
    // orbit's transients): GMRES is asked for the same absolute residual. (The sequence's
    // residual after the solve is the condensed one passed through one step: the periodicity
    // mismatch of the history enters the first rows as the delayed values do.)
    const double rhs_norm = rhs.norm(), b_norm = b.norm();
    const double tolerance = b_norm > 0 ? std::min(0.5, forcing * rhs_norm / b_norm) : forcing;
    const GmresResult g = gmres(
        [&](const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::VectorXd& out) {
          sweep(y.head(n), nullptr);
          out.resize(n + kf);
          out.head(n) = end_history() - y.head(n) - e_C_.leftCols(kf) * y.tail(kf);
          out.tail(kf) = b_.rows.topRows(kf) * sequence() + corner * y.tail(kf);
        },
        b, GmresOptions{tolerance, limits_.restart, limits_.max_iterations}, &basis_);
    products += g.iterations;
    if (!g.converged) {
      why = "GMRES on the condensed bordered system did not converge at parameter " + format_number(p_) +
            " (relative residual " + format_number(g.relative_residual) + " after " + std::to_string(g.iterations) +
            " products, asked " + format_number(tolerance) + ")";
      return std::nullopt;
    }
    Eigen::VectorXd dy(k);
    dy.head(kf) = g.x.tail(kf);
    if (fixes_last_) dy[k - 1] = fixed;
    f = rhs.head(nx_) - b_.columns * dy;
    sweep(g.x.head(n), &f);
    Eigen::VectorXd z(nx_ + k);
    z << sequence(), dy;
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
    return {work_.data() + grid_.M * D, nx_};
  }
  Eigen::Map<const Eigen::VectorXd> end_history() const {  // dx_{K-M} .. dx_K
    return {work_.data() + grid_.K * D, n_};
  }

  HistoryGrid grid_;
  std::vector<StepMap<D, DW>> maps_;
  Borders b_;
  double p_;
  GmresLimits limits_;
  long n_, nx_, k_;
  bool fixes_last_ = false;
  std::vector<double> work_;  // the sweep's slots, (M + 1 + K) d
  Eigen::MatrixXd e_C_;       // e(C), n x k
  Eigen::MatrixXd s_C_;       // R s(C), k x k
  Eigen::MatrixXd basis_;     // GMRES' workspace, kept between the solves of one iterate
};

}  // namespace delayspec::continuation_detail
