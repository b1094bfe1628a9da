#pragma once
// ModelAnalyses: what the front ends (the CLI and the Python module) ask of a model, behind one
// interface whatever the model and its state dimension d: its periodic orbit linearised (the
// monodromy as a LinearOperator, for floquet, chart, converge and bench), Lyapunov exponents
// (lyapunov, sweep), the stroboscopic sequence (basin) and a simulation (simulate).
//
// ModelAnalysesFor<Model> implements it from the templates of the engine, compiled for Model's
// d. It is instantiated once per built-in model (builtin_analyses.hpp) and, for a
// model written as equations in a scene, inside the object compiled from those equations at run
// time (docs/models.md): the per-step work is always compiled for the model, never interpreted,
// and one virtual call per analysis is all the front ends add.
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/autonomous_orbit.hpp"
#include "delayspec/autonomous_shooting.hpp"
#include "delayspec/contact_aligned_orbit.hpp"
#include "delayspec/continuation.hpp"
#include "delayspec/equilibrium.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/linear_operator.hpp"
#include "delayspec/lyapunov.hpp"
#include "delayspec/model.hpp"
#include "delayspec/model_grid.hpp"
#include "delayspec/monodromy.hpp"
#include "delayspec/orbit_search.hpp"
#include "delayspec/simulation.hpp"
#include "delayspec/spectral_reference.hpp"
#include "delayspec/step_options.hpp"
#include "delayspec/stepper.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {

// The discretisation: N steps per delay, the map over orbit_period forcing periods, the step.
struct MapSettings {
  int N = 100;
  int orbit_period = 1;
  StepOptions step;
};

// What linearised_orbit() does beyond the orbit settings.
struct OrbitRequest {
  // When set: Newton (orbit_by_newton) from this periodic sequence (another resolution's orbit,
  // any K: prolonged) instead of the configured method. Nonlinear models only.
  const Eigen::VectorXd* newton_guess = nullptr;
  // Fill LinearisedOrbit::sequence with the orbit's states u_0 .. u_{K-1} (nonlinear models).
  bool sequence = false;
  // A model switching in its state, on an aligned grid (the default): the orbit and its monodromy
  // on the grid aligned with the orbit's contacts (contact_aligned_orbit.hpp). false: on the
  // uniform grid with the contacts located inside steps, as a branch of orbits is continued
  // (continuation's grid cannot follow contacts that move with the parameter), so that a test
  // function evaluated at one point agrees with the branch through it (boundary).
  bool align_contacts = true;
};

// A periodic orbit and the map's linearisation along it.
struct LinearisedOrbit {
  PeriodicOrbit orbit;
  ContactSummary contacts;                    // the orbit against H = 0 (no switching: zero)
  std::unique_ptr<LinearOperator> monodromy;  // Monodromy<d> of one map at the orbit
  Eigen::VectorXd sequence;                   // u_0 .. u_{K-1} when requested (empty for linear models)
  HistoryGrid grid;                           // the grid of the orbit and its monodromy
  // A switching model on an aligned grid (contact_aligned_orbit.hpp): the contacts the grid is
  // aligned with, each alternation's largest move, or why it stayed uniform ("" when not tried).
  std::vector<std::array<double, 2>> contact_times;
  std::vector<double> contact_moves;
  std::string alignment_note;
};

// A periodic orbit of unknown period (autonomous_orbit.hpp) and its monodromy over one period.
struct AutonomousLinearisedOrbit {
  AutonomousOrbit orbit;
  std::unique_ptr<LinearOperator> monodromy;
};

class ModelAnalyses;
struct EquilibriumBifurcation;  // equilibrium_branch.hpp
// The analyses of one model with one parameter set to p (continuation's family of models): for
// the built-in models the scene's keys with the continued one changed, for an equation model its
// compiled code with other constants. Must give analyses of the same model type as the caller.
using AnalysesAt = std::function<std::shared_ptr<const ModelAnalyses>(double p)>;

class ModelAnalyses {
 public:
  virtual ~ModelAnalyses() = default;

  virtual int state_dimension() const = 0;     // d
  virtual bool switches_in_state() const = 0;  // H(y) with events (has_switching)
  virtual bool switches_in_time() const = 0;   // cutting windows (has_time_switches)
  virtual bool is_linear() const = 0;          // the monodromy does not depend on the orbit
  virtual bool is_autonomous() const = 0;      // f does not depend on t (model.hpp): equilibria
  virtual double tau() const = 0;  // the longest delay
  // Every delay, in the model's order ({tau()} for one delay; model.hpp).
  virtual std::vector<double> delays() const = 0;
  virtual double period() const = 0;
  // The model's time switches in [0, T) (model_grid.hpp; empty: none).
  virtual std::vector<double> time_switches() const = 0;
  // Its multipliers by piecewise Chebyshev collocation (spectral_reference.hpp): a reference
  // independent of the step maps. BadInput for a model it does not take (not linear, several
  // delays, tau != T).
  virtual SpectralResult spectral_reference(const SpectralOptions& options) const = 0;
  // The grid of these settings (model_grid.hpp: the switches as breakpoints when aligned).
  HistoryGrid grid(const MapSettings& s) const {
    GridBreaks breaks;
    if (s.step.grid == GridLayout::aligned) breaks.times = time_switches();
    return make_grid(delays(), period(), s.N, s.orbit_period, {}, breaks);
  }

  // The periodic orbit (orbit_search.hpp; the zero orbit of a linear model) and its monodromy.
  virtual LinearisedOrbit linearised_orbit(const MapSettings& map, const OrbitSettings& orbit,
                                           const OrbitRequest& request = {}) const = 0;
  // An equilibrium from `guess` (d entries; empty: the model's constant initial history) and its
  // rightmost characteristic roots (equilibrium.hpp). BadInput for a model that is not
  // autonomous or a guess of another size.
  virtual EquilibriumResult equilibrium(const Eigen::VectorXd& guess, const EquilibriumOptions& options) const = 0;
  // f, A, the B_i and the delays on the constant history y (d entries): what an equilibrium's
  // Newton and its characteristic function need (equilibrium.hpp). BadInput as equilibrium().
  virtual ConstantHistory at_constant_history(const Eigen::VectorXd& y) const = 0;
  // [A B] (d x d (n + 1)) on the history with current state y and delayed states `delayed`
  // (d n): the Jacobian whose differences give a Hopf point's normal form (hopf_normal_form.hpp).
  // BadInput as equilibrium().
  virtual Eigen::MatrixXd jacobian_at(const Eigen::VectorXd& y, const Eigen::VectorXd& delayed) const = 0;
  // A periodic orbit of unknown period near the guess (autonomous_orbit.hpp) and its monodromy.
  // BadInput for a model that is not autonomous, or linear (no isolated orbits).
  virtual AutonomousLinearisedOrbit autonomous_orbit(const AutonomousOrbitOptions& options) const = 0;
  // Lyapunov exponents from the constant initial history.
  virtual LyapunovResult lyapunov(const MapSettings& map, const LyapunovOptions& options) const = 0;
  // The histories U_0 .. U_{count-1} of successive maps after `transient` maps, from the constant
  // initial history (the stroboscopic section of a trajectory).
  virtual std::vector<Eigen::VectorXd> section_sequence(const MapSettings& map, long transient, long count) const = 0;
  // simulate() from the constant initial history: `before` (a model of the same type, e.g. the
  // impact model with its control off; nullptr: this one) with the step settings of
  // `before_map` runs the steps starting before options.switch_time, this model with `map` the
  // others. Both settings must give the same grid.
  virtual SimulationRecord<Eigen::Dynamic> simulate(const MapSettings& before_map, const MapSettings& map,
                                                    const SimulationOptions& options,
                                                    const ModelAnalyses* before = nullptr) const = 0;
  // The branch of periodic orbits through this model's orbit (found as `orbit` says, on the
  // grid of options.N and options.periods_per_map), continued in p over the family `at`
  // (continuation.hpp: continue_orbit; this model is the one at options.from).
  virtual ContinuationResult continue_orbit(const AnalysesAt& at, const OrbitSettings& orbit,
                                            const ContinuationOptions& options) const = 0;
  // The period-2 branch born at the period doubling `at_pd` of such a branch
  // (continuation.hpp: continue_period_doubled).
  virtual ContinuationResult continue_period_doubled(const AnalysesAt& at, const Bifurcation& at_pd,
                                                     const ContinuationOptions& options) const = 0;
  // The branch of periodic orbits born at the Hopf point `hopf` of the family's equilibria
  // (hopf_branch.hpp: continue_from_hopf). BadInput for a model that is not autonomous, or linear.
  virtual ContinuationResult continue_from_hopf(const AnalysesAt& at, const EquilibriumBifurcation& hopf,
                                                const ContinuationOptions& options) const = 0;
  // The branch of periodic orbits of unknown period through this model's orbit found as `orbit`
  // says (autonomous_orbit.hpp; orbit.N must be options.N), continued in p over the family `at`
  // (hopf_branch.hpp: continue_autonomous_orbit). BadInput for a model that is not autonomous, or
  // linear; NumericalFailure when no orbit is found.
  virtual ContinuationResult continue_autonomous_orbit(const AnalysesAt& at, const AutonomousOrbitOptions& orbit,
                                                       const ContinuationOptions& options) const = 0;

 protected:
  ModelAnalyses() = default;
  ModelAnalyses(const ModelAnalyses&) = default;
  ModelAnalyses& operator=(const ModelAnalyses&) = default;
};

template <class Model>
class ModelAnalysesFor final : public ModelAnalyses {
 public:
  static constexpr int D = Model::d;
  static constexpr int DW = delayed_rows<Model>;  // D, or D n with n delays (model.hpp)
  explicit ModelAnalysesFor(Model model) : model_(std::move(model)) {}
  const Model& model() const { return model_; }

  int state_dimension() const override { return D; }
  bool switches_in_state() const override { return Model::has_switching; }
  bool switches_in_time() const override { return TimeSwitchedModel<Model>; }
  bool is_linear() const override { return Model::is_linear; }
  bool is_autonomous() const override { return AutonomousModel<Model>; }
  double tau() const override { return model_.tau(); }
  std::vector<double> delays() const override { return delays_of(model_); }
  double period() const override { return model_.period(); }
  std::vector<double> time_switches() const override { return time_switches_in_period(model_); }
  SpectralResult spectral_reference(const SpectralOptions& options) const override {
    if constexpr (delay_count_of<Model>() == 1) {
      return spectral_multipliers(model_, options);
    } else {
      throw BadInput("the spectral reference takes models with one delay; this one has " +
                     std::to_string(delay_count_of<Model>()));
    }
  }

  LinearisedOrbit linearised_orbit(const MapSettings& s, const OrbitSettings& settings,
                                   const OrbitRequest& request) const override {
    const StroboscopicMap<Model> map = make_map(s);
    LinearisedOrbit out;
    OrbitLinearisation<D, DW> at_orbit;  // step maps and states of one map at the orbit
    if (request.newton_guess && !Model::is_linear) {
      const Eigen::VectorXd guess = prolonged_guess(*request.newton_guess, map.grid());
      out.orbit = orbit_by_newton(map, guess, settings.newton);
      map.apply(out.orbit.history, &at_orbit.maps, &at_orbit.states);
    } else {
      out.orbit = find_orbit(model_, map, settings, &at_orbit);
    }
    // A model whose derivative is infinite on the orbit (x^(1/3) at 0) gives a monodromy that
    // no eigensolver can use: say at which step, once here (a pass over K small matrices).
    if (!all_finite(at_orbit)) map.throw_first_non_finite_step(out.orbit.history, 1, "the map at the periodic orbit");
    // A switching orbit on an aligned grid: the contact times as nodes (contact_aligned_orbit.hpp)
    if constexpr (Model::has_switching) {
      const StepOptions& step = s.step;
      if (request.align_contacts && step.grid == GridLayout::aligned && step.events != EventMode::off &&
          step.fixed_region == 0 && step.jacobian == JacobianMode::consistent && map.grid().aligned() &&
          map.grid().delays.empty()) {
        ContactAlignmentOptions o;
        o.shooting = settings.shooting;
        if (auto aligned = contact_aligned_orbit(map, at_orbit.states, o, out.alignment_note)) {
          const StroboscopicMap<Model> on_contacts(map.stepper(), aligned->grid);
          // the orbit as found (method, iterations) at the aligned grid's history; the
          // alignment's own solves are in contact_moves
          out.orbit.history = std::move(aligned->orbit.history);
          out.orbit.residual = aligned->orbit.residual;
          out.contact_times = std::move(aligned->contacts);
          out.contact_moves = std::move(aligned->moves);
          return finish(on_contacts, std::move(aligned->at_orbit), request, std::move(out));
        }
      }
    }
    return finish(map, std::move(at_orbit), request, std::move(out));
  }

  EquilibriumResult equilibrium(const Eigen::VectorXd& guess, const EquilibriumOptions& options) const override {
    if constexpr (AutonomousModel<Model>) {
      if (guess.size() == 0) return find_equilibrium(model_, model_.initial_state(), options);
      if (guess.size() != D)
        throw BadInput("the equilibrium guess has " + std::to_string(guess.size()) + " entries; the state has " +
                       std::to_string(D));
      return find_equilibrium(model_, Vec<D>(guess), options);
    } else {
      throw BadInput(kNotAutonomous);
    }
  }
  ConstantHistory at_constant_history(const Eigen::VectorXd& y) const override {
    if constexpr (AutonomousModel<Model>) {
      if (y.size() != D)
        throw BadInput("the state has " + std::to_string(D) + " entries, not " + std::to_string(y.size()));
      return constant_history(model_, Vec<D>(y));
    } else {
      throw BadInput(kNotAutonomous);
    }
  }
  Eigen::MatrixXd jacobian_at(const Eigen::VectorXd& y, const Eigen::VectorXd& delayed) const override {
    if constexpr (AutonomousModel<Model>) {
      constexpr int NT = delay_count_of<Model>();
      if (y.size() != D || delayed.size() != D * NT)
        throw BadInput("the Jacobian takes " + std::to_string(D) + " states and " + std::to_string(D * NT) +
                       " delayed values, not " + std::to_string(y.size()) + " and " + std::to_string(delayed.size()));
      const Vec<D> now(y);
      const Vec<D * NT> w(delayed);
      // entry by entry: Eigen's vectorised copy of a 1 x 1 block trips GCC 12's -Warray-bounds
      const auto A = model_.A(1, 0.0, now, w);
      const auto B = model_.B(1, 0.0, now, w);
      Eigen::MatrixXd J(D, D * (NT + 1));
      for (int c = 0; c < D * (NT + 1); ++c)
        for (int r = 0; r < D; ++r) J(r, c) = c < D ? A(r, c) : B(r, c - D);
      return J;
    } else {
      throw BadInput(kNotAutonomous);
    }
  }

  AutonomousLinearisedOrbit autonomous_orbit(const AutonomousOrbitOptions& options) const override {
    if constexpr (AutonomousModel<Model> && !Model::is_linear) {
      AutonomousLinearisedOrbit out;
      if (options.method == AutonomousOrbitMethod::shooting) {
        AutonomousShootingOptions shooting;
        shooting.shooting.tolerance = options.newton.tolerance;
        shooting.shooting.max_iterations = options.newton.max_iterations;
        out.orbit = find_autonomous_orbit_by_shooting(model_, options, shooting);
      } else {
        out.orbit = find_autonomous_orbit(model_, options);
      }
      out.monodromy = std::make_unique<Monodromy<D, DW>>(
          autonomous_orbit_map(model_, out.orbit, options.step).monodromy(out.orbit.history));
      return out;
    } else if constexpr (AutonomousModel<Model>) {
      throw BadInput("a linear model has no isolated periodic orbits: `period_guess` is for nonlinear autonomous models");
    } else {
      throw BadInput(kNotAutonomous);
    }
  }

  LyapunovResult lyapunov(const MapSettings& s, const LyapunovOptions& options) const override {
    const StroboscopicMap<Model> map = make_map(s);
    const Eigen::VectorXd U0 = map.constant_history(model_.initial_state());
    try {
      return lyapunov_exponents(map, U0, options);
    } catch (const NonFiniteResult& e) {  // the tangent block: find the step that made it (failures only)
      map.throw_first_non_finite_step(U0, options.transient + options.periods, e.what());
      throw;
    }
  }

  std::vector<Eigen::VectorXd> section_sequence(const MapSettings& s, long transient, long count) const override {
    const StroboscopicMap<Model> map = make_map(s);
    Eigen::VectorXd U = map.constant_history(model_.initial_state());
    for (long j = 0; j < transient; ++j) U = map.apply(U);
    std::vector<Eigen::VectorXd> section;
    section.reserve(static_cast<size_t>(count));
    for (long j = 0; j < count; ++j) {
      if (j > 0) U = map.apply(U);
      section.push_back(U);
    }
    return section;
  }

  SimulationRecord<Eigen::Dynamic> simulate(const MapSettings& before_map, const MapSettings& s,
                                            const SimulationOptions& options,
                                            const ModelAnalyses* before) const override {
    const auto* before_model = before ? dynamic_cast<const ModelAnalysesFor*>(before) : this;
    if (!before_model) throw std::logic_error("simulate: the model before the switch is of another type");
    const TrapezoidStepper<Model> first(before_model->model_, before_map.step), second(model_, s.step);
    const StroboscopicMap<Model> map = make_map(s);  // its grid and constant history
    SimulationRecord<D> rec = delayspec::simulate(first, second, map.grid(),
                                                  map.constant_history(model_.initial_state()), options);
    SimulationRecord<Eigen::Dynamic> out;
    out.t = std::move(rec.t);
    out.y.assign(rec.y.begin(), rec.y.end());
    out.poincare_t = std::move(rec.poincare_t);
    out.poincare_y.assign(rec.poincare_y.begin(), rec.poincare_y.end());
    out.impact_times = std::move(rec.impact_times);
    out.steps = rec.steps;
    out.max_H = rec.max_H;
    return out;
  }

  // Defined in model_analyses_continuation.hpp and instantiated apart (analyses_continuation.cpp
  // and models_continuation.cpp for the built-in models): compiled into the same unit as the other analyses, continuation's
  // templates took GCC's inlining budget from the stepper's (lyapunov of the impact model 1.13x
  // slower, measured).
  ContinuationResult continue_orbit(const AnalysesAt& at, const OrbitSettings& settings,
                                    const ContinuationOptions& options) const override;
  ContinuationResult continue_period_doubled(const AnalysesAt& at, const Bifurcation& at_pd,
                                             const ContinuationOptions& options) const override;
  ContinuationResult continue_from_hopf(const AnalysesAt& at, const EquilibriumBifurcation& hopf,
                                        const ContinuationOptions& options) const override;
  ContinuationResult continue_autonomous_orbit(const AnalysesAt& at, const AutonomousOrbitOptions& orbit,
                                               const ContinuationOptions& options) const override;

 private:
  // The rest of linearised_orbit on the orbit's own map: its states as the sequence, its
  // contacts, its monodromy and grid.
  static LinearisedOrbit finish(const StroboscopicMap<Model>& map, OrbitLinearisation<D, DW> at_orbit,
                                const OrbitRequest& request, LinearisedOrbit out) {
    const long K = map.grid().K;
    if (request.sequence && !Model::is_linear) {
      out.sequence.resize(static_cast<long>(D) * K);
      for (long l = 0; l < K; ++l) out.sequence.template segment<D>(D * l) = at_orbit.states[static_cast<size_t>(l)];
    }
    out.contacts = orbit_contacts(map, std::move(at_orbit.states));
    out.grid = map.grid();
    out.monodromy = std::make_unique<Monodromy<D, DW>>(map.grid(), std::move(at_orbit.maps));
    return out;
  }
  // Another level's orbit (any K) on this map's grid: on a grid with breakpoints, from that
  // level's grid (the same problem at N' = N K' / K; grid.hpp's regrid), else by index.
  static Eigen::VectorXd prolonged_guess(const Eigen::VectorXd& sequence, const HistoryGrid& grid) {
    const long K_from = sequence.size() / D;
    if (grid.has_breakpoints() && sequence.size() == K_from * D && (K_from * grid.N) % grid.K == 0) {
      const HistoryGrid from = regrid(grid, static_cast<int>(K_from * grid.N / grid.K));
      if (from.K == K_from) return prolong_periodic_sequence(sequence, D, from, grid);
    }
    return prolong_periodic_sequence(sequence, D, grid.K);
  }
  static bool all_finite(const OrbitLinearisation<D, DW>& at) {
    for (const StepMap<D, DW>& m : at.maps)
      if (!m.P.allFinite() || !m.Q.allFinite() || !m.R.allFinite()) return false;
    for (const Vec<D>& y : at.states)
      if (!y.allFinite()) return false;
    return true;
  }
  static constexpr const char* kNotAutonomous =
      "equilibria and orbits of unknown period are for autonomous models (no forcing: f independent of t); this "
      "one is forced";
  StroboscopicMap<Model> make_map(const MapSettings& s) const {
    return StroboscopicMap<Model>(TrapezoidStepper<Model>(model_, s.step), grid(s));
  }
  Model model_;
};

}  // namespace delayspec
