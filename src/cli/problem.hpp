#pragma once
// Problem: what every command needs to know about the system being studied: the model (one of
// the built-in ones, as a variant), the grid, and the discretisation options. Read from a
// Config; every key it reads is documented in the CLI contract.
#include <string>
#include <variant>
#include <vector>

#include "config.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mackey_glass.hpp"
#include "delayspec/model_mathieu.hpp"
#include "delayspec/stepper.hpp"

namespace delayspec::cli {

using AnyModel = std::variant<ImpactModel, LinearModel, MathieuModel, MackeyGlassModel>;

struct Problem {
  std::string model_name;
  AnyModel model;
  int N = 100;
  int orbit_period = 1;
  std::string events = "on";           // on | linear | off
  std::string jacobian = "consistent"; // consistent | frozen
  int contact_substeps = StepOptions{}.contact_substeps;  // trapezoid sub-steps per contact piece
  HistoryGrid grid;
};

// The stepper options (events, jacobian, ...) the problem asks for.
StepOptions step_options(const Problem& problem);

// The built-in models, the default first (the values of the key `model`).
const std::vector<std::string>& model_names();

// Reads `model` and its parameters, N, orbit_period, events, jacobian, contact_substeps;
// builds the grid.
// default_N is used when the key N is absent.
Problem read_problem(Config& config, int default_N = 100);

}  // namespace delayspec::cli
