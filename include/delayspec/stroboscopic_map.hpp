#pragma once
// StroboscopicMap: the nonlinear map U -> P(U) over one stroboscopic period (K steps of the
// stepper), optionally recording the step maps along the way, which gives the Monodromy at U.
//
// Same linear-buffer layout as Monodromy: b[0..M] = U, step l writes b[M + l + 1], the result
// is b[K .. K + M]. Step l starts at time t = l h, or at its node on a grid with breakpoints
// (grid.hpp; the grid phase is fixed: the section is t = 0 mod T).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/cancellation.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/model.hpp"
#include "delayspec/monodromy.hpp"
#include "delayspec/stepper.hpp"

namespace delayspec {

template <class Model, class Stepper = TrapezoidStepper<Model>>
class StroboscopicMap {
 public:
  static constexpr int D = Model::d;
  static constexpr int DW = delayed_rows<Model>;  // D, or D n with n delays (model.hpp)
  using V = Vec<D>;
  using W = DelayedVec<Model>;

  StroboscopicMap(const Stepper& stepper, const HistoryGrid& grid) : stepper_(stepper), grid_(grid) {}

  long dimension() const { return grid_.dimension(D); }
  const HistoryGrid& grid() const { return grid_; }
  const Stepper& stepper() const { return stepper_; }

  // The constant history y(t) = y0 for t <= 0.
  Eigen::VectorXd constant_history(const V& y0) const {
    Eigen::VectorXd U(dimension());
    for (int j = 0; j <= grid_.M; ++j) U.segment<D>(static_cast<long>(j) * D) = y0;
    return U;
  }

  // P(U). When maps is non-null it receives the K step maps (the monodromy at U).
  // When trajectory is non-null it receives the K + 1 states u_0 at t = 0, h, ..., K h.
  Eigen::VectorXd apply(const Eigen::VectorXd& U, std::vector<StepMap<D, DW>>* maps = nullptr,
                        std::vector<V>* trajectory = nullptr) const {
    if (U.size() != dimension())
      throw BadInput("StroboscopicMap: history has " + std::to_string(U.size()) + " entries, expected " +
                     std::to_string(dimension()));
    throw_if_cancelled();  // one period: the front end may stop here (cancellation.hpp)
    const long M = grid_.M, K = grid_.K;
    std::vector<V> b(static_cast<size_t>(M + 1 + K));
    for (long j = 0; j <= M; ++j) b[j] = U.segment<D>(j * D);
    if (maps) maps->resize(K);
    if (trajectory) {
      trajectory->clear();
      trajectory->reserve(K + 1);
      trajectory->push_back(b[M]);
    }
    StepMap<D, DW> scratch;
    auto slot = [&b](long i) -> const V& { return b[i]; };
    for (long l = 0; l < K; ++l) {
      const DelayTap<W> tap = grid_.template delay_taps<D, W>(l, slot);
      b[M + l + 1] = step(l, tap, b[M + l], maps ? (*maps)[l] : scratch);
      if (trajectory) trajectory->push_back(b[M + l + 1]);
    }
    Eigen::VectorXd out(dimension());
    for (long j = 0; j <= M; ++j) out.segment<D>(j * D) = b[K + j];
    return out;
  }

  // For failures only (it repeats the steps): from U, over `maps` maps, the first step whose new
  // state or step map (P, Q, R) is not finite, thrown as NonFiniteStep (the message starts with
  // `what`) with the points where that step evaluated the model. Returns when every step is finite.
  // apply() does not look (the look costs ~15 % of a step: 83f6ef8); callers look where a result
  // is not finite, once.
  void throw_first_non_finite_step(Eigen::VectorXd U, long maps, const std::string& what) const {
    const long M = grid_.M, K = grid_.K;
    std::vector<V> b(static_cast<size_t>(M + 1 + K));
    auto slot = [&b](long i) -> const V& { return b[i]; };
    for (long m = 0; m < maps; ++m) {
      throw_if_cancelled();
      for (long j = 0; j <= M; ++j) b[j] = U.segment<D>(j * D);
      const std::string which = "map " + std::to_string(m + 1) + ", step ";
      for (long l = 0; l < K; ++l) {
        const DelayTap<W> tap = grid_.template delay_taps<D, W>(l, slot);
        StepMap<D, DW> step_map;
        const double h = tap.h;
        try {
          b[M + l + 1] = step(l, tap, b[M + l], step_map);
        } catch (const NonFiniteStep& e) {
          throw NonFiniteStep(what + " (" + which + std::to_string(l + 1) + "): " + e.what(), e.points());
        }
        if (!b[M + l + 1].allFinite() || !step_map.P.allFinite() || !step_map.Q.allFinite() ||
            !step_map.R.allFinite())
          throw NonFiniteStep(what + " (" + which + std::to_string(l + 1) + "): the step from t = " +
                                  format_number(tap.t) + " to " + format_number(tap.t + h) + " has a " +
                                  (b[M + l + 1].allFinite() ? "derivative (step map)" : "new state") +
                                  " that is not finite",
                              {model_point<D, DW>(tap.t, b[M + l], tap.w0),
                               model_point<D, DW>(tap.t + h, b[M + l + 1], tap.w1)});
      }
      for (long j = 0; j <= M; ++j) U.segment<D>(j * D) = b[K + j];
    }
  }

  // Step l from u with its tap: in the region the grid fixes for it (an orbit's grid aligned with
  // its contacts, grid.hpp), else the stepper's step.
  V step(long l, const DelayTap<W>& tap, const V& u, StepMap<D, DW>& map) const {
    if constexpr (Model::has_switching) {
      if (const int region = grid_.step_region(l)) return stepper_.region_step(tap.t, tap.h, u, tap.w0, tap.w1, region, map);
    }
    return stepper_.step(tap.t, tap.h, u, tap.w0, tap.w1, map);
  }

  // The monodromy at U (the Jacobian of apply at U).
  Monodromy<D, DW> monodromy(const Eigen::VectorXd& U) const {
    std::vector<StepMap<D, DW>> maps;
    apply(U, &maps);
    return Monodromy<D, DW>(grid_, std::move(maps));
  }

 private:
  Stepper stepper_;
  HistoryGrid grid_;
};

}  // namespace delayspec
