#include "equation_model.hpp"

#include <cmath>
#include <map>
#include <mutex>

#include <toml++/toml.h>

#include "delayspec/errors.hpp"
#include "equation_plugin.hpp"
#include "equations_module_loader.hpp"
#include "key_registry.hpp"
#include "problem.hpp"

namespace delayspec::cli {

namespace {

// A table printed and loaded once per process: the points of a sweep or chart (threads) read the
// same table again and again with other parameter values.
struct LoadedEquations {
  EquationModelSource source;
  EquationPlugin plugin;
};

const LoadedEquations& load(const std::string& table_text, const std::filesystem::path& cache_dir) {
  // GiNaC is not thread-safe: every use of it, and the registry, under one lock.
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<const LoadedEquations>> loaded;
  const std::lock_guard<std::mutex> lock(mutex);
  const std::string key = cache_dir.string() + '\n' + table_text;
  if (auto it = loaded.find(key); it != loaded.end()) return *it->second;
  toml::table table;
  try {
    table = toml::parse(std::string_view(table_text), std::string_view("[equations]"));
  } catch (const toml::parse_error& e) {
    throw BadInput("`equations`: " + std::string(e.description()));
  }
  auto entry = std::make_unique<LoadedEquations>();
  entry->source = equations_module().generate(table, engine_keys());
  entry->plugin = load_equation_plugin(entry->source.code, cache_dir);
  return *(loaded[key] = std::move(entry));
}

double positive_value(const std::string& item, double value) {
  if (!std::isfinite(value) || !(value > 0))
    throw BadInput("`" + item + "` evaluates to " + format_number(value) +
                   " at these parameters: must be > 0 and finite");
  return value;
}

}  // namespace

std::vector<std::string> engine_keys() {
  std::vector<std::string> keys = {"model", "equations", "tau_over_T", "model_cache"};
  const size_t builtin_models = model_names().size();
  for (const auto& [key, by_command] : key_readers())
    for (const auto& [command, models] : by_command)
      if (models.size() == builtin_models) {
        keys.push_back(key);
        break;
      }
  return keys;
}

EquationModel read_equation_model(Config& config) {
  if (!config.has("equations"))
    throw BadInput("`model = equations`: the scene has no [equations] table (docs/models.md shows its format)");
  const std::string text = config.get_string("equations", "");
  const std::filesystem::path cache_dir = config.get_string("model_cache", default_model_cache().string());
  const LoadedEquations& eq = load(text, cache_dir);

  const EquationModelSource& src = eq.source;
  std::vector<double> p(src.parameters.size());
  for (size_t k = 0; k < p.size(); ++k) {
    p[k] = config.get_double(src.parameters[k], src.parameter_defaults[k]);
    require_finite(src.parameters[k].c_str(), p[k]);
  }
  const double period = positive_value("equations.period", eq.plugin.period(p.data()));
  double tau = 0;
  if (config.has("tau_over_T")) {
    const double ratio = config.get_double("tau_over_T", 1);
    require_positive("tau_over_T", ratio);
    tau = ratio * period;
  } else {
    tau = positive_value("equations.delay", eq.plugin.delay(p.data()));
  }
  std::vector<double> history(src.state.size());
  eq.plugin.history(p.data(), history.data());
  for (size_t i = 0; i < history.size(); ++i)
    if (!std::isfinite(history[i]))
      throw BadInput("`equations.history." + src.state[i] + "` evaluates to " + format_number(history[i]) +
                     " at these parameters: must be finite");
  EquationModel model;
  model.state = src.state;
  model.parameters = src.parameters;
  model.analyses.reset(eq.plugin.analyses(p.data(), tau, period, history.data()));
  return model;
}

}  // namespace delayspec::cli
