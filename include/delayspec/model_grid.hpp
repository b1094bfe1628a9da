#pragma once
// The grid of a model at N: make_grid with the model's delays and period, and, for a model that
// switches at known times (model.hpp, "Time switches"), those times as breakpoints when the layout
// is aligned (grid.hpp, "Aligned with breakpoints"). The one place a model's grid is laid.
#include <string>
#include <vector>

#include "delayspec/errors.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/model.hpp"
#include "delayspec/step_options.hpp"

namespace delayspec {

// More switches than this in one period is taken for a model that does not advance.
inline constexpr int kMaxTimeSwitchesPerPeriod = 100000;

// The model's time switches in [0, T) (its next_time_switch from 0 on); empty for a model
// without time switches. NumericalFailure when the model reports a switch that is not later than
// the last, or more than kMaxTimeSwitchesPerPeriod.
template <class Model>
std::vector<double> time_switches_in_period(const Model& model) {
  std::vector<double> times;
  if constexpr (TimeSwitchedModel<Model>) {
    const double T = model.period();
    for (double from = 0;;) {
      const double s = model.next_time_switch(from, T);
      if (!(s < T)) break;
      if (!(s > from) || times.size() >= static_cast<size_t>(kMaxTimeSwitchesPerPeriod))
        throw NumericalFailure("the model's time switches: after t = " + format_number(from) + " the next at " +
                               format_number(s) + " (not later, or more than " +
                               std::to_string(kMaxTimeSwitchesPerPeriod) + " in a period)");
      times.push_back(s);
      from = s;
    }
  }
  return times;
}

// The breakpoints of the model's grid for a layout (empty: uniform).
template <class Model>
GridBreaks grid_breaks(const Model& model, GridLayout layout, std::vector<int> piece_steps = {}) {
  if (layout != GridLayout::aligned) return {};
  GridBreaks breaks;
  breaks.times = time_switches_in_period(model);
  breaks.piece_steps = std::move(piece_steps);
  return breaks;
}

// The model's grid at N steps per the longest delay, periods_per_map periods a map.
template <class Model>
HistoryGrid model_grid(const Model& model, int N, int periods_per_map, GridLayout layout) {
  return make_grid(delays_of(model), model.period(), N, periods_per_map, {}, grid_breaks(model, layout));
}

}  // namespace delayspec
