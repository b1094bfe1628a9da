#pragma once
// Simulation over a time window: the trajectory of the discretised DDE (the same steps as the
// stroboscopic map), its Poincare points (t = m T) and its impacts (entries into region 1,
// H > 0), optionally switching the stepper at a given time (e.g. control switched on, as in
// the paper's Fig. 6.3).
//
// Impacts: with events on/linear, the events located inside each step (grazing contacts that
// begin and end inside one step included); with events off, only entries seen at grid points
// (region of u_0 changes from 2 to 1 between two steps): what a plain trapezoid integrator
// sees.
//
// History storage: a ring buffer of M + 3 blocks (no growth with the time window), so memory
// is O(N) plus what is recorded.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "delayspec/cancellation.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/model.hpp"
#include "delayspec/stepper.hpp"

namespace delayspec {

struct SimulationOptions {
  double t_end = 0;               // simulate [0, t_end]: ceil(t_end / h) steps
  double t_start = 0;             // record (trajectory, Poincare points, impacts) only for t >= t_start
  long sample_every = 1;          // keep every sample_every-th grid point of the trajectory
  double switch_time = INFINITY;  // steps starting at t >= switch_time use the second stepper
};

template <int D>
struct SimulationRecord {
  std::vector<double> t;  // sampled trajectory
  std::vector<Vec<D>> y;
  std::vector<double> poincare_t;  // t = m T (grid points that are whole periods)
  std::vector<Vec<D>> poincare_y;
  std::vector<double> impact_times;  // entries into region 1
  long steps = 0;
  double max_H = -INFINITY;  // largest H at grid points in the window
};

// Steps from t = 0 to the first node at or after t_end (less 1e-9 h of rounding): ceil(t_end / h)
// on a uniform grid (as a double: the caller bounds it before converting).
inline double steps_to_reach(const HistoryGrid& grid, double t_end) {
  if (!grid.has_breakpoints()) return std::ceil(t_end / grid.h - 1e-9);
  const double periods = std::floor(t_end / grid.period);
  const double rest = t_end - periods * grid.period;
  const auto first = std::lower_bound(grid.nodes.begin(), grid.nodes.end(), rest - 1e-9 * grid.h);
  return periods * grid.steps_per_period + static_cast<double>(first - grid.nodes.begin());
}

// Simulates from history U0 (oldest block first, as StroboscopicMap). `before` runs the steps
// starting before options.switch_time, `after` the others. BadInput for a non-positive or
// non-finite t_end, t_start outside [0, t_end], sample_every < 1, or a wrong history size.
template <class Model>
SimulationRecord<Model::d> simulate(const TrapezoidStepper<Model>& before, const TrapezoidStepper<Model>& after,
                                    const HistoryGrid& grid, const Eigen::VectorXd& U0,
                                    const SimulationOptions& options) {
  constexpr int D = Model::d;
  using V = Vec<D>;
  if (!(options.t_end > 0) || !std::isfinite(options.t_end))
    throw BadInput("`t_end = " + format_number(options.t_end) + "`: must be > 0 and finite");
  if (!(options.t_start >= 0 && options.t_start <= options.t_end))
    throw BadInput("`t_start = " + format_number(options.t_start) + "`: must be in [0, t_end]");
  if (options.sample_every < 1)
    throw BadInput("`sample_every = " + std::to_string(options.sample_every) + "`: must be >= 1");
  if (U0.size() != grid.dimension(D))
    throw BadInput("simulate: history has " + std::to_string(U0.size()) + " entries, expected " +
                   std::to_string(grid.dimension(D)));
  const double steps_real = steps_to_reach(grid, options.t_end);
  if (steps_real > 1e10) throw BadInput("`t_end = " + format_number(options.t_end) + "`: more than 1e10 steps");
  const long steps = static_cast<long>(steps_real);
  // The trajectory is kept in memory (time and state per sample): bound it before allocating.
  const double samples = (options.t_end - options.t_start) / grid.h / static_cast<double>(options.sample_every);
  if (samples > 1e8)
    throw BadInput("`t_end = " + format_number(options.t_end) + "`, `t_start = " + format_number(options.t_start) +
                   "`, `sample_every = " + std::to_string(options.sample_every) +
                   "`: more than 1e8 trajectory samples; raise sample_every or shorten the window");
  const long M = grid.M, ring = M + 3;
  std::vector<V> b(static_cast<size_t>(ring));
  auto slot = [&](long i) -> V& { return b[static_cast<size_t>(i % ring)]; };  // linear index -> ring
  for (long j = 0; j <= M; ++j) slot(j) = U0.template segment<D>(j * D);       // u_M .. u_0 at t = 0
  SimulationRecord<D> rec;
  rec.steps = steps;
  auto record_point = [&](long l, const V& y) {
    const double t = grid.node_time(l);
    if (t < options.t_start) return;
    if (l % options.sample_every == 0) {
      rec.t.push_back(t);
      rec.y.push_back(y);
    }
    if (l % grid.steps_per_period == 0) {
      rec.poincare_t.push_back(t);
      rec.poincare_y.push_back(y);
    }
    if constexpr (Model::has_switching) rec.max_H = std::max(rec.max_H, before.model().H(y));
  };
  record_point(0, slot(M));
  StepMap<D, delayed_rows<Model>> scratch;
  StepEvents events;
  for (long l = 0; l < steps; ++l) {
    // Between periods a front end may stop the run (cancellation.hpp).
    if (l % grid.steps_per_period == 0) throw_if_cancelled();
    const DelayTap<DelayedVec<Model>> tap = grid.template delay_taps<D, DelayedVec<Model>>(l, slot);  // tap.t: the time in the period, as StroboscopicMap
    const double t_abs = grid.node_time(l), h = tap.h;
    const TrapezoidStepper<Model>& stepper = t_abs >= options.switch_time ? after : before;
    const V u = slot(M + l);
    const V next = stepper.step(tap.t, h, u, tap.w0, tap.w1, scratch, &events);
    if (!next.allFinite()) throw NumericalFailure("simulate: the trajectory diverged at t = " + format_number(t_abs));
    slot(M + l + 1) = next;
    if constexpr (Model::has_switching) {
      if (stepper.options().events != EventMode::off) {
        for (int e = 0; e < events.count; ++e)
          if (events.new_region[e] == 1 && t_abs + events.offset[e] >= options.t_start)
            rec.impact_times.push_back(t_abs + events.offset[e]);
      } else if (region_of(stepper.model(), u) == 2 && region_of(stepper.model(), next) == 1 &&
                 t_abs + h >= options.t_start) {
        rec.impact_times.push_back(t_abs + h);
      }
    }
    record_point(l + 1, next);
  }
  return rec;
}

}  // namespace delayspec
