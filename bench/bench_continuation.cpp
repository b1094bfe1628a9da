// Continuation speed (issue 15): a 200-point branch of the impact orbit at N = 400, nev = 6.
//
//  BM_ImpactBranch   the paper's system at tau = T, k = 0.5, continued in the gap e from 1.3 in
//                    steps of 5e-4 (continue_step = continue_step_max), 200 points: across the
//                    grazing point (e = 1.26063) and the Neimark-Sacker point (e = 1.2545), both
//                    located. Counters: ms per point, and the share of Newton (corrector: one
//                    periodic residual with its sparse Jacobian, two residuals for F_p, one
//                    linear solve of the bordered n + 1 = 801 system per iteration) and of Krylov
//                    (the nev leading multipliers at every point and location step). Second
//                    argument: the corrector's solver, 0 = lu (a UMFPACK factorisation per
//                    iteration), 1 = krylov (GMRES on the system condensed onto the history,
//                    issue 36): the same branch (test_condensed_bordered.cpp), side by side.
// Requirement of the issue: < 10 s for the branch on 2 cores (the continuation uses one).
// The fractional-delay branch where the LU fills in: scripts/continuation_solver_cost.py.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "delayspec/continuation.hpp"
#include "delayspec/model_impact.hpp"

namespace {

using namespace delayspec;

void BM_ImpactBranch(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const ContinuationSolver solver = state.range(1) == 0 ? ContinuationSolver::lu : ContinuationSolver::krylov;
  state.SetLabel(to_string(solver));
  const ImpactParameters base{.k = 0.5};
  const double w = base.omega, T = 2 * std::numbers::pi / w, h = T / N;
  // the start: the free forced oscillator's orbit (no contact at e = 1.3), exact up to O(h^2)
  const double A = base.a * w * w / std::hypot(1 - w * w, 2 * base.zeta * w);
  const double phi = std::atan2(2 * base.zeta * w, 1 - w * w);
  Eigen::VectorXd guess(2 * N);
  for (int l = 0; l < N; ++l) {
    guess[2 * l] = A * std::sin(w * l * h - phi);
    guess[2 * l + 1] = A * w * std::cos(w * l * h - phi);
  }
  ContinuationOptions o;
  o.from = 1.3;
  o.to = 1.1;
  o.step = o.step_max = 5e-4;
  o.max_points = 200;
  o.N = N;
  o.floquet.nev = 6;
  o.solver = solver;
  auto model_at = [&](double e) {
    ImpactParameters p = base;
    p.e = e;
    return ImpactModel(p);
  };
  ContinuationResult r;
  for (auto _ : state) {
    r = continue_orbit<ImpactModel>(model_at, guess, o);
    benchmark::DoNotOptimize(r.points.data());
  }
  const double points = static_cast<double>(r.points.size());
  state.counters["points"] = points;
  state.counters["bifurcations"] = static_cast<double>(r.bifurcations.size());
  state.counters["ms_per_point"] = 1e3 * r.seconds / points;
  state.counters["newton_share"] = r.newton_seconds / r.seconds;
  state.counters["krylov_share"] = r.krylov_seconds / r.seconds;
  state.counters["newton_iterations"] = static_cast<double>(r.newton_iterations);
  state.counters["krylov_solves"] = static_cast<double>(r.krylov_solves);
  state.counters["factorisations"] = static_cast<double>(r.factorisations);
  state.counters["gmres_products"] = static_cast<double>(r.gmres_products);
}
BENCHMARK(BM_ImpactBranch)->Args({400, 0})->Args({400, 1})->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
