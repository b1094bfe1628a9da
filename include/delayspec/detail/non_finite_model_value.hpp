#pragma once
// What a model compiled from a scene's equations (src/equations/equation_model_source.cpp) does
// when its field f or a derivative A = df/dy, B = df/dy_tau is not a finite number at a point the
// engine asks for: x^(1/3) has an infinite derivative at x = 0, log(x) is -inf there. Left alone
// the value would reach the step maps and surface much later as "matrix has non-finite entries";
// the generated code checks each result (a few compares against transcendental functions) and
// throws here, naming the expression and the point in the user's names.
#include <cmath>
#include <sstream>
#include <string>

#include "delayspec/errors.hpp"

namespace delayspec::detail {

// `what`: 'f', 'A' or 'B'; `values` the d (f) or d x d column-major (A, B) results; `switched`:
// the model has two fields (rhs_switched for j = 1, rhs for j = 2); `names`: the d state names,
// or null (then y[i]).
[[noreturn]] inline void throw_non_finite_model_value(char what, int j, bool switched, const double* values, int d,
                                                      double t, const double* y, const double* z,
                                                      const char* const* names) {
  const auto name = [&](int i) { return names ? std::string(names[i]) : "y[" + std::to_string(i) + "]"; };
  const int count = what == 'f' ? d : d * d;
  int k = 0;
  while (k < count && std::isfinite(values[k])) ++k;
  if (k == count) k = 0;
  const int row = what == 'f' ? k : k % d, column = k / d;
  std::ostringstream s;
  s.precision(17);
  const std::string item =
      "`equations." + std::string(switched && j == 1 ? "rhs_switched" : "rhs") + "[" + std::to_string(row + 1) + "]`";
  if (what == 'f')
    s << item << " is not finite (" << values[k] << ")";
  else
    s << "the derivative of " << item << " by " << name(column) << (what == 'B' ? "_tau" : "") << " is not finite ("
      << values[k] << ")";
  s << " at t = " << t;
  for (int i = 0; i < d; ++i) s << ", " << name(i) << " = " << y[i];
  for (int i = 0; i < d; ++i) s << ", " << name(i) << "_tau = " << z[i];
  s << ": the model is not smooth there (e.g. x^(1/3) or sqrt(x) at x = 0); the engine needs finite derivatives "
       "along the orbit";
  throw BadInput(s.str());
}

}  // namespace delayspec::detail
