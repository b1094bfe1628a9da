#pragma once
// The keys every `boundary` run reads, for orbits (command_boundary.cpp) and for equilibria
// (boundary_equilibria.cpp): the two parameters, their ranges, the tracer's steps and tolerances,
// and where curves start.
#include <string>

#include "delayspec/boundary.hpp"
#include "scene/keys/config.hpp"

namespace delayspec::cli {

struct BoundarySettings {
  std::string x_key, y_key;  // boundary_x, boundary_y
  BoundaryOptions options;
  int scan_points = 0;  // boundary_starts = scan: the x values searched; 0: the first start only
};

// BadInput naming the key: boundary_x or boundary_y missing or equal (whether each is a model
// parameter is the problem's: starting_problem, family_parameter);
// an empty range; a step <= 0 or step_min > step_max; a chord error or tolerance <= 0.
BoundarySettings read_boundary_settings(Config& config);

}  // namespace delayspec::cli
