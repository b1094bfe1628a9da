#pragma once
// HistoryGrid: how a delay tau and a period T are laid on a uniform time grid.
//
// The state is the history U = (u_M, ..., u_1, u_0), u_i = y(t - i h), oldest block first,
// dimension d (M + 1). One stroboscopic map is K = p T / h steps (p = periods per map).
//
//  * Aligned delay (tau = N h exactly): M = N, theta = 0. Chosen when tau / T is a ratio
//    p/q with q <= 64 and N is compatible (N q / p steps per period is an integer),
//    h = tau / N.
//  * Fractional delay (any other ratio, design.md 1.4): h = T / K_1 with K_1 = round(N T / tau)
//    steps per period, tau = (m + theta) h with m = floor(tau / h) >= 1, theta in (0, 1);
//    the history has M = m + 1 slots beyond u_0, and the delayed value at the start of a
//    step is the linear interpolant (1 - theta) u_m + theta u_{m+1}.
//
// In both cases the delayed value at the start of a step is (1 - theta) u_m + theta u_{m+1}
// and at its end (1 - theta) u_{m-1} + theta u_m (the terms with theta = 0 are absent):
// HistoryGrid::delay_tap, the one statement of this rule.
//
//  * Aligned with breakpoints (design.md 1.4c; issue 58): where the field switches at known times
//    (GridBreaks: milling's tooth entries and exits) and the one delay is aligned, tau / T = p / q,
//    the nodes are put on every switch. The pattern P = T / q = tau / p repeats (so that t - tau
//    of a node is a node); the breakpoints taken mod P cut it into pieces, each uniform with
//    n_i steps, sum n_i = N / p (so N keeps its meaning, steps per delay, and M = N). A piece's
//    steps are L_i / n_i long; h is the mean, T / K_1. The n_i are nested: n_i(2 n) = 2 n_i(n)
//    whenever n / 2 >= kMinPatternSteps (the largest-remainder allocation is made once, at the
//    odd part or at the first n of the halving chain below kMinPatternSteps), so that doubling N
//    halves every step and the error keeps the even expansion h^2, h^4, ... that Richardson needs.
#include <array>
#include <string>
#include <vector>

namespace delayspec {

// The field's switch times the grid puts nodes on (HistoryGrid, "aligned with breakpoints").
struct GridBreaks {
  std::vector<double> times;     // switch times in [0, T), any order (time_switches_in_period)
  std::vector<int> piece_steps;  // empty: allocated from N (nested); else each piece's steps, as given
                                 // (a continuation keeps its start's allocation: the map smooth in p)
  // An orbit's contacts (contact_aligned_orbit.hpp): the intervals [entry, exit) of the map's time
  // [0, periods_per_map T) spent in region 1 (an exit before its entry wraps over the map's end).
  // Non-empty: each step of the map is in one region throughout, region 1 where its midpoint lies
  // in an interval, else 2 (HistoryGrid::step_region); their ends must be among `times`.
  std::vector<std::array<double, 2>> region1;
};

// What step l of a map reads from the history (HistoryGrid::delay_tap).
template <class V>
struct DelayTap {
  V w0;      // y(t - tau): the delayed state at the step's start
  V w1;      // y(t + h - tau): the delayed state at the step's end
  double t;  // the step's start time within the forcing period, (l mod K_1) h
  double h;  // the step's length: h, or its piece's step on a grid with breakpoints
};

struct HistoryGrid {
  int N = 0;          // requested steps per delay
  double tau = 0;     // delay
  double period = 0;  // forcing period T
  int periods_per_map = 1;
  double h = 0;              // step
  int steps_per_period = 0;  // K_1 = T / h
  int K = 0;                 // steps per stroboscopic map = periods_per_map * steps_per_period
  int m = 0;                 // delayed slot index (see above)
  double theta = 0;          // fractional part of tau / h; 0 when aligned
  int M = 0;                 // last history slot: the history has M + 1 blocks

  // Aligned with breakpoints (header): the pieces' start times in [0, P), P = the pattern, and
  // their steps; `nodes` the K_1 + 1 node times of one period, 0 .. T. All empty: uniform.
  std::vector<double> breakpoints;
  std::vector<int> piece_steps;
  std::vector<double> nodes;
  double pattern = 0;  // P (0: uniform)
  std::vector<signed char> step_regions;  // per step of a map (K): the fixed region; empty: each node's own

  // The region step l is taken in throughout (GridBreaks::region1), or 0: the state's (automatic).
  int step_region(long l) const { return step_regions.empty() ? 0 : step_regions[static_cast<size_t>(l % K)]; }

  bool aligned() const { return theta == 0; }
  bool has_breakpoints() const { return !nodes.empty(); }

  // The slot of the working history holding u_m for step l: b(delayed_slot(l)) = y(t - tau)
  // when aligned (numbering of delay_tap). The block kernels (block_kernel.hpp) take it as d0.
  long delayed_slot(long l) const { return M + l - m; }

  // The delay tap of step l (l >= 0, counted from the start of a map or of a run). `b(i)` is
  // slot i of the working history: b(0..M) = u_M .. u_0 at the start, b(M + l) = the state at
  // the start of step l (any callable returning a state or an Eigen expression of one). With
  // j = M + l - m:
  //   w0 = (1 - theta) b(j) + theta b(j - 1),  w1 = (1 - theta) b(j + 1) + theta b(j)
  // (aligned, theta = 0: w0 = b(j), w1 = b(j + 1), no arithmetic). Inline and allocation-free:
  // it sits in every stepper loop. block_kernel.hpp's step_block applies the same formula to k
  // vectors at once.
  template <class V, class Slot>
  DelayTap<V> delay_tap(long l, const Slot& b) const {
    const long j = delayed_slot(l);
    const StepSpan at = step_span(l);
    if (theta == 0) return {V(b(j)), V(b(j + 1)), at.t, at.h};
    const double c0 = 1 - theta;
    return {V(c0 * b(j) + theta * b(j - 1)), V(c0 * b(j + 1) + theta * b(j)), at.t, at.h};
  }
  // Where step l lies in the period: its start and length (one place of l in the period, one
  // test of the layout: the steppers' loops ask it once per step, through the tap).
  struct StepSpan {
    double t, h;
  };
  StepSpan step_span(long l) const {
    const long j = l < steps_per_period ? l : l % steps_per_period;
    if (nodes.empty()) return {static_cast<double>(j) * h, h};
    const size_t i = static_cast<size_t>(j);
    return {nodes[i], nodes[i + 1] - nodes[i]};
  }
  // The start of step l within the forcing period, (l mod K_1) h (or its node, with breakpoints).
  // l mod K_1 without a division where l < K_1 (every step of a one-period map): a 64-bit idiv
  // sat at the head of the step's dependency chain (t -> forcing -> S -> ...)
  double time_in_period(long l) const { return step_span(l).t; }
  // The length of step l: h, or its piece's step with breakpoints.
  double step_size(long l) const { return step_span(l).h; }
  // The start of step l from the start of the run (l >= 0): l h, or (l div K_1) T + its node.
  double node_time(long l) const {
    if (nodes.empty()) return static_cast<double>(l) * h;
    return static_cast<double>(l / steps_per_period) * period + nodes[static_cast<size_t>(l % steps_per_period)];
  }

  // Several delays (model.hpp): `delays` holds each delay's position, tau_i = (m_i + theta_i) h,
  // in the model's order; the longest is the grid's own tau, m, theta. Empty for one delay.
  struct DelayPosition {
    double tau = 0;
    int m = 0;
    double theta = 0;
  };
  std::vector<DelayPosition> delays;

  // The taps of a state of dimension D: delay_tap for a model with one delay (W = Vec<D>);
  // with several, W = Vec<D n> stacks each delay's delay_tap, delay i in rows i D .. i D + D - 1,
  // by the same formula with its own m_i and theta_i.
  template <int D, class W, class Slot>
  DelayTap<W> delay_taps(long l, const Slot& b) const {
    if constexpr (W::RowsAtCompileTime == D) {
      return delay_tap<W>(l, b);
    } else {
      DelayTap<W> tap;
      const StepSpan at = step_span(l);
      tap.t = at.t;
      tap.h = at.h;
      constexpr int kDelays = W::RowsAtCompileTime / D;  // == delays.size()
      for (int i = 0; i < kDelays; ++i) {
        const long j = M + l - delays[static_cast<size_t>(i)].m;
        const double th = delays[static_cast<size_t>(i)].theta, c0 = 1 - th;
        const long row = static_cast<long>(i) * D;
        if (th == 0) {
          tap.w0.template segment<D>(row) = b(j);
          tap.w1.template segment<D>(row) = b(j + 1);
        } else {
          tap.w0.template segment<D>(row) = c0 * b(j) + th * b(j - 1);
          tap.w1.template segment<D>(row) = c0 * b(j + 1) + th * b(j);
        }
      }
      return tap;
    }
  }

  // The values of the delays: {tau} for one, else each of `delays`.
  std::vector<double> delay_values() const;

  // Dimension of the history vector for state dimension d.
  long dimension(int d) const { return static_cast<long>(d) * (M + 1); }
  std::string describe() const;
};

// Steps a pattern keeps at least before its allocation is halved (header): the allocation of the
// halving chain's base, from which finer n double it.
inline constexpr int kMinPatternSteps = 8;

// Builds the grid; throws BadInput naming N, tau, period or orbit_period when they are invalid
// (N < 1, non-positive or non-finite times, a rational ratio with incompatible N, a delay
// shorter than one step). With breaks (non-empty times) and an aligned delay the nodes are put on
// them (header); BadInput naming N when N / p is below the number of pieces (each needs a step),
// or a given allocation does not sum to N / p or has a piece without a step. A fractional delay
// ignores the breaks (uniform).
HistoryGrid make_grid(double tau, double period, int N, int periods_per_map = 1, const GridBreaks& breaks = {});

// Several delays (taus in the model's order; one entry is make_grid above): N steps per the
// longest, laid as make_grid lays it, each other delay at its (m_i, theta_i). Throws BadInput
// naming the delay when it is not positive and finite or shorter than one step: by names[i] when
// given (one per delay, e.g. "`equations.delays.tau1`"), else by its place ("delay 2 of 3").
// Breaks are used with one delay only (another delay would fall between the nodes of the pieces).
HistoryGrid make_grid(const std::vector<double>& taus, double period, int N, int periods_per_map = 1,
                      const std::vector<std::string>& names = {}, const GridBreaks& breaks = {});

// The same problem's grid at another N (the same delays, period, map length and breakpoints; the
// allocation made afresh for N, nested with g's where N / g.N is a power of two): the levels of a
// resolution study or of nested shooting.
HistoryGrid regrid(const HistoryGrid& g, int N);

// A grid of exactly `steps_per_period` steps per period (h = period / steps_per_period), every
// delay placed where it falls, (m_i, theta_i) = tau_i / h as above (aligned only where tau_i / h
// is whole). For a problem whose delays move against the period while the discretisation must
// keep its size: an autonomous orbit's unknown period (autonomous_orbit.hpp). N = m of the
// longest delay. BadInput for a delay not positive, or shorter than one step.
HistoryGrid make_grid_with_steps(const std::vector<double>& taus, double period, int steps_per_period,
                                 int periods_per_map = 1);

}  // namespace delayspec
