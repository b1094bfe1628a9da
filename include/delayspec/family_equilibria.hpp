#pragma once
// The equilibrium analyses of a problem family (problem_family.hpp), what `continue` and
// `boundary` with continue_object / boundary_object = equilibrium run (issue 57 item 3): the
// equilibria along one parameter (continue_equilibrium's EquilibriumFamily), over two
// (hopf_curves' and fold_curves' EquilibriumFamily2), and the branches of orbits born at the Hopf
// points of an equilibrium branch, each at several N with its bifurcations extrapolated.
#include <memory>
#include <vector>

#include "delayspec/continuation.hpp"
#include "delayspec/equilibrium_boundary.hpp"
#include "delayspec/equilibrium_branch.hpp"
#include "delayspec/problem_family.hpp"

namespace delayspec {

// The equilibria of the family `at` along its parameter, with `options` (nroots set per call).
// A normal form asks for some 700 Jacobians at one parameter value: the model is made once for
// them (the last value's kept). Serves one thread.
EquilibriumFamily equilibria_along(AnalysesAt at, const EquilibriumOptions& options);

// The equilibria over parameters x and y of `family` (the other parameters at `values`), the
// model made once per (x, y) (Newton asks for the same pair several times in a row) at the
// resolution of `map` (the starting roots' N). A pair the model refuses throws BadInput with the
// model's reason (the curves end there). Serves one thread.
EquilibriumFamily2 equilibria_over(std::shared_ptr<const ProblemFamily> family, std::vector<double> values, int x,
                                   int y, const MapSettings& map, const EquilibriumOptions& options);

// The branch of orbits born at one Hopf point, at every N, and its bifurcations extrapolated
// (extrapolate_bifurcations over the levels).
struct HopfOrbitBranch {
  const EquilibriumBifurcation* hopf = nullptr;  // into the equilibrium branch given
  std::vector<ContinuationResult> levels;        // by N; the reported branch is the last
  std::vector<BifurcationEstimate> estimates;
  const ContinuationResult& finest() const { return levels.back(); }
};

// The orbit branch of every Hopf point of `equilibria` (continue_from_hopf through `at`) at each
// of Ns (increasing), with options (N set per level; on_point called as the branches go).
std::vector<HopfOrbitBranch> orbits_from_hopf_points(const EquilibriumBranch& equilibria, const AnalysesAt& at,
                                                     const std::vector<int>& Ns, const ContinuationOptions& options);

}  // namespace delayspec
