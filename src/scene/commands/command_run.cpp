// delayspec run SCENE --out DIR: runs the analyses a scene lists (`analyses = ["floquet", ...]`;
// without the key, the one command the scene's keys belong to, see read_analyses),
// each through the command table exactly as `delayspec NAME SCENE --json` would, and writes
// DIR/NAME.json (the command's JSON plus a "metadata" object, see metadata.hpp) and a manifest
// DIR/run.json. Every file is written atomically (atomic_file.hpp). run.json is removed before the
// first analysis runs and written after the last: it exists only for a finished run. An analysis
// that exits 3 with its failures recorded (failed points of sweep, chart, basin) keeps its
// file, the other analyses still run, and run exits 3; one that throws stops the run.
//
// The whole scene is validated before anything is computed: each analysis first runs in
// key-collection mode (Config::collect_keys_only: it reads its keys and stops at
// check_all_used()), then every key of the scene must be read by at least one analysis.
// A key only one analysis reads is therefore not "unknown" to the others.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <set>
#include <sstream>

#include "scene/output/output_directory.hpp"
#include "scene/commands/commands.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/printable.hpp"
#include "scene/points/distributed_points.hpp"
#include "scene/commands/key_registry.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/progress.hpp"
#include "scene/points/ranks.hpp"

namespace delayspec::cli {

namespace {

namespace fs = std::filesystem;

// The analyses listed, empty items dropped ("floquet,,lyapunov" lists two).
std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out = split_items(text);
  std::erase(out, std::string());
  return out;
}

// A scene without `analyses` (written for one command: `delayspec sweep SCENE`, ...) runs the
// command that reads every key of the scene, found by probing the commands in this order of
// preference (key_registry.hpp): floquet for a scene of model keys only, simulate for fig6_3's
// control_on_at, sweep for sweep_key, ... When none reads them all: floquet, whose key check
// then names the key.
std::string inferred_analysis(const Config& config) {
  for (const char* name : {"floquet", "lyapunov", "converge", "simulate", "sweep", "chart", "basin", "bench"}) {
    if (!is_command(name)) continue;
    std::set<std::string> read = {"analyses", "title"};
    for (const auto& r : probe_command(name, config).reads) read.insert(r.key);
    if (std::all_of(config.values().begin(), config.values().end(),
                    [&](const auto& kv) { return read.count(kv.first) > 0; }))
      return name;
  }
  return "floquet";
}

std::vector<std::string> read_analyses(Config& config) {
  const std::string inferred = config.has("analyses") ? "" : inferred_analysis(config);
  const std::string text = config.get_string("analyses", inferred);
  const std::vector<std::string> names = split_list(text);
  if (names.empty())
    throw BadInput("`analyses` is empty: list what to run, e.g. analyses = [\"floquet\"] in the scene");
  std::vector<std::string> available;
  for (const auto& spec : command_table())
    if (spec.analysis) available.push_back(spec.name);
  std::string available_list;
  for (const auto& a : available) available_list += (available_list.empty() ? "" : ", ") + a;
  std::set<std::string> seen;
  for (const auto& name : names) {
    if (!seen.insert(name).second) throw BadInput("`analyses = " + text + "`: `" + name + "` is listed twice");
    if (is_command(name) && !command_spec(name).analysis)
      throw BadInput("`analyses = " + text + "`: `" + name + "` is a command, not an analysis");
    if (is_command(name)) continue;
    const std::string suggestion = closest_key(name, available);
    throw BadInput("`analyses = " + text + "`: unknown analysis `" + name + "`" +
                   (suggestion.empty() ? "" : "; did you mean `" + suggestion + "`?") +
                   " (available: " + available_list + ")");
  }
  return names;
}

// The Config and Invocation of one analysis of the scene: the keys of the other analyses count
// as read; --json (its result is kept in NAME.json) and `out` given.
Config config_of_analysis(const Config& config, const std::set<std::string>& known) {
  Config analysis = config;
  for (const auto& key : known) analysis.mark_used(key);
  return analysis;
}

Invocation analysis_invocation(const std::string& name, const Invocation& inv, std::ostream& out) {
  return Invocation{.command = name,
                    .scene = inv.scene,
                    .json = true,
                    .out_dir = inv.out_dir,
                    .quiet = inv.quiet,
                    .resume = inv.resume,
                    .out = out,
                    .err = inv.err,
                    .output = inv.output};
}

// Under mpirun, a worker rank (ranks.hpp): it takes part in the point loops of the analyses that
// have them (distributed_points.hpp), in the lead's order, and writes nothing but point logs.
int run_worker_analyses(const Config& config, const Invocation& inv, const RunPlan& plan) {
  for (const auto& name : plan.analyses) {
    if (!command_spec(name).distributes) continue;
    Config worker_config = config_of_analysis(config, plan.known_keys);
    const Invocation analysis = analysis_invocation(name, inv, inv.out);
    try {
      command_spec(name).run(worker_config, analysis);
    } catch (const WorkerPointsDone&) {
      // this rank's points of the analysis are with the lead
    }
  }
  return 0;
}

}  // namespace

RunPlan plan_run(Config& config) {
  RunPlan plan;
  plan.analyses = read_analyses(config);
  plan.known_keys = {"analyses", "title"};
  for (const auto& name : plan.analyses) {
    const std::set<std::string> keys = probe_command(name, config, OnBadInput::rethrow).keys;
    plan.known_keys.insert(keys.begin(), keys.end());
  }
  for (const auto& [key, value] : config.values()) {
    if (plan.known_keys.count(key)) continue;
    const auto model = config.values().find("model");
    throw BadInput(unread_key_message(key_index(), printable(key), "(= " + printable(value) + ")", plan.analyses,
                                      model == config.values().end() ? "" : model->second, plan.known_keys));
  }
  return plan;
}

int command_run(Config& config, const Invocation& inv) {
  const auto run_start = std::chrono::steady_clock::now();
  // 1. Validate the whole scene before computing anything.
  const RunPlan plan = plan_run(config);
  const std::vector<std::string>& analyses = plan.analyses;
  const std::set<std::string>& known = plan.known_keys;
  const std::string title = config.get_string("title", "");
  if (!inv.out_dir) throw BadInput("`delayspec run` needs --out DIR: the directory the results are written to");
  const fs::path dir = *inv.out_dir;

  bool resumable = false;
  for (const auto& name : analyses) resumable = resumable || command_spec(name).resume;
  if (inv.resume && !resumable)
    throw BadInput("`--resume`: no analysis of this scene has anything to resume (only sweep, chart and basin do)");

  if (!is_lead_rank()) return run_worker_analyses(config, inv, plan);

  // 2. Run the analyses; each result file appears only once it is complete. run.json (the
  // manifest) goes first and comes back last: while it is absent the set is not complete.
  std::error_code removed;
  if (fs::remove(dir / "run.json", removed); removed)
    throw BadInput("cannot write `" + (dir / "run.json").string() +
                   "`: cannot remove the previous one: " + removed.message());
  nlohmann::json manifest;
  manifest["analyses"] = nlohmann::json::array();
  if (!title.empty()) manifest["title"] = title;
  int worst_status = 0;
  Progress progress(inv.err, "run", static_cast<long>(analyses.size()), inv.quiet);
  for (const auto& name : analyses) {
    Config analysis_config = config_of_analysis(config, known);
    std::ostringstream json_out;
    const Invocation analysis = analysis_invocation(name, inv, json_out);
    const auto start = std::chrono::steady_clock::now();
    const int status = command_spec(name).run(analysis_config, analysis);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Exit 3 from an analysis means failures recorded in its (complete) result, as sweep, chart
    // and basin do with failing points: keep it, run the other analyses, and exit 3 at the end.
    worst_status = std::max(worst_status, status);
    nlohmann::json result;
    try {
      result = nlohmann::json::parse(json_out.str());
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error("analysis `" + name + "` printed no single JSON object: " + e.what());
    }
    result["metadata"] = metadata_json(make_metadata(name, inv.scene, analysis_config, result, seconds));
    const fs::path file = dir / (name + ".json");
    write_output(inv, file, result.dump(2) + "\n");
    manifest["analyses"].push_back(
        {{"name", name}, {"file", file.filename().string()}, {"seconds", seconds}, {"exit_status", status}});
    if (!inv.json) inv.out << name << ": wrote " << file.string() << " (" << format_duration(seconds) << ")\n";
    progress.add();
  }
  progress.finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count();
  manifest["metadata"] = metadata_json(make_metadata("run", inv.scene, config, nlohmann::json::object(), wall));
  write_output(inv, dir / "run.json", manifest.dump(2) + "\n");
  if (inv.json) {
    manifest["out"] = dir.string();
    inv.out << manifest.dump(2) << "\n";
  } else {
    inv.out << "run: " << analyses.size() << " analyses in " << format_duration(wall) << "; results in " << dir.string()
            << " (plot them: delayspec plot " << dir.string() << ")\n";
  }
  return worst_status;
}

}  // namespace delayspec::cli
