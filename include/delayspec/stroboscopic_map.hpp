#pragma once
// StroboscopicMap: the nonlinear map U -> P(U) over one stroboscopic period (K steps of the
// stepper), optionally recording the step maps along the way, which gives the Monodromy at U.
//
// Same linear-buffer layout as Monodromy: b[0..M] = U, step l writes b[M + l + 1], the result
// is b[K .. K + M]. Step l starts at time t = l h (the grid phase is fixed: the section is
// t = 0 mod T).
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
  using V = Vec<D>;

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
  Eigen::VectorXd apply(const Eigen::VectorXd& U, std::vector<StepMap<D>>* maps = nullptr,
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
    StepMap<D> scratch;
    auto slot = [&b](long i) -> const V& { return b[i]; };
    for (long l = 0; l < K; ++l) {
      const DelayTap<V> tap = grid_.delay_tap<V>(l, slot);
      b[M + l + 1] = stepper_.step(tap.t, grid_.h, b[M + l], tap.w0, tap.w1, maps ? (*maps)[l] : scratch);
      if (trajectory) trajectory->push_back(b[M + l + 1]);
    }
    Eigen::VectorXd out(dimension());
    for (long j = 0; j <= M; ++j) out.segment<D>(j * D) = b[K + j];
    return out;
  }

  // The monodromy at U (the Jacobian of apply at U).
  Monodromy<D> monodromy(const Eigen::VectorXd& U) const {
    std::vector<StepMap<D>> maps;
    apply(U, &maps);
    return Monodromy<D>(grid_, std::move(maps));
  }

 private:
  Stepper stepper_;
  HistoryGrid grid_;
};

}  // namespace delayspec
