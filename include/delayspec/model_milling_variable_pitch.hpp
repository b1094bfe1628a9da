#pragma once
// Milling with a variable-pitch cutter (model_milling.hpp's equation, teeth unequally spaced, the
// industrial remedy for chatter: Altintas, Engin & Budak, J. Manuf. Sci. Eng. 121, 1999):
//
//   m x'' + 2 m zeta omega_n x' + m omega_n^2 x = -a_p sum_j g_j(t) h_j(t) (x(t) - x(t - tau_j)),
//
// tooth j at offset_j = psi_0 + ... + psi_{j-1} (psi_j = pitch_angles[j], the angle from tooth j
// to tooth j + 1 in the direction of rotation), so tooth j + 1 passed every angle psi_j / Omega
// before tooth j: tooth j cuts the surface tooth j + 1 left, tau_j = psi_j / Omega (Omega in
// rad/s). Teeth with the same spacing share a delay: the model has one delay per distinct
// spacing, at most kMaxPitches (padded to kMaxPitches with zero gain at the longest, so that
// delay_count is a constant). N counts steps per the longest delay.
//
// The map's period is the pattern's: the smallest m dividing N_t with psi_{j + m} = psi_j for
// all j, over (psi_0 + ... + psi_{m-1}) / Omega (half a revolution for the alternating pitch
// 80/100/80/100; one tooth period when all are equal).
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"
#include "delayspec/model_milling.hpp"

namespace delayspec {

class VariablePitchMillingModel {
 public:
  static constexpr int d = 2;
  static constexpr int kMaxPitches = 4;
  static constexpr int delay_count = kMaxPitches;
  static constexpr bool has_switching = false;
  static constexpr bool has_time_switches = true;
  static constexpr bool affine_in_state = true;
  static constexpr bool is_linear = true;
  using V = Vec<2>;
  using M = Mat<2>;
  using Delayed = Vec<d * delay_count>;
  using DelayedMatrix = RectMat<d, d * delay_count>;

  // BadInput naming `pitch_angles` (or the key) for a value outside its range: teeth angles,
  // each > 0, summing to 360 degrees (to 1e-9), at most kMaxPitches distinct.
  explicit VariablePitchMillingModel(const MillingParameters& p)
      : cutter_(p, offsets(checked(p))) {
    const double spindle = cutter_.spindle();
    // Distinct spacings (equal to 1e-12 degrees: what a scene writes twice is one spacing).
    for (int j = 0; j < p.teeth; ++j) {
      const double psi = p.pitch_angles[j];
      int slot = 0;
      while (slot < pitches_ && std::abs(spacings_[slot] - psi) > 1e-12) ++slot;
      if (slot == pitches_) {
        if (pitches_ == kMaxPitches)
          throw BadInput("`pitch_angles`: more than " + std::to_string(kMaxPitches) +
                         " distinct spacings (one delay each); at most " + std::to_string(kMaxPitches));
        spacings_[pitches_++] = psi;
      }
      slot_of_tooth_[j] = slot;
    }
    const double longest = *std::max_element(spacings_.begin(), spacings_.begin() + pitches_);
    for (int k = 0; k < kMaxPitches; ++k)
      delays_[k] = (k < pitches_ ? spacings_[k] : longest) * std::numbers::pi / 180 / spindle;
    tau_ = longest * std::numbers::pi / 180 / spindle;
    // The pattern's period: the smallest m | N_t whose shift leaves the slots as they are.
    int m = 1;
    for (; m < p.teeth; ++m) {
      if (p.teeth % m != 0) continue;
      bool repeats = true;
      for (int j = 0; j + m < p.teeth && repeats; ++j) repeats = slot_of_tooth_[j] == slot_of_tooth_[j + m];
      if (repeats) break;
    }
    double angle = 0;
    for (int j = 0; j < m; ++j) angle += p.pitch_angles[j];
    period_ = angle * std::numbers::pi / 180 / spindle;
  }
  const MillingParameters& parameters() const { return cutter_.parameters(); }
  double tau() const { return tau_; }  // the longest delay
  std::array<double, delay_count> delays() const { return delays_; }
  double period() const { return period_; }
  int distinct_pitches() const { return pitches_; }

  int time_segment(double t) const { return cutter_.time_segment(t); }
  double next_time_switch(double t0, double t1) const { return cutter_.next_time_switch(t0, t1); }

  // h_k(t) of branch j: the sum over the teeth in the cut (mask j - 1) whose spacing is slot k.
  std::array<double, kMaxPitches> cutting_coefficients(int j, double t) const {
    std::array<double, kMaxPitches> h{};
    for (int tooth = 0, mask = j - 1; mask != 0; ++tooth, mask >>= 1)
      if (mask & 1) h[slot_of_tooth_[tooth]] += cutter_.tooth_coefficient(tooth, t);
    return h;
  }

  V f(int j, double t, const V& y, const Delayed& z) const {
    const std::array<double, kMaxPitches> h = cutting_coefficients(j, t);
    double cutting = 0;
    for (int k = 0; k < kMaxPitches; ++k) cutting += h[k] * (y[0] - z[d * k]);
    const double w = parameters().omega_n;
    return V(y[1], -2 * parameters().zeta * w * y[1] - w * w * y[0] - cutter_.cut() * cutting);
  }
  M A(int j, double t, const V&, const Delayed&) const {
    const std::array<double, kMaxPitches> h = cutting_coefficients(j, t);
    const double w = parameters().omega_n;
    M a;
    a << 0, 1, -w * w - cutter_.cut() * std::accumulate(h.begin(), h.end(), 0.0), -2 * parameters().zeta * w;
    return a;
  }
  DelayedMatrix B(int j, double t, const V&, const Delayed&) const {
    const std::array<double, kMaxPitches> h = cutting_coefficients(j, t);
    DelayedMatrix b = DelayedMatrix::Zero();
    for (int k = 0; k < kMaxPitches; ++k) b(1, d * k) = cutter_.cut() * h[k];
    return b;
  }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
  V initial_state() const { return V(parameters().x0, parameters().v0); }

 private:
  static const MillingParameters& checked(const MillingParameters& p) {
    const auto& angles = p.pitch_angles;
    if (static_cast<int>(angles.size()) != p.teeth)
      throw BadInput("`pitch_angles`: " + std::to_string(angles.size()) + " angles for `teeth = " +
                     std::to_string(p.teeth) + "`: one per tooth (the angle to the next tooth)");
    double sum = 0;
    for (double psi : angles) {
      if (!std::isfinite(psi) || !(psi > 0))
        throw BadInput("`pitch_angles`: " + format_number(psi) + " degrees: each angle must be > 0");
      sum += psi;
    }
    if (std::abs(sum - 360) > 1e-9 * 360)
      throw BadInput("`pitch_angles`: sum to " + format_number(sum) + " degrees, not 360");
    return p;
  }
  static std::vector<double> offsets(const MillingParameters& p) {
    std::vector<double> out(p.teeth);
    double angle = 0;
    for (int j = 0; j < p.teeth; ++j) {
      out[j] = angle * std::numbers::pi / 180;
      angle += p.pitch_angles[j];
    }
    return out;
  }

  detail::MillingCutter cutter_;
  std::array<double, kMaxPitches> spacings_{};  // the distinct spacings (degrees), pitches_ of them
  std::array<int, detail::MillingCutter::kMaxTeeth> slot_of_tooth_{};
  std::array<double, delay_count> delays_{};
  int pitches_ = 0;
  double tau_ = 0, period_ = 0;
};

}  // namespace delayspec
