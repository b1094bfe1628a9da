#pragma once
// The [equations] table of a scene (docs/models.md), checked, differentiated (GiNaC) and printed
// as the C++ source of the model's functions (model_functions.hpp), which the plugin loader
// compiles and loads.
//
// Nothing of the scene reaches the code as text: user names become generated names (y[i],
// z[i], p[k], t), numbers their exact values, and every expression is printed by GiNaC from its
// parsed form (equation_expression.hpp).
#include <functional>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "delayspec/model_functions.hpp"

namespace delayspec::cli {

// The [equations] table of a scene, checked, differentiated (GiNaC) and printed as C++.
struct EquationModelSource {
  std::vector<std::string> state;          // state names in order; d = state.size()
  std::vector<std::string> parameters;     // parameter names, sorted (the table's order)
  std::vector<double> parameter_defaults;  // their values in the table, same order
  std::vector<std::string> delays;         // the delays' names (sorted; {"tau"} for one delay)
  std::vector<std::string> delayed;        // the delayed states' names NAME_X, d per delay, delay by delay
  bool written_with_delays = false;        // the `delays` table (else `delay` or none): for messages
  // What the engine's templates need to know (model_functions.hpp); shape.switching is `state`
  // when `switch` is given and depends on the state, `time` when it depends on t only.
  ModelShape shape;
  std::string code;                        // C++ text of the functions and their table (below)
  // The constant expressions at parameter values (in the order of `parameters`): period, the
  // delays (in the order of `delays`), then the d history values, each GiNaC's evaluation of the exact expression (NaN where that is
  // not a finite real number, e.g. 1/0). So that they are checked before the model is compiled
  // (seconds) rather than after. Not thread-safe (GiNaC).
  std::function<std::vector<double>(const std::vector<double>& p)> constants;
  // terms_not_finite (equation_model_symbolic.hpp) of this model at a point and parameter values:
  // what to say when a step is not finite there. Not thread-safe (GiNaC).
  std::function<std::vector<std::string>(double t, const std::vector<double>& y, const std::vector<double>& y_tau,
                                         const std::vector<double>& p)>
      terms_not_finite;
};

// Throws BadInput naming the item (e.g. "`equations.rhs[2]`: ...") for every input error that
// is not about the compiler. reserved_keys: every key the engine reads (N, nev, seed, ...): a
// parameter may not take one of these names. NOT thread-safe (GiNaC is not): call under a mutex.
//
// The code (after <cmath>, "delayspec/detail/remembered_trig.hpp" and
// "delayspec/model_functions.hpp", inside a namespace of the caller's) defines the constants d,
// parameter_count and kShape (= shape), the static functions period_of(p), delays_of(p, taus),
// history_of(p, y) of the constant expressions, and the model's functions (model_functions.hpp:
// f, A, B for j = 1 (rhs_switched, switch > 0) and j = 2 (rhs); f_t, f_tt, H and grad_H with a
// state switch; switch_value with a time switch) with their table `kFunctions`, in which p holds
// the parameters in the order of `parameters`.
EquationModelSource generate_equation_model(const toml::table& equations,
                                            const std::vector<std::string>& reserved_keys);

}  // namespace delayspec::cli
