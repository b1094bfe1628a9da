#pragma once
// The model concept. A model is a small value type describing
//
//     y'(t) = f_j(t, y(t), y(t - tau)),   j = 1 where H(y) > 0,  j = 2 where H(y) <= 0
//
// with state dimension `d` known at compile time. A model provides (names are the contract):
//
//   static constexpr int d;                  // state dimension
//   static constexpr bool has_switching;     // false: H is irrelevant, region is always 1
//   static constexpr bool affine_in_state;   // f_j affine in y(t) for fixed (t, y_tau): the
//                                            // implicit trapezoid equation is one linear solve
//   static constexpr bool is_linear;         // f linear in (y, y_tau): the monodromy does not
//                                            // depend on the orbit (take the zero orbit)
//   double tau() const;                      // the delay
//   double period() const;                   // the period T of the forcing / stroboscopic map
//   Vec f(int j, double t, const Vec& y, const Vec& y_tau) const;
//   Mat A(int j, double t, const Vec& y, const Vec& y_tau) const;   // df_j / dy
//   Mat B(int j, double t, const Vec& y, const Vec& y_tau) const;   // df_j / dy_tau
//   Vec initial_state() const;               // constant initial history y(t), t <= 0
//
// Models with switching (has_switching) also provide the switching function and, for event
// handling (event_step.hpp), the time derivatives of the field:
//   double H(const Vec& y) const;  Vec grad_H(const Vec& y) const;
//   Vec f_t(int j, double t, const Vec& y, const Vec& y_tau) const;   // df_j / dt at fixed y, y_tau
//   Vec f_tt(int j, double t, const Vec& y, const Vec& y_tau) const;  // d2f_j / dt2 (events = linear)
// and must have f_1 = f_2 on H = 0 (a continuous vector field: no saltation; design.md 1.5).
// The event code assumes H affine (grad_H constant); events = linear with the consistent
// Jacobian also assumes A and B constant within a region (true for the impact model).
//
// Regions: j = 1 is the strict side H > 0 (design.md 1.5 conventions).
//
// Time switches. A model whose field changes at known times, independent of the state (a
// cutting window in milling: a tooth is in the cut or not), declares
//   static constexpr bool has_time_switches = true;
//   int time_segment(double t) const;   // the branch j in force on [t, next switch): j >= 1
//   double next_time_switch(double t0, double t1) const;  // first switch in (t0, t1), else t1
// and its f, A, B for branch j are smooth in t on the whole step (the branch's own formula,
// evaluated past the window's ends when a piece ends there). The step is then split at the
// switches (time_switch_step.hpp); with events = off it is the plain grid trapezoid, each node
// evaluated in the branch of its own time (first order across a jump). Such a model has no
// state switching (has_switching = false): the two kinds are not combined.
//
// Several delays. A model with n > 1 discrete delays declares
//   static constexpr int delay_count = n;
//   std::array<double, n> delays() const;    // tau_1 .. tau_n, each > 0 (any order)
// and tau() returns the longest (the history's length: N steps per the longest delay). Its
// delayed argument is then the n delayed states stacked, Vec<d n> (rows i d .. i d + d - 1 hold
// y(t - tau_{i+1})), and B = df / d(that stack) is d x d n (DelayedVec, DelayedMat). A model
// without delay_count has the one delay tau(). Switching and time switches work with several
// delays as with one (the event and time-switch steps carry the stacked delayed values).
//
// Autonomy. A model whose f does not depend on t (no forcing, no switch) declares
//   static constexpr bool autonomous = true;
// its period() is then only the stroboscopic map's sampling time, and it may have equilibria
// (equilibrium.hpp). A model that does not declare it is taken as forced.
#include <array>
#include <concepts>
#include <vector>

#include "delayspec/types.hpp"

namespace delayspec {

// Does Model switch its field at given times (see above)? Models that do not declare
// has_time_switches do not.
template <class Model>
concept TimeSwitchedModel = requires {
  requires Model::has_time_switches;
};

// Is Model autonomous (see above)?
template <class Model>
concept AutonomousModel = requires {
  requires Model::autonomous;
};

// The number of delays of Model (1 unless it declares delay_count).
template <class Model>
constexpr int delay_count_of() {
  if constexpr (requires { Model::delay_count; }) return Model::delay_count;
  else return 1;
}
// The rows of a model's delayed argument, and its types (see above).
template <class Model>
inline constexpr int delayed_rows = Model::d * delay_count_of<Model>();
template <class Model>
using DelayedVec = Vec<delayed_rows<Model>>;
template <class Model>
using DelayedMat = RectMat<Model::d, delayed_rows<Model>>;

// The delays of a model, in its order: {tau()} for a model with one delay.
template <class Model>
std::vector<double> delays_of(const Model& model) {
  if constexpr (delay_count_of<Model>() > 1) {
    const auto taus = model.delays();
    return std::vector<double>(taus.begin(), taus.end());
  } else {
    return {model.tau()};
  }
}

// The contract above as a concept, checked where a stepper is made (stepper.hpp): the members
// every model has, the switching members (H, grad_H, f_t, f_tt) only when has_switching, the
// time-switch members only when has_time_switches.
template <class Model>
concept DelayModel = requires(const Model& m, const Vec<Model::d>& y, double t, int j) {
  requires Model::d >= 1;
  { Model::has_switching } -> std::convertible_to<bool>;
  { Model::affine_in_state } -> std::convertible_to<bool>;
  { Model::is_linear } -> std::convertible_to<bool>;
  { m.tau() } -> std::convertible_to<double>;
  { m.period() } -> std::convertible_to<double>;
  { m.f(j, t, y, DelayedVec<Model>()) } -> std::convertible_to<Vec<Model::d>>;
  { m.A(j, t, y, DelayedVec<Model>()) } -> std::convertible_to<Mat<Model::d>>;
  { m.B(j, t, y, DelayedVec<Model>()) } -> std::convertible_to<DelayedMat<Model>>;
  { m.initial_state() } -> std::convertible_to<Vec<Model::d>>;
}
&&(delay_count_of<Model>() == 1 || requires(const Model& m) {
     requires delay_count_of<Model>() >= 2;
     { m.delays() } -> std::convertible_to<std::array<double, delay_count_of<Model>()>>;
   })
&&(!Model::has_switching ||
   requires(const Model& m, const Vec<Model::d>& y, double t, int j) {
     { m.H(y) } -> std::convertible_to<double>;
     { m.grad_H(y) } -> std::convertible_to<Vec<Model::d>>;
     { m.f_t(j, t, y, DelayedVec<Model>()) } -> std::convertible_to<Vec<Model::d>>;
     { m.f_tt(j, t, y, DelayedVec<Model>()) } -> std::convertible_to<Vec<Model::d>>;
   }) &&
    (!TimeSwitchedModel<Model> || requires(const Model& m, double t) {
      { m.time_segment(t) } -> std::convertible_to<int>;
      { m.next_time_switch(t, t) } -> std::convertible_to<double>;
    });

// Region of a state: 1 on the strict side H > 0, else 2. Models without switching: 1.
template <class Model>
int region_of(const Model& model, const Vec<Model::d>& y) {
  if constexpr (!Model::has_switching) {
    return 1;
  } else {
    return model.H(y) > 0 ? 1 : 2;
  }
}

}  // namespace delayspec
