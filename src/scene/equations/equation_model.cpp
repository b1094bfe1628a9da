#include "scene/equations/equation_model.hpp"

#include <cmath>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <toml++/toml.h>

#include "delayspec/errors.hpp"
#include "scene/equations/equation_plugin.hpp"
#include "scene/equations/equations_module_loader.hpp"
#include "scene/equations/model_cache.hpp"

namespace delayspec::cli {

namespace {

// GiNaC is not thread-safe: every use of it (the module's generate and constants), and the
// registries below, under one lock. The points of a sweep or chart (threads) read the same table
// again and again with other parameter values: each table is printed once per process, and
// compiled and loaded once per process and cache directory.
std::mutex& equations_mutex() {
  static std::mutex mutex;
  return mutex;
}

const EquationModelSource& generated(const std::string& table_text, const KeyIndex& index) {
  // Never destroyed: `constants` holds GiNaC expressions, which must not outlive GiNaC's own
  // statics, and the module's destructors may run first at exit.
  static auto& sources = *new std::map<std::string, std::unique_ptr<const EquationModelSource>>;
  const std::lock_guard<std::mutex> lock(equations_mutex());
  if (auto it = sources.find(table_text); it != sources.end()) return *it->second;
  toml::table table;
  try {
    table = toml::parse(std::string_view(table_text), std::string_view("[equations]"));
  } catch (const toml::parse_error& e) {
    throw BadInput("`equations`: " + std::string(e.description()));
  }
  auto source = std::make_unique<const EquationModelSource>(equations_module().generate(table, engine_keys(index)));
  const EquationModelSource& result = *source;
  sources[table_text] = std::move(source);
  return result;
}

std::vector<double> constants_at(const EquationModelSource& source, const std::vector<double>& p) {
  const std::lock_guard<std::mutex> lock(equations_mutex());
  return source.constants(p);
}

// What this layer needs of a model besides its compiled code: the names of keys, columns and
// messages, and the parameters' defaults. From the table read by GiNaC, or from the record kept
// beside the compiled model (TableRecord), so that a cached model costs no symbolic work.
struct EquationNames {
  std::vector<std::string> state, parameters, delays, delayed;
  std::vector<double> parameter_defaults;
  bool written_with_delays = false;
};

EquationNames names_of(const EquationModelSource& source) {
  return {source.state, source.parameters, source.delays, source.delayed, source.parameter_defaults,
          source.written_with_delays};
}

// The record's text: a line per list, "NAME ITEM ITEM ...", the defaults in the shortest exact
// spelling. Every name is an identifier (the table's reader checks them).
std::string names_text(const EquationNames& n) {
  std::string text;
  const auto line = [&](const char* name, const std::vector<std::string>& items) {
    text += name;
    for (const auto& item : items) text += " " + item;
    text += "\n";
  };
  line("state", n.state);
  line("parameters", n.parameters);
  std::vector<std::string> defaults;
  for (double v : n.parameter_defaults) defaults.push_back(format_number(v));
  line("defaults", defaults);
  line("delays", n.delays);
  line("delayed", n.delayed);
  line("written_with_delays", {n.written_with_delays ? "1" : "0"});
  return text;
}

// names_text read back; nothing when the text is not what names_text writes.
std::optional<EquationNames> names_from_text(const std::string& text) {
  std::map<std::string, std::vector<std::string>> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string name;
    words >> name;
    for (std::string item; words >> item;) lines[name].push_back(item);
  }
  EquationNames n{lines["state"], lines["parameters"], lines["delays"], lines["delayed"], {}, false};
  for (const auto& v : lines["defaults"]) {
    char* end = nullptr;
    n.parameter_defaults.push_back(std::strtod(v.c_str(), &end));
    if (*end != '\0') return std::nullopt;
  }
  const auto& flag = lines["written_with_delays"];
  n.written_with_delays = flag == std::vector<std::string>{"1"};
  if (n.state.empty() || n.parameter_defaults.size() != n.parameters.size() ||
      n.delayed.size() != n.state.size() * n.delays.size() || flag.size() != 1)
    return std::nullopt;
  return n;
}

struct LoadedEquations {
  const EquationPlugin* plugin;
  EquationNames names;
};

// The parameters' defaults as the table's own text gives them (TOML numbers, in key order, as the
// module reads them), when its parameters are `names`; nothing otherwise. A record's `defaults`
// line is never what a model runs with: editing it changed the model (issue 61 item 4), while the
// table text is compared byte for byte with the scene's.
std::optional<std::vector<double>> table_defaults(const std::string& table_text, const std::vector<std::string>& names) {
  toml::table table;
  try {
    table = toml::parse(std::string_view(table_text), std::string_view("[equations]"));
  } catch (const toml::parse_error&) {
    return std::nullopt;
  }
  std::vector<std::string> keys;
  std::vector<double> values;
  if (const toml::node* node = table.get("parameters")) {
    const toml::table* parameters = node->as_table();
    if (!parameters) return std::nullopt;
    for (const auto& [key, value] : *parameters) {
      std::optional<double> number;
      if (const auto* i = value.as_integer()) number = static_cast<double>(i->get());
      if (const auto* f = value.as_floating_point()) number = f->get();
      if (!number || !std::isfinite(*number)) return std::nullopt;
      keys.emplace_back(key.str());
      values.push_back(*number);
    }
  }
  if (keys != names) return std::nullopt;
  return values;
}

// The model compiled before from this table (found_equation_plugin), once per process and cache
// directory; nothing when this program has not compiled it into `cache_dir`.
std::optional<LoadedEquations> found(const std::string& table_text, const std::filesystem::path& cache_dir) {
  static std::map<std::string, std::optional<LoadedEquations>> known;
  static std::map<std::string, EquationPlugin> plugins;  // (never moved: the results point here)
  const std::lock_guard<std::mutex> lock(equations_mutex());
  const std::string key = cache_dir.string() + '\n' + table_text;
  if (auto it = known.find(key); it != known.end()) return it->second;
  std::optional<LoadedEquations> result;
  try {
    if (std::optional<FoundPlugin> hit = found_equation_plugin(table_text, cache_dir))
      if (std::optional<EquationNames> names = names_from_text(hit->names))
        if (std::optional<std::vector<double>> defaults = table_defaults(table_text, names->parameters)) {
          names->parameter_defaults = std::move(*defaults);
          result = LoadedEquations{&(plugins[key] = hit->plugin), *names};
        }
  } catch (const BadInput&) {
    // No compiler, an unusable cache, an object that cannot be loaded: the table is read, and
    // its constants checked, first; the compile then says the same (as without a record).
  }
  // A miss too: this process reads the table with GiNaC and compiles it, once (generated(), compiled()).
  return known[key] = result;
}

const EquationPlugin& compiled(const EquationModelSource& source, const std::string& table_text,
                               const std::filesystem::path& cache_dir) {
  static std::map<std::string, EquationPlugin> plugins;
  const std::lock_guard<std::mutex> lock(equations_mutex());
  const std::string key = cache_dir.string() + '\n' + source.code;
  if (auto it = plugins.find(key); it != plugins.end()) return it->second;
  return plugins[key] = load_equation_plugin(source.code, source.shape, cache_dir, {table_text, names_text(names_of(source))});
}

// The plugin's analyses (compiled from the equations), with a failure at a step that is not
// finite told in the equations' terms: the engine says which step and where it evaluated the
// model (NonFiniteStep), GiNaC says which term is not finite there. Only failures pay for it.
class ExplainedAnalyses final : public ModelAnalyses {
 public:
  ExplainedAnalyses(std::unique_ptr<const ModelAnalyses> inner, std::string table_text, EquationNames names,
                    std::vector<double> p)
      : inner_(std::move(inner)), table_text_(std::move(table_text)), names_(std::move(names)), p_(std::move(p)) {}

  int state_dimension() const override { return inner_->state_dimension(); }
  bool switches_in_state() const override { return inner_->switches_in_state(); }
  bool switches_in_time() const override { return inner_->switches_in_time(); }
  bool is_linear() const override { return inner_->is_linear(); }
  bool is_autonomous() const override { return inner_->is_autonomous(); }
  double tau() const override { return inner_->tau(); }
  std::vector<double> delays() const override { return inner_->delays(); }
  double period() const override { return inner_->period(); }
  std::vector<double> time_switches() const override { return inner_->time_switches(); }
  SpectralResult spectral_reference(const SpectralOptions& options) const override {
    return inner_->spectral_reference(options);
  }
  LinearisedOrbit linearised_orbit(const MapSettings& map, const OrbitSettings& orbit,
                                   const OrbitRequest& request) const override {
    return explained([&] { return inner_->linearised_orbit(map, orbit, request); });
  }
  EquilibriumResult equilibrium(const Eigen::VectorXd& guess, const EquilibriumOptions& options) const override {
    return explained([&] { return inner_->equilibrium(guess, options); });
  }
  AutonomousLinearisedOrbit autonomous_orbit(const AutonomousOrbitOptions& options) const override {
    return explained([&] { return inner_->autonomous_orbit(options); });
  }
  ConstantHistory at_constant_history(const Eigen::VectorXd& y) const override {
    return inner_->at_constant_history(y);
  }
  Eigen::MatrixXd jacobian_at(const Eigen::VectorXd& y, const Eigen::VectorXd& delayed) const override {
    return inner_->jacobian_at(y, delayed);
  }
  LyapunovResult lyapunov(const MapSettings& map, const LyapunovOptions& options) const override {
    return explained([&] { return inner_->lyapunov(map, options); });
  }
  std::vector<Eigen::VectorXd> section_sequence(const MapSettings& map, long transient, long count) const override {
    return explained([&] { return inner_->section_sequence(map, transient, count); });
  }
  SimulationRecord<Eigen::Dynamic> simulate(const MapSettings& before_map, const MapSettings& map,
                                            const SimulationOptions& options,
                                            const ModelAnalyses* before) const override {
    const auto* explained_before = dynamic_cast<const ExplainedAnalyses*>(before);
    const ModelAnalyses* inner_before = explained_before ? explained_before->inner_.get() : before;
    return explained([&] { return inner_->simulate(before_map, map, options, inner_before); });
  }
  ContinuationResult continue_orbit(const AnalysesAt& at, const OrbitSettings& orbit,
                                    const ContinuationOptions& options) const override {
    return explained([&] { return inner_->continue_orbit(unwrapped(at), orbit, options); });
  }
  ContinuationResult continue_period_doubled(const AnalysesAt& at, const Bifurcation& at_pd,
                                             const ContinuationOptions& options) const override {
    return explained([&] { return inner_->continue_period_doubled(unwrapped(at), at_pd, options); });
  }
  ContinuationResult continue_from_hopf(const AnalysesAt& at, const EquilibriumBifurcation& hopf,
                                        const ContinuationOptions& options) const override {
    return explained([&] { return inner_->continue_from_hopf(unwrapped(at), hopf, options); });
  }
  ContinuationResult continue_autonomous_orbit(const AnalysesAt& at, const AutonomousOrbitOptions& orbit,
                                               const ContinuationOptions& options) const override {
    return explained([&] { return inner_->continue_autonomous_orbit(unwrapped(at), orbit, options); });
  }

 private:
  // The family `at` gives explained analyses; the plugin's own continuation takes its own.
  static AnalysesAt unwrapped(const AnalysesAt& at) {
    return [at](double p) -> std::shared_ptr<const ModelAnalyses> {
      std::shared_ptr<const ModelAnalyses> analyses = at(p);
      if (const auto* explained = dynamic_cast<const ExplainedAnalyses*>(analyses.get())) return explained->inner_;
      return analyses;
    };
  }

  template <class Analysis>
  auto explained(const Analysis& analysis) const -> decltype(analysis()) {
    try {
      return analysis();
    } catch (const NonFiniteStep& e) {
      throw NumericalFailure(explanation(e));
    }
  }

  // "<the engine's words>; at t = 0, x = 0, x_tau = 0: `equations.rhs[1]` = ...: its derivative
  // by x, ..., is undefined (...)", each point where some term is not finite.
  std::string explanation(const NonFiniteStep& e) const {
    std::string text = e.what();
    bool named = false;
    // The table read again by GiNaC (a cached model was loaded without it). It passed every
    // check when it was compiled, so no key needs reserving (the index stays unbuilt).
    const EquationModelSource& source = generated(table_text_, KeyIndex{});
    for (const ModelPoint& point : e.points()) {
      std::vector<std::string> terms;
      {
        const std::lock_guard<std::mutex> lock(equations_mutex());
        terms = source.terms_not_finite(point.t, point.y, point.y_tau, p_);
      }
      if (terms.empty()) continue;
      text += "; at t = " + format_number(point.t);
      for (size_t i = 0; i < names_.state.size() && i < point.y.size(); ++i)
        text += ", " + names_.state[i] + " = " + format_number(point.y[i]);
      for (size_t a = 0; a < names_.delayed.size() && a < point.y_tau.size(); ++a)
        text += ", " + names_.delayed[a] + " = " + format_number(point.y_tau[a]);
      for (size_t i = 0; i < terms.size(); ++i) text += (i ? "; " : ": ") + terms[i];
      named = true;
      break;  // the first point the step evaluated where a term is not finite
    }
    if (!named) {
      text += "; every term of the equations is finite where this step evaluated them";
      for (const ModelPoint& point : e.points()) text += describe_point(point);
      text += ": the step itself is not finite (a larger N gives smaller steps)";
    }
    return "model = equations: " + text;
  }

  std::shared_ptr<const ModelAnalyses> inner_;
  std::string table_text_;
  EquationNames names_;
  std::vector<double> p_;
};

// The item of delay k in messages: equations.delay for a model written with `delay`, else
// equations.delays.NAME.
std::string delay_item(const EquationNames& names, size_t k) {
  return names.written_with_delays ? "equations.delays." + names.delays[k] : "equations.delay";
}

double positive_value(const std::string& item, double value) {
  if (!std::isfinite(value) || !(value > 0))
    throw BadInput("`" + item + "` evaluates to " + format_number(value) +
                   " at these parameters: must be > 0 and finite");
  return value;
}

// The items of the delays in messages, each in backquotes.
std::vector<std::string> delay_items(const EquationNames& names) {
  std::vector<std::string> items;
  for (size_t k = 0; k < names.delays.size(); ++k)  // (append: GCC 12 warns falsely on "`" + string, -Wrestrict)
    items.push_back(std::string("`").append(delay_item(names, k)).append("`"));
  return items;
}

// The period, delays and constant history at some parameters, each checked and named.
struct EquationConstants {
  double period;
  std::vector<double> delays, history;
};

// From `constants` (period, delays, history: GiNaC's values, or the compiled model's); ratio:
// tau_over_T (NaN: the delays are the table's).
EquationConstants equation_constants(const EquationNames& names, double ratio, const std::vector<double>& constants) {
  const size_t n = names.delays.size();
  EquationConstants c;
  c.period = positive_value("equations.period", constants[0]);
  if (!std::isnan(ratio)) {
    require_positive("tau_over_T", ratio);
    c.delays = {ratio * c.period};
  } else {
    for (size_t k = 0; k < n; ++k) positive_value(delay_item(names, k), constants[1 + k]);
    c.delays.assign(constants.begin() + 1, constants.begin() + 1 + static_cast<long>(n));
  }
  c.history.assign(constants.begin() + 1 + static_cast<long>(n), constants.end());
  for (size_t i = 0; i < c.history.size(); ++i)
    if (!std::isfinite(c.history[i]))
      throw BadInput("`equations.history." + names.state[i] + "` evaluates to " + format_number(c.history[i]) +
                     " at these parameters: must be finite");
  return c;
}

// The compiled model as a family (problem_family.hpp): its parameters, and tau_over_T for a
// model of one delay (NaN in the base values when the scene does not give it: the table's delay).
// A new value costs the constants' evaluation and the analyses' construction, never a compile.
class EquationFamily final : public ProblemFamily {
 public:
  EquationFamily(const EquationPlugin& plugin, std::string table_text, EquationNames names, std::vector<double> p,
                 double ratio)
      : plugin_(plugin), table_text_(std::move(table_text)), names_(std::move(names)) {
    parameter_names_ = names_.parameters;
    base_values_ = std::move(p);
    if (names_.delays.size() == 1) {
      parameter_names_.push_back("tau_over_T");
      base_values_.push_back(ratio);
    }
  }
  const std::vector<std::string>& parameter_names() const override { return parameter_names_; }
  const std::vector<double>& base_values() const override { return base_values_; }

  // The compiled model's constants at `values`; BadInput naming the item that is not valid.
  EquationConstants constants(const std::vector<double>& values) const {
    const size_t n = names_.delays.size();
    std::vector<double> c(1 + n + names_.state.size());
    c[0] = plugin_.period(values.data());
    plugin_.delays(values.data(), c.data() + 1);
    plugin_.history(values.data(), c.data() + 1 + n);
    return equation_constants(names_, ratio(values), c);
  }


 protected:
  FamilyMember make(const std::vector<double>& values) const override {
    if (values.size() != base_values_.size())
      throw std::invalid_argument("EquationFamily::make: " + std::to_string(values.size()) + " values for " +
                                  std::to_string(base_values_.size()) + " parameters");
    try {
      for (size_t k = 0; k < names_.parameters.size(); ++k) require_finite(names_.parameters[k].c_str(), values[k]);
      const EquationConstants c = constants(values);
      std::unique_ptr<const ModelAnalyses> analyses(
          plugin_.analyses(values.data(), c.delays.data(), c.period, c.history.data()));
      // Null only from a model of a prebuilt shape whose libdelayspec_prebuilt lacks that shape: a
      // library left from a build with another list (prebuilt_shapes.hpp) under the same revision.
      if (!analyses)
        throw BadInput("equations: libdelayspec_prebuilt beside the library does not hold the shape of the model " +
                       plugin_.object.string() + " (left from another build?): rebuild it (cmake --build BUILD_DIR "
                       "--target delayspec_prebuilt)");
      const std::vector<double> p(values.begin(), values.begin() + static_cast<long>(names_.parameters.size()));
      return {std::make_shared<const ExplainedAnalyses>(std::move(analyses), table_text_, names_, p), ""};
    } catch (const BadInput& e) {
      return {nullptr, e.what()};
    }
  }

 private:
  double ratio(const std::vector<double>& values) const {
    return names_.delays.size() == 1 ? values.back() : NAN;
  }
  const EquationPlugin& plugin_;  // (compiled() and found() keep every plugin for the process)
  std::string table_text_;
  EquationNames names_;
  std::vector<std::string> parameter_names_;
  std::vector<double> base_values_;
};

}  // namespace

std::vector<std::string> engine_keys(const KeyIndex& index) {
  std::vector<std::string> keys = {"model", "equations", "tau_over_T", "model_cache"};
  for (const auto& key : keys_of_every_model(index)) keys.push_back(key);
  return keys;
}

EquationModel read_equation_model(Config& config,
                                  const std::function<void(const std::vector<double>&, const std::vector<std::string>&, double)>& check_grid,
                                  const std::function<void(bool)>& check_autonomy) {
  if (!config.has("equations"))
    throw BadInput("`model = equations`: the scene has no [equations] table (docs/models.md shows its format)");
  const std::string text = config.get_string("equations", "");
  // The cache holds code this program runs: a scene, which may come from anywhere, never chooses
  // it (model_cache.hpp).
  if (config.has("model_cache") && config.from_scene("model_cache"))
    throw BadInput("`model_cache` in the scene " + config.origin("model_cache") +
                   ": a scene may not choose where compiled models are loaded from; give it on the command line " +
                   "(--set model_cache=DIR), as a Python keyword, or through XDG_CACHE_HOME");
  const std::filesystem::path cache_dir = config.get_string("model_cache", default_model_cache().string());
  // A table this program compiled before is found by its text (found_equation_plugin): no GiNaC
  // and no key index, a few milliseconds. The first run of a table reads it with GiNaC, checks
  // all it can before the compile (seconds), compiles and records it.
  std::optional<LoadedEquations> loaded = found(text, cache_dir);
  const bool was_compiled = loaded.has_value();
  const EquationModelSource* src = was_compiled ? nullptr : &generated(text, config.key_index());
  const EquationNames names = was_compiled ? loaded->names : names_of(*src);
  std::vector<double> p(names.parameters.size());
  for (size_t k = 0; k < p.size(); ++k) {
    p[k] = config.get_double(names.parameters[k], names.parameter_defaults[k]);
    require_finite(names.parameters[k].c_str(), p[k]);
  }
  const size_t n = names.delays.size();
  double ratio = NAN;  // tau_over_T, when given: the one delay in periods
  if (config.has("tau_over_T")) {
    ratio = config.get_double("tau_over_T", 1);
    require_positive("tau_over_T", ratio);
    if (n > 1)
      throw BadInput("`tau_over_T`: sets the one delay of a model; this model has " + std::to_string(n) +
                     " (equations.delays): set the parameters its delays depend on instead");
  }
  if (!was_compiled) {
    // Everything that can be checked without the compiled model is checked before the compile
    // (seconds): the constant expressions, and the grid they give with N.
    const EquationConstants exact = equation_constants(names, ratio, constants_at(*src, p));
    check_grid(exact.delays, delay_items(names), exact.period);
    // equilibrium of a forced model compiled for 13 s before refusing it (issue 61 item 4)
    if (check_autonomy) check_autonomy(src->shape.autonomous);
    loaded = LoadedEquations{&compiled(*src, text, cache_dir), names};
  }
  auto family = std::make_shared<const EquationFamily>(*loaded->plugin, text, names, p, ratio);
  if (was_compiled) {
    const EquationConstants constants = family->constants(family->base_values());
    check_grid(constants.delays, delay_items(names), constants.period);
  }
  return {names.state, names.parameters, std::move(family)};
}

}  // namespace delayspec::cli
