#pragma once
// Regenerative chatter in milling, one degree of freedom (the standard benchmark of Insperger &
// Stepan, and of Ding et al.'s full discretisation):
//
//   m x'' + 2 m zeta omega_n x' + m omega_n^2 x = -a_p h(t) (x(t) - x(t - tau)),
//
//   h(t) = sum_j g_j(t) sin(phi_j) (K_t cos(phi_j) + K_n sin(phi_j)),
//   phi_j(t) = 2 pi Omega t / 60 + 2 pi j / N_t,   j = 0 .. N_t - 1,
//
// g_j = 1 while tooth j is in the cut, phi_st <= phi_j mod 2 pi < phi_ex, else 0. Down-milling:
// phi_st = arccos(2 a/D - 1), phi_ex = pi; up-milling: phi_st = 0, phi_ex = arccos(1 - 2 a/D).
// The delay is the tooth-passing period, tau = T = 60 / (N_t Omega) (Omega in rpm, t in s); h
// is T-periodic, so the stroboscopic map is over T. y = (x, v); linear in (y, y_tau).
//
// The cutting windows are time switches (model.hpp): branch j = 1 + (bit mask of the teeth in
// the cut), and each branch's h is the sum of its teeth's terms at any t (smooth). Where a tooth
// enters or leaves the cut with sin(phi) (K_t cos + K_n sin) != 0 (down-milling entry at a/D < 1,
// up-milling exit) h jumps; at a/D = 1 it is continuous with a kink.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"

namespace delayspec {

enum class MillingDirection { down, up };

struct MillingParameters {
  double spindle_rpm = 10000;                   // Omega
  double depth = 0.5e-3;                        // a_p, axial depth of cut (m)
  double radial_immersion = 1;                  // a/D, in (0, 1]
  int teeth = 2;                                // N_t
  double Kt = 6e8;                              // tangential cutting coefficient (N/m^2)
  double Kn = 2e8;                              // normal cutting coefficient (N/m^2)
  double omega_n = 922 * 2 * std::numbers::pi;  // natural angular frequency (rad/s)
  double zeta = 0.011;                          // relative damping
  double mass = 0.03993;                        // modal mass (kg)
  MillingDirection direction = MillingDirection::down;
  double x0 = 1e-5, v0 = 0;  // constant initial history (m, m/s), for simulations
  // Variable pitch (VariablePitchMillingModel, model_milling_variable_pitch.hpp): the angle
  // from tooth j to tooth j + 1 in degrees, teeth of them summing to 360. Empty: equal pitch.
  std::vector<double> pitch_angles;
};

namespace detail {

// The cutter's geometry and the cut, shared by the equal- and variable-pitch models: tooth j at
// the angle phi_j(t) = 2 pi Omega t / 60 + offset_j, in the cut where phi_start <= phi_j mod 2 pi
// < phi_exit; which teeth are in the cut at t (the branch, 1 + bit mask), when the next enters or
// leaves, and each tooth's sin(phi) (K_t cos(phi) + K_n sin(phi)).
class MillingCutter {
 public:
  static constexpr int kMaxTeeth = 30;  // branch j encodes the teeth in the cut as bits of j - 1

  // BadInput naming the key for a value outside its range. `offsets`: offset_j, one per tooth.
  MillingCutter(const MillingParameters& p, const std::vector<double>& offsets) : p_(p) {
    require_positive("spindle_rpm", p.spindle_rpm);
    require_finite("depth", p.depth);
    if (p.depth < 0) throw BadInput("`depth = " + format_number(p.depth) + "`: must be >= 0 (m)");
    require_finite("radial_immersion", p.radial_immersion);
    if (!(p.radial_immersion > 0 && p.radial_immersion <= 1))
      throw BadInput("`radial_immersion = " + format_number(p.radial_immersion) + "`: must be in (0, 1] (a/D)");
    if (p.teeth < 1 || p.teeth > kMaxTeeth)
      throw BadInput("`teeth = " + std::to_string(p.teeth) + "`: must be between 1 and " + std::to_string(kMaxTeeth));
    require_finite("Kt", p.Kt);
    require_finite("Kn", p.Kn);
    require_positive("omega_n", p.omega_n);
    require_finite("zeta", p.zeta);
    require_positive("mass", p.mass);
    require_finite("x0", p.x0);
    require_finite("v0", p.v0);
    const double ratio = 2 * p.radial_immersion - 1;  // in (-1, 1]
    if (p.direction == MillingDirection::down) {
      phi_start_ = std::acos(ratio);
      phi_exit_ = std::numbers::pi;
    } else {
      phi_start_ = 0;
      phi_exit_ = std::acos(-ratio);
    }
    spindle_ = 2 * std::numbers::pi * p.spindle_rpm / 60;
    cut_ = p.depth / p.mass;
    std::copy(offsets.begin(), offsets.end(), offsets_.begin());
  }
  const MillingParameters& parameters() const { return p_; }
  double spindle() const { return spindle_; }  // 2 pi Omega / 60 (rad/s)
  double cut() const { return cut_; }          // a_p / m

  // The teeth in the cut on [t, next switch): branch 1 + mask.
  int time_segment(double t) const {
    int mask = 0;
    for (int j = 0; j < p_.teeth; ++j) {
      const double phase = wrapped_angle(j, t);
      if (phase >= phi_start_ && phase < phi_exit_) mask |= 1 << j;
    }
    return 1 + mask;
  }
  // The first time in (t0, t1) at which a tooth enters or leaves the cut, else t1.
  // A boundary that a tooth's angle cannot reach within the step is passed over without its exact
  // crossing time (next_crossing: a floor and three divisions): most steps meet no switch, and
  // the exact times for every tooth and boundary were 9 % of a lobe diagram's time. Out of reach:
  // the angle still to turn from phi_j(t0) to the boundary exceeds the angle the step sweeps,
  // spindle (t1 - t0), by the margin `clear` (and the boundary is not just behind, where rounding
  // may still put the crossing after t0); `clear` is far above the rounding of both angles
  // (64 eps |phi|, 1e-9 rad at least), so a crossing passed over would have come after t1 and
  // the result is the same double as with every crossing computed.
  double next_time_switch(double t0, double t1) const {
    const double two_pi = 2 * std::numbers::pi;
    const double clear = 1e-9 + 64 * std::numeric_limits<double>::epsilon() * (std::abs(spindle_ * t0) + two_pi);
    const double swept = spindle_ * (t1 - t0) + clear;
    double next = t1;
    for (int j = 0; j < p_.teeth; ++j) {
      const double phase = wrapped_angle(j, t0);
      for (double boundary : {phi_start_, phi_exit_}) {
        double ahead = boundary - phase;  // the angle still to turn, in [0, 2 pi)
        if (ahead < 0) ahead += two_pi;
        if (ahead > swept && ahead < two_pi - clear) continue;
        next = std::min(next, next_crossing(j, boundary, t0));
      }
    }
    return next;
  }
  // sin(phi_j) (K_t cos(phi_j) + K_n sin(phi_j)) of tooth j at t (in the cut or not).
  double tooth_coefficient(int tooth, double t) const {
    const double phi = spindle_ * t + offsets_[tooth];
    const double s = std::sin(phi), c = std::cos(phi);
    return s * (p_.Kt * c + p_.Kn * s);
  }

  double entry_angle() const { return phi_start_; }
  double exit_angle() const { return phi_exit_; }

 private:
  // phi_j(t) mod 2 pi, in [0, 2 pi).
  double wrapped_angle(int j, double t) const {
    const double two_pi = 2 * std::numbers::pi;
    double phase = std::fmod(spindle_ * t + offsets_[j], two_pi);
    if (phase < 0) phase += two_pi;
    return phase;
  }
  // The first t > t0 with phi_j(t) = boundary (mod 2 pi): t = (boundary - offset + 2 pi n) / spindle.
  double next_crossing(int j, double boundary, double t0) const {
    const double two_pi = 2 * std::numbers::pi;
    const double base = boundary - offsets_[j];
    double n = std::floor((spindle_ * t0 - base) / two_pi);
    auto time = [&](double k) { return (base + two_pi * k) / spindle_; };
    while (time(n) <= t0) n += 1;  // rounding may leave n one short (or, below, one long)
    while (time(n - 1) > t0) n -= 1;
    return time(n);
  }

  MillingParameters p_;
  std::array<double, kMaxTeeth> offsets_{};
  double phi_start_ = 0, phi_exit_ = 0, spindle_ = 0, cut_ = 0;
};

// Equal pitch: offset_j = 2 pi j / N_t.
inline std::vector<double> equal_pitch_offsets(int teeth) {
  std::vector<double> offsets(std::max(teeth, 0));
  for (int j = 0; j < teeth; ++j) offsets[j] = 2 * std::numbers::pi * j / teeth;
  return offsets;
}

}  // namespace detail

class MillingModel {
 public:
  static constexpr int d = 2;
  static constexpr bool has_switching = false;
  static constexpr bool has_time_switches = true;
  static constexpr bool affine_in_state = true;
  static constexpr bool is_linear = true;
  static constexpr int kMaxTeeth = detail::MillingCutter::kMaxTeeth;
  using V = Vec<2>;
  using M = Mat<2>;

  // BadInput naming the key for a value outside its range; pitch_angles must be empty (equal
  // pitch: VariablePitchMillingModel takes the others).
  explicit MillingModel(const MillingParameters& p = {})
      : cutter_(checked_equal_pitch(p), detail::equal_pitch_offsets(p.teeth)) {}
  const MillingParameters& parameters() const { return cutter_.parameters(); }
  double tau() const { return 60 / (parameters().teeth * parameters().spindle_rpm); }
  double period() const { return tau(); }

  int time_segment(double t) const { return cutter_.time_segment(t); }
  double next_time_switch(double t0, double t1) const { return cutter_.next_time_switch(t0, t1); }

  // h(t) of branch j (the teeth of mask j - 1 in the cut).
  double cutting_coefficient(int j, double t) const {
    double h = 0;
    for (int tooth = 0, mask = j - 1; mask != 0; ++tooth, mask >>= 1)
      if (mask & 1) h += cutter_.tooth_coefficient(tooth, t);
    return h;
  }

  V f(int j, double t, const V& y, const V& y_tau) const {
    const double w = parameters().omega_n, zeta = parameters().zeta;
    return V(y[1], -2 * zeta * w * y[1] - w * w * y[0] - cutter_.cut() * cutting_coefficient(j, t) * (y[0] - y_tau[0]));
  }
  M A(int j, double t, const V&, const V&) const {
    const double w = parameters().omega_n;
    M a;
    a << 0, 1, -w * w - cutter_.cut() * cutting_coefficient(j, t), -2 * parameters().zeta * w;
    return a;
  }
  M B(int j, double t, const V&, const V&) const {
    M b;
    b << 0, 0, cutter_.cut() * cutting_coefficient(j, t), 0;
    return b;
  }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
  V initial_state() const { return V(parameters().x0, parameters().v0); }

  double entry_angle() const { return cutter_.entry_angle(); }
  double exit_angle() const { return cutter_.exit_angle(); }

 private:
  static const MillingParameters& checked_equal_pitch(const MillingParameters& p) {
    if (!p.pitch_angles.empty())
      throw BadInput("MillingModel: equal pitch (pitch_angles given: VariablePitchMillingModel)");
    return p;
  }
  detail::MillingCutter cutter_;
};

}  // namespace delayspec
