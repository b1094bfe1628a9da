#pragma once
// The Illinois variant of regula falsi (Dowell & Jarratt, BIT 11, 1971), the one home of its rule
// for the locators that close a bracket on a sign change: the bifurcations on a branch segment
// (bifurcation_locator.hpp), Re lambda = 0 on an equilibrium branch (equilibrium_branch.cpp),
// and a sign change between two points of a boundary curve (boundary.cpp). Internal: not an
// interface.
//
// The bracket's ends a and b carry working values g_a, g_b of opposite signs, and the next trial
// is the secant root
//
//     s = (s_a g_b - s_b g_a) / (g_b - g_a).
//
// A trial's value replaces the end of its sign. When the same end is replaced twice in a row,
// the other end's working value is halved. Plain regula falsi keeps one end for ever where g is
// convex and converges only linearly; the halving moves the secant root across the root, and
// the order becomes 1.44 (3^(1/3)).
//
// Only the working values live here: each locator keeps its ends' positions and samples itself,
// and asks which end a value replaced.
namespace delayspec::detail {

struct IllinoisValues {
  double a = 0, b = 0;  // the working values at the ends a and b (opposite signs), possibly halved
  int last = 0;         // the end replaced last: -1 a, +1 b, 0 neither yet

  // The secant root between the ends' positions s_a and s_b.
  double root(double s_a, double s_b) const { return (s_a * b - s_b * a) / (b - a); }

  // The value g (nonzero) of a trial replaces the end of its sign; returns that end (-1 a, +1 b).
  int replace(double g) {
    if ((g > 0) == (a > 0)) {
      a = g;
      if (last == -1) b /= 2;
      last = -1;
    } else {
      b = g;
      if (last == 1) a /= 2;
      last = 1;
    }
    return last;
  }
};

}  // namespace delayspec::detail
