#include "floquet_settings.hpp"

#include <cmath>
#include <limits>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

FloquetOptions read_floquet_options(Config& config, int default_nev) {
  FloquetOptions options;
  const long nev = config.get_int("nev", default_nev);
  if (nev < 1 || nev > std::numeric_limits<int>::max())
    throw BadInput("`nev = " + std::to_string(nev) + "`: must be >= 1");
  options.nev = static_cast<int>(nev);
  options.solver = parse_floquet_solver(
      config.get_choice("solver", "spectra", {"spectra", "arpack", "dense", "dense-eigen", "dense-lapack"}));
  const long ncv = config.get_int("ncv", 0);
  if (ncv < 0 || ncv > std::numeric_limits<int>::max())
    throw BadInput("`ncv = " + std::to_string(ncv) + "`: must be 0 (automatic) or >= nev + 2");
  options.ncv = static_cast<int>(ncv);
  const std::string tol_text = config.get_string("tol", "");
  options.tolerance = config.get_double("tol", options.tolerance);
  if (!(options.tolerance > 0)) throw BadInput("`tol = " + tol_text + "`: must be > 0");
  const long restarts = config.get_int("max_restarts", options.max_iterations - 1);
  if (restarts < 0 || restarts > 1000000)
    throw BadInput("`max_restarts = " + std::to_string(restarts) + "`: must be between 0 and 1000000");
  options.max_iterations = static_cast<int>(restarts) + 1;  // Arnoldi iterations = 1 + restarts
  const long seed = config.get_int("seed", static_cast<long>(options.seed));
  if (seed < 0) throw BadInput("`seed = " + std::to_string(seed) + "`: must be >= 0");
  options.seed = static_cast<std::uint64_t>(seed);
  return options;
}

}  // namespace delayspec::cli
