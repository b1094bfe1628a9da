#include "scene/problem/floquet_settings.hpp"

#include <cmath>
#include <limits>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

FloquetOptions read_floquet_options(Config& config, int default_nev) {
  const long nev = config.get_int_in_range("nev", default_nev, 1, std::numeric_limits<int>::max());
  FloquetOptions options = read_eigensolver_options(config);
  options.nev = static_cast<int>(nev);
  return options;
}

FloquetOptions read_eigensolver_options(Config& config) {
  FloquetOptions options;
  options.solver = parse_floquet_solver(config.get_choice(
      "solver", "auto", {"auto", "spectra", "arpack", "block", "dense", "dense-eigen", "dense-lapack"}));
  options.block_size = static_cast<int>(config.get_int_in_range("block_size", options.block_size, 1, 64));
  // 0 = automatic; otherwise >= nev + 2 (checked by floquet_multipliers)
  options.ncv = static_cast<int>(config.get_int_in_range("ncv", 0, 0, std::numeric_limits<int>::max()));
  const std::string tol_text = config.get_string("tol", "");
  options.tolerance = config.get_double("tol", options.tolerance);
  if (!(options.tolerance > 0)) throw BadInput("`tol = " + tol_text + "`: must be > 0");
  options.residual_bound = config.get_double("residual_bound", options.residual_bound);
  if (!(options.residual_bound > 0))
    throw BadInput("`residual_bound = " + config.get_string("residual_bound", "") + "`: must be > 0");
  const long restarts = config.get_int_in_range("max_restarts", options.max_iterations - 1, 0, 1'000'000);
  options.max_iterations = static_cast<int>(restarts) + 1;  // Arnoldi iterations = 1 + restarts
  options.seed = static_cast<std::uint64_t>(
      config.get_int_in_range("seed", static_cast<long>(options.seed), 0, std::numeric_limits<long>::max()));
  return options;
}

}  // namespace delayspec::cli
