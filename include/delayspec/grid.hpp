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
// and at its end (1 - theta) u_{m-1} + theta u_m (the terms with theta = 0 are absent).
#include <string>

namespace delayspec {

struct HistoryGrid {
  int N = 0;             // requested steps per delay
  double tau = 0;        // delay
  double period = 0;     // forcing period T
  int periods_per_map = 1;
  double h = 0;          // step
  int steps_per_period = 0;  // K_1 = T / h
  int K = 0;             // steps per stroboscopic map = periods_per_map * steps_per_period
  int m = 0;             // delayed slot index (see above)
  double theta = 0;      // fractional part of tau / h; 0 when aligned
  int M = 0;             // last history slot: the history has M + 1 blocks

  bool aligned() const { return theta == 0; }
  // Dimension of the history vector for state dimension d.
  long dimension(int d) const { return static_cast<long>(d) * (M + 1); }
  std::string describe() const;
};

// Builds the grid; throws BadInput naming N, tau, period or orbit_period when they are invalid
// (N < 1, non-positive or non-finite times, a rational ratio with incompatible N, a delay
// shorter than one step).
HistoryGrid make_grid(double tau, double period, int N, int periods_per_map = 1);

}  // namespace delayspec
