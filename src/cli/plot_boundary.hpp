#pragma once
// The figure of a `delayspec boundary` result directory (command_plot.cpp calls it when DIR has
// boundary.csv): `boundary`, the curve in (boundary_x, boundary_y) at the finest N, the points
// extrapolated to N -> infinity with their error bars where they have one, and the codim-2
// points of boundary.json marked and named. Inputs read strictly (plot_inputs.hpp).
#include <filesystem>

#include "cli/gnuplot_script.hpp"

namespace delayspec::cli {

void plot_boundary(FigureRenderer& renderer, const std::filesystem::path& dir);
// boundary_object = equilibrium: the Hopf curves from boundary.json, drawn by criticality, the
// generalised Hopf points marked.
void plot_hopf_curves(FigureRenderer& renderer, const std::filesystem::path& dir);

}  // namespace delayspec::cli
