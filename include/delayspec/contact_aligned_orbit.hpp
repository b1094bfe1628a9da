#pragma once
// A periodic orbit of a model that switches in its state (an impact: H(y) = x - e) on a grid with
// a node at every contact time (issue 58 item 2; design.md 1.5c).
//
// On a uniform grid a contact's entry and exit fall inside steps; the step is split there (event
// location, event_step.hpp) and keeps order 2, but its error depends on where in its step the
// event falls, theta = frac(t_c / h), which changes with N: the h^2 coefficient of the multipliers
// wanders and Richardson stops after one column (design.md 1.5, 1.8). Here the contact times c_i
// are nodes: the grid is aligned with them (grid.hpp, GridBreaks with region1), each piece between
// them uniform, and every step is the plain trapezoid in the one region of its piece (contact or
// not: HistoryGrid::step_region), so the discrete orbit and its step maps are smooth functions of
// the history and of the c_i, and the error expansion is even again.
//
// The c_i are unknowns, found with the orbit: H(y(c_i)) = 0 at the node c_i. From the contact
// times of the orbit on the uniform grid (its steps' located events), alternately
//   1. the orbit on the grid aligned with the current c_i (Newton-Krylov shooting from the last
//      orbit carried over by time, orbit_shooting.hpp), and
//   2. each c_i moved by Newton's step on its own condition, dc_i = -H(u(c_i)) / (dH/dt), dH/dt =
//      grad H . f(c_i, u, y(c_i - tau)) (f is continuous across H = 0: either region's),
// until every |dc_i| <= tolerance T. The iteration converges fast because the orbit hardly feels a
// misplaced contact: a contact end off by delta moves the field by |f_2 - f_1| ~ |grad H| |H| ~
// delta^2 there, so the orbit moves by O(delta^2) and step 2 is Newton's on H(y(c)) = 0 with an
// O(delta^2) perturbation (measured on the paper's orbit: moves of 1e-4, 1e-8, 1e-16).
//
// The monodromy on that grid is the trapezoid rule of the variational equation with A switching
// at the (discrete) contact times: the step maps of the converged orbit. It does not include the
// sensitivity of the c_i to the history (the discrete map's consistent Jacobian would, design.md
// 1.5): for a continuous vector field that term vanishes in the limit h -> 0 (no saltation), and
// leaving it out keeps the expansion even; the multipliers converge to the exact ones either way.
//
// Not aligned (std::nullopt with the reason): no contact (nothing to align), a contact shorter
// than 1e-9 T (grazing: the pieces would degenerate), entries and exits that do not alternate, a
// grid that cannot give every piece a step (N too small), a shooting solve that fails, or no
// convergence in max_iterations. The caller then keeps the uniform grid's orbit.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "delayspec/errors.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/orbit_shooting.hpp"
#include "delayspec/periodic_orbit.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {

struct ContactAlignmentOptions {
  int max_iterations = 16;  // alternations of orbit and contact times
  // |dc_i| <= tolerance T at the end, or the moves stalled at rounding (a move above half the
  // last, both below stall T): H's rounding, ~eps |x|, moves c by eps |x| / |dH/dt|, 1e-15 T on the
  // paper's orbit (its slope 0.025). The multiplier moves ~10x a contact's error (design.md 1.5):
  // a contact left at 1e-13 T stopped the fifth Richardson column from showing its order there.
  double tolerance = 4e-16;
  double stall = 1e-12;
  OrbitByShootingOptions shooting;
};

template <int D, int DW = D>
struct ContactAlignedOrbit {
  HistoryGrid grid;             // aligned with the contacts, steps in fixed regions
  PeriodicOrbit orbit;          // on `grid`
  OrbitLinearisation<D, DW> at_orbit;  // its step maps (the monodromy) and states
  std::vector<std::array<double, 2>> contacts;  // [entry, exit) in the map's time (exit < entry: wraps)
  std::vector<double> moves;    // max |dc_i| / T of each alternation (the convergence)
};

namespace detail {

// The states u_0 .. u_{K-1} of a periodic orbit as one vector (PeriodicOrbitProblem's order).
template <int D>
Eigen::VectorXd state_sequence(const std::vector<Vec<D>>& states, long K) {
  Eigen::VectorXd x(static_cast<long>(D) * K);
  for (long l = 0; l < K; ++l) x.template segment<D>(D * l) = states[static_cast<size_t>(l)];
  return x;
}

// The taps of node l of a periodic orbit given by its states (u_{l+K} = u_l): delay_taps with the
// history slots u_{l - M} .. (orbit_search.hpp's convention).
template <int D, class W>
DelayTap<W> orbit_tap(const HistoryGrid& g, const std::vector<Vec<D>>& states, long l) {
  const long K = g.K, M = g.M;
  auto u = [&](long i) { return states[static_cast<size_t>(((i % K) + K) % K)]; };
  return g.template delay_taps<D, W>(l, [&](long i) { return u(i - M); });
}

}  // namespace detail

// The contact intervals of the orbit whose states on `map`'s grid (uniform, events located) are
// `states` (K + 1 of them): each step stepped again with its events, entries into region 1 and
// exits paired in order around the map. Empty when the orbit has no contact; NumericalFailure when
// entries and exits do not alternate.
template <class Model, class Stepper>
std::vector<std::array<double, 2>> orbit_contact_intervals(const StroboscopicMap<Model, Stepper>& map,
                                                           const std::vector<Vec<Model::d>>& states) {
  constexpr int D = Model::d;
  using W = DelayedVec<Model>;
  const HistoryGrid& g = map.grid();
  std::vector<std::pair<double, int>> events;  // (time, region entered)
  StepMap<D, delayed_rows<Model>> scratch;
  for (long l = 0; l < g.K; ++l) {
    const DelayTap<W> tap = detail::orbit_tap<D, W>(g, states, l);
    StepEvents e;
    map.stepper().step(tap.t, tap.h, states[static_cast<size_t>(l)], tap.w0, tap.w1, scratch, &e);
    for (int i = 0; i < e.count; ++i) events.emplace_back(g.node_time(l) + e.offset[i], e.new_region[i]);
  }
  std::vector<std::array<double, 2>> contacts;
  if (events.empty()) return contacts;
  const double span = g.period * g.periods_per_map;
  // start at an entry; entries and exits must alternate around the map
  size_t first = 0;
  while (first < events.size() && events[first].second != 1) ++first;
  if (first == events.size()) throw NumericalFailure("the orbit's contacts: exits without entries");
  const size_t n = events.size();
  if (n % 2 != 0) throw NumericalFailure("the orbit's contacts: an odd number of crossings of H = 0");
  for (size_t k = 0; k < n; k += 2) {
    const auto& entry = events[(first + k) % n];
    const auto& exit = events[(first + k + 1) % n];
    if (entry.second != 1 || exit.second == 1)
      throw NumericalFailure("the orbit's contacts: entries into and exits from H > 0 do not alternate");
    contacts.push_back({std::fmod(entry.first, span), std::fmod(exit.first, span)});
  }
  return contacts;
}

// The orbit on the grid aligned with its contacts (header), from the orbit `states` (K + 1) on
// `map`'s uniform grid. std::nullopt (with `why`) where it cannot be aligned.
template <class Model, class Stepper>
std::optional<ContactAlignedOrbit<Model::d, delayed_rows<Model>>> contact_aligned_orbit(
    const StroboscopicMap<Model, Stepper>& map, const std::vector<Vec<Model::d>>& states,
    const ContactAlignmentOptions& o, std::string& why) {
  constexpr int D = Model::d, DW = delayed_rows<Model>;
  using W = DelayedVec<Model>;
  using Map = StroboscopicMap<Model, Stepper>;
  const HistoryGrid& uniform = map.grid();
  const Model& model = map.stepper().model();
  const double T = uniform.period, span = T * uniform.periods_per_map;
  ContactAlignedOrbit<D, DW> out;
  try {
    out.contacts = orbit_contact_intervals(map, states);
  } catch (const NumericalFailure& e) {
    why = e.what();
    return std::nullopt;
  }
  if (out.contacts.empty()) {
    why = "the orbit has no contact";
    return std::nullopt;
  }
  HistoryGrid previous_grid = uniform;
  std::vector<Vec<D>> previous_states = states;
  for (int it = 1; it <= o.max_iterations; ++it) {
    GridBreaks breaks;
    for (const auto& c : out.contacts) {
      const double length = c[1] >= c[0] ? c[1] - c[0] : c[1] + span - c[0];
      if (!(length > 1e-9 * T)) {
        why = "a contact of " + format_number(length) + " time units (grazing: no piece between its ends)";
        return std::nullopt;
      }
      breaks.times.push_back(c[0]);
      breaks.times.push_back(c[1]);
    }
    breaks.region1 = out.contacts;
    try {
      out.grid = make_grid(uniform.delay_values(), T, uniform.N, uniform.periods_per_map, {}, breaks);
      const Map aligned(map.stepper(), out.grid);
      const Eigen::VectorXd guess = prolong_periodic_sequence(
          detail::state_sequence<D>(previous_states, previous_grid.K), D, previous_grid, out.grid);
      out.orbit = orbit_by_shooting(aligned, PeriodicOrbitProblem<Map>(aligned).history(guess), o.shooting,
                                    &out.at_orbit);
    } catch (const std::exception& e) {  // BadInput (too few steps) or NumericalFailure (shooting)
      why = std::string("the orbit on the grid aligned with its contacts: ") + e.what();
      return std::nullopt;
    }
    // Newton on H(y(c_i)) = 0 for each contact end, at its node
    double largest = 0;
    for (auto& c : out.contacts)
      for (double& end : c) {
        const long period = static_cast<long>(std::floor(end / T));
        const double in_period = end - static_cast<double>(period) * T;
        const auto at = std::lower_bound(out.grid.nodes.begin(), out.grid.nodes.end(), in_period);
        long j = static_cast<long>(at - out.grid.nodes.begin());
        if (j > 0 && (at == out.grid.nodes.end() || in_period - out.grid.nodes[j - 1] < *at - in_period)) --j;
        const long l = (period * out.grid.steps_per_period + j) % out.grid.K;
        const Vec<D>& u = out.at_orbit.states[static_cast<size_t>(l)];
        const DelayTap<W> tap = detail::orbit_tap<D, W>(out.grid, out.at_orbit.states, l);
        const double slope = model.grad_H(u).dot(model.f(1, tap.t, u, tap.w0));
        const double dc = -model.H(u) / slope;
        if (!std::isfinite(dc)) {
          why = "a contact end where H's time derivative is 0 (grazing)";
          return std::nullopt;
        }
        end = std::fmod(end + dc + span, span);
        largest = std::max(largest, std::abs(dc) / T);
      }
    out.moves.push_back(largest);
    if (largest <= o.tolerance) return out;
    if (out.moves.size() >= 2 && largest <= o.stall && largest > 0.5 * out.moves[out.moves.size() - 2]) return out;
    previous_grid = out.grid;
    previous_states = out.at_orbit.states;
  }
  why = "the contact times did not settle in " + std::to_string(o.max_iterations) + " alternations (last move " +
        format_number(out.moves.back()) + " T)";
  return std::nullopt;
}

}  // namespace delayspec
