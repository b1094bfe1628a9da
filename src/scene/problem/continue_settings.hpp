#pragma once
// The keys of `delayspec continue` (issue 15): which model key is continued over which range,
// the step control, the location tolerance and the levels N for the error bars.
#include <string>
#include <vector>

#include "scene/keys/config.hpp"
#include "delayspec/continuation.hpp"
#include "delayspec/model_analyses.hpp"

namespace delayspec::cli {

struct ContinueSettings {
  std::string key;                      // continue_key: a numeric model key
  ContinuationOptions options;          // from, to, step, step_min, step_max, max_points, tolerance
  std::vector<int> Ns;                  // continue_Ns (increasing); empty: the one level N
  bool switch_period_doubling = false;  // continue_switch: the period-2 branch at each period doubling
};

// Reads continue_key, continue_from, continue_to (required), continue_step, continue_step_min,
// continue_step_max, continue_max_points, continue_tolerance, continue_Ns, continue_switch, continue_solver. BadInput naming the key:
// a missing required key, an empty range, a non-positive step or tolerance, step_min > step_max, Ns not increasing or out of range.
// The Floquet and discretisation options are the caller's (read_floquet_options, read_problem), and
// whether the key is a parameter of the model the problem's (starting_problem, family_parameter).
ContinueSettings read_continue_settings(Config& config);

}  // namespace delayspec::cli
