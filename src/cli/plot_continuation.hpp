#pragma once
// The figures of a `delayspec continue` result directory (command_plot.cpp calls it when DIR has
// branch.csv):
//   branch      max over the orbit of one state component (the key plot_component: `component`,
//               a state name or 1-based index; empty: the files' plot_component, else the first),
//               named as the model names it (the files' `# state_names`), against the continued
//               parameter, stable solid, unstable dashed, the bifurcations of continue.json marked
//               and named
//   branch_mu1  |mu_1| against the parameter with the unit line and the bifurcations
// Inputs read strictly (plot_inputs.hpp): bad files are BadInput naming the file and field.
#include <filesystem>
#include <string>

#include "cli/gnuplot_script.hpp"

namespace delayspec::cli {

void plot_continuation(FigureRenderer& renderer, const std::filesystem::path& dir, const std::string& component);

// The figures of `continue` with continue_object = equilibrium (DIR has equilibria.csv):
//   equilibria            the state component `component` (as for branch) against the parameter, stable solid,
//                         unstable dashed, the folds and Hopf points of
//                         equilibrium_bifurcations.csv marked and named
//   equilibria_re_lambda  Re lambda_1, the rightmost root, with the zero line and the same marks
//   hopf_branch_K, hopf_branch_K_mu1  with continue_switch, the orbits born at the K-th Hopf point
//                         (hopf_branch_K.csv), as `branch` and `branch_mu1`
void plot_equilibria(FigureRenderer& renderer, const std::filesystem::path& dir, const std::string& component);

}  // namespace delayspec::cli
