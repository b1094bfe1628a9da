#pragma once
// A model given as plain functions on arrays (the contract of model.hpp, with the state, delayed
// values and parameters as pointers to doubles), and its shape: what the engine's templates must
// know at compile time (d, the number of delays, the kind of switch, the flags).
//
// Why: a model written as equations in a scene (docs/models.md) is printed as such functions and
// compiled at run time. When its shape is one the library was built for (prebuilt_shapes.hpp),
// only these functions are compiled (under a second: this header includes no Eigen and no
// engine template), and the analyses come from the library (FunctionModel<shape>,
// function_model.hpp, instantiated there once per shape). Any other shape compiles the same
// FunctionModel with the analyses into the model's object, as before (about 20 s).
//
// Layout: y holds d values, z the delayed states d * delay_count (delay by delay, model.hpp), p
// the parameters. A and B are written column by column (Eigen's order): A(i, a) is out[i + d a],
// B(i, a) is out[i + d a] for a < d * delay_count; the caller zeroes them and the functions write
// only the entries that are not identically zero.

namespace delayspec {

class ModelAnalyses;

enum class ModelSwitching : int { none = 0, state = 1, time = 2 };

struct ModelShape {
  int d = 1;
  int delay_count = 1;
  ModelSwitching switching = ModelSwitching::none;
  bool autonomous = false;       // f does not depend on t (model.hpp)
  bool affine_in_state = false;  // f_j affine in y(t)
  bool is_linear = false;        // f linear in (y, delayed y)
  constexpr bool operator==(const ModelShape&) const = default;
};

// j: the field (1 where the switch is > 0, else 2; 1 without a switch).
struct ModelFunctions {
  using Field = void (*)(int j, double t, const double* y, const double* z, const double* p, double* out);
  Field f = nullptr, A = nullptr, B = nullptr;
  Field f_t = nullptr, f_tt = nullptr;                                     // state switch only
  double (*H)(const double* y, const double* p) = nullptr;                 // state switch only
  void (*grad_H)(const double* y, const double* p, double* out) = nullptr;  // state switch only
  double (*switch_value)(double t, const double* p) = nullptr;             // time switch only: > 0 is field 1
};

// The values a model is made at: parameters (in the model's order), delays (its order), the
// period and the constant initial history (d values).
struct ModelValues {
  const double* parameters = nullptr;
  int parameter_count = 0;
  const double* delays = nullptr;
  double period = 0;
  const double* history = nullptr;
};

// The analyses (model_analyses.hpp) of FunctionModel<shape> over `functions`, compiled in the
// library; null when the library was not built for `shape`. `functions` must outlive them (a
// model's object is never unloaded). The caller owns the result.
// Defined in libdelayspec_prebuilt, as is:
ModelAnalyses* prebuilt_model_analyses(const ModelShape& shape, const ModelFunctions& functions,
                                       const ModelValues& values);
// "VERSION REVISION" of the build that made libdelayspec_prebuilt (delayspec/version.hpp): a
// model's loader checks it against its own.
const char* prebuilt_library_build();

}  // namespace delayspec
