#pragma once
// boundary_diagram: the stability boundaries of a periodic orbit as curves in two parameters of a
// problem family (problem_family.hpp), each point with its distance to the N -> infinity curve
// (issue 36; issue 57 item 3 moved it here from the `boundary` command, so that a C++ user calls
// it as the command does; docs/continuation.md, "Stability boundaries as curves").
//
// The start: the branch of orbits continued in y over [y_from, y_to] at x = x_from (the finest N;
// or at the coarsest and moved to the finest, which costs half as much) locates the bifurcations
// there; the first of `type` (none: the first of any type but grazing) starts the curve. A
// grazing curve's test function is the orbit's max H (orbit_contacts: over the steps'
// interpolants), zero where the orbit touches the switching surface. With scan_points, the same
// search at scan_points values of x gives a start at each, and every start not on a curve already
// followed starts another (followed both ways from it): the lobes of a lobe diagram. A curve is
// followed at the finest N (trace_boundary_both_ways), the test function at each (x, y) evaluated
// on the orbit solved there (linear models: the zero orbit; nonlinear: at least one Newton step
// from the last orbit, the orbit search of `orbit` where that fails). Each point is then studied
// against the coarser levels' curves (boundary_point_study): its extrapolation and error estimate.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "delayspec/boundary.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/problem_family.hpp"
#include "delayspec/richardson.hpp"

namespace delayspec {

struct BoundaryDiagramOptions {
  int x = -1, y = -1;          // the family's parameters: x along the curves, y searched for starts
  std::vector<double> values;  // every parameter's value (the family's order); x's and y's are set
  MapSettings map;             // orbit_period and the step options (N: the levels below)
  BoundaryOptions curve;       // the ranges, steps and tolerances of the curves
  std::optional<BifurcationType> type;  // the curves' type; none: the first found of any but grazing
  std::vector<int> Ns;                  // increasing; the curves are followed at the last
  std::vector<int> finer_Ns;  // studied where Ns are pre-asymptotic (boundary_point_study's finer)
  int scan_points = 0;        // 0: one start, at x_from; else starts searched at this many x
  int threads = 1;            // the searches and the studies (the curves are the same for any count)
  OrbitSettings orbit;
  FloquetOptions floquet;
  RichardsonOptions richardson;  // the points' error expansion
  // Called before the studies with their number of points, and after each (from any thread).
  std::function<void(long points)> on_studies;
  std::function<void()> on_point_studied;
};

struct BoundaryDiagram {
  std::vector<BoundaryCurve> curves;
  std::vector<BifurcationType> types;                     // each curve's
  std::vector<std::vector<BoundaryPointStudy>> studies;  // each curve's points'
  bool stable_below = false;  // the orbit stable at y_from wherever the starts were searched
  long evaluations = 0;       // of the test function at the finest N (the tracing)
  long study_evaluations = 0;  // at the other levels (the error bars)
  // Wall time of each phase: the starts' search (continuation in y), the tracing, the studies
  double search_seconds = 0, trace_seconds = 0, study_seconds = 0;
  std::string failures;  // the curves that ended in a failure, named ("" when none)
};

// The curves of `options`. BadInput: a parameter index outside the family, no levels; a value
// the model refuses where a start is searched. NumericalFailure: no start at all (with what the
// searches found), or the only search failing.
BoundaryDiagram boundary_diagram(std::shared_ptr<const ProblemFamily> family, const BoundaryDiagramOptions& options);

}  // namespace delayspec
