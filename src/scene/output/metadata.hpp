#pragma once
// Metadata carried by every output file of `delayspec run` (and of any command writing files
// into --out): what was computed, with which parameters, by which version, in how long.
//
// JSON files get a "metadata" object:
//     {"delayspec_version": "0.1.0", "source_revision": "b054d7f-dirty",
//      "command": "floquet", "scene": "data/scenes/default.toml",
//      "parameters": {"N": "200", "k": "0.2", ...},   // every key given (scene + --set), as text
//      "defaults": {"solver": "spectra", ...},        // every other key the command read, with
//                                                     // the default it used (Config::effective_defaults)
//      "N": 200, "events": "on", "jacobian": "consistent",
//      "wall_seconds": 1.23, "finished_utc": "2026-11-22T04:00:00Z"}
// CSV files start with the same content as comment lines (gnuplot, numpy.loadtxt and
// pandas.read_csv(comment='#') skip them):
//     # delayspec 0.1.0
//     # source_revision: b054d7f-dirty
//     # command: floquet
//     # scene: data/scenes/default.toml
//     # N = 200                    (one line per key given)
//     # default: solver = spectra  (one line per key read with its default)
//     ...
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/keys/config.hpp"

namespace delayspec::cli {

struct OutputMetadata {
  std::string command;
  std::optional<std::string> scene;
  std::map<std::string, std::string> parameters;  // Config::values()
  std::map<std::string, std::string> defaults;    // Config::effective_defaults()
  // Resolved discretisation: taken from the result (its "N", "events", "jacobian") when it has
  // them, else from the parameters, else the defaults.
  long N = 0;
  std::string events;
  std::string jacobian;
  double wall_seconds = 0;
  // How the files name the model and its state components (name_model): "model_label" and
  // "state_names" in JSON, `# model_label = ...` and `# state_names = x,v` in CSV (plot's titles
  // and axis labels); empty: not said (a command without one model).
  std::string model_label;
  std::vector<std::string> state_names;
};

// How outputs name a model: the built-in model's name (the key `model`); an [equations] model,
// whose key value "equations" names no model, by its scene file's stem ("pyragas_oscillator"),
// else by its state ("equations in x, y") (issue 61 item 8).
std::string model_label(const std::string& model, const std::vector<std::string>& state_names,
                        const std::optional<std::string>& scene);
// Fills metadata.model_label and metadata.state_names: a command passes its Problem's
// (problem.hpp: model_label of the scene file holding the [equations] table); make_metadata
// names a result that carries `model` and `state_names` by model_label(model, names, scene).
void name_model(OutputMetadata& metadata, const std::string& label, const std::vector<std::string>& state_names);

// The state component `value` names, 0-based: a state name or its 1-based index among `names`
// (the key plot_component); BadInput naming `key`, the value and the names otherwise.
size_t state_component(const std::string& key, const std::string& value, const std::vector<std::string>& names);

// Fills the metadata of `command` run with `config`, taking N/events/jacobian from `result`
// when present.
OutputMetadata make_metadata(const std::string& command, const std::optional<std::string>& scene, const Config& config,
                             const nlohmann::json& result, double wall_seconds);

nlohmann::json metadata_json(const OutputMetadata& metadata);
// The "# ..." comment lines (each ends with a newline).
std::string metadata_comment_lines(const OutputMetadata& metadata);

// Current UTC time, ISO 8601 ("2026-11-22T04:00:00Z").
std::string utc_now_iso8601();

}  // namespace delayspec::cli
