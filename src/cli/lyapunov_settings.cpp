#include "lyapunov_settings.hpp"

#include <climits>

namespace delayspec::cli {

namespace {

long read_long(Config& config, const std::string& key, long fallback, long min) {
  const long value = config.get_int(key, fallback);
  if (value < min)
    throw BadInput("`" + key + " = " + std::to_string(value) + "`: must be an integer >= " + std::to_string(min));
  return value;
}

}  // namespace

LyapunovOptions read_lyapunov_options(Config& config, int default_exponents) {
  LyapunovOptions o;
  o.exponents = static_cast<int>(read_long(config, "exponents", default_exponents, 1));
  o.periods = read_long(config, "periods", o.periods, 2);
  o.transient = read_long(config, "transient", o.transient, 0);
  o.seed = static_cast<std::uint64_t>(read_long(config, "seed", 1, 0));
  o.qr_every = static_cast<int>(std::min<long>(read_long(config, "qr_every", 1, 1), INT_MAX));
  o.batches = static_cast<int>(std::min<long>(read_long(config, "batches", o.batches, 2), INT_MAX));
  if (o.exponents > 64)
    throw BadInput("`exponents = " + std::to_string(o.exponents) + "`: at most 64 (only the leading ones are meant)");
  if (o.periods % o.qr_every != 0)
    throw BadInput("`periods = " + std::to_string(o.periods) + "` must be a multiple of `qr_every = " +
                   std::to_string(o.qr_every) + "`");
  return o;
}

LyapunovResult run_lyapunov(const Problem& problem, const LyapunovOptions& options) {
  return std::visit(
      [&](const auto& model) {
        using Model = std::decay_t<decltype(model)>;
        StroboscopicMap<Model> map(TrapezoidStepper<Model>(model, step_options(problem)), problem.grid);
        return lyapunov_exponents(map, map.constant_history(model.initial_state()), options);
      },
      problem.model);
}

int state_dimension(const Problem& problem) {
  return std::visit([](const auto& m) { return std::decay_t<decltype(m)>::d; }, problem.model);
}

}  // namespace delayspec::cli
