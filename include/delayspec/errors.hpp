#pragma once
// The two error channels of delayspec (see docs/design.md, "Bad input"):
//  * BadInput: the caller asked for something invalid (a key, a value, a size).
//    The message names the offending key or value and the rule it broke.
//    The CLI maps it to exit status 2.
//  * NumericalFailure: the input was valid but a numerical method did not reach
//    its goal (Newton, Krylov, orbit search). The message carries the numbers
//    (iterations, residual). The CLI maps it to exit status 3.
#include <complex>
#include <stdexcept>
#include <string>
#include <vector>

namespace delayspec {

class BadInput : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

class NumericalFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A NumericalFailure whose cause is a number that is not finite (NaN, infinite) in a result
// (a tangent block, a residual), found where the step that made it is no longer known. The
// analyses catch it and locate that step (StroboscopicMap::throw_first_non_finite_step).
class NonFiniteResult : public NumericalFailure {
 public:
  using NumericalFailure::NumericalFailure;
};

// A point at which a step evaluated the model's f(t, y, y(t - tau)) and its derivatives.
struct ModelPoint {
  double t = 0;
  std::vector<double> y, y_tau;
};

// A NumericalFailure at one step of the discretisation whose new state or whose derivative (the
// step map) is not finite, with the points where that step evaluated the model: for the front
// end that knows the model's terms to say which one is not finite there (model = equations:
// src/scene/equations/equation_model.cpp). what() describes the step in the engine's words.
class NonFiniteStep : public NumericalFailure {
 public:
  NonFiniteStep(const std::string& what, std::vector<ModelPoint> points);
  const std::vector<ModelPoint>& points() const { return points_; }

 private:
  std::vector<ModelPoint> points_;
};

// " at t = 0.5: y = (1, -2), y(t - tau) = (0.5, 0)": a point of the model in a message.
std::string describe_point(const ModelPoint& point);

// Formats a double with the fewest digits that read back as the same double (messages,
// metadata, values passed on as text).
std::string format_number(double value);
// Formats a double with `significant_digits` digits (printf's %g): a tolerance in a message
// (3), a coordinate in a plot script (10). The one home of number formatting with format_number.
std::string format_number(double value, int significant_digits);
// A printf format with up to four doubles (%g, %.3g, %.0f for a count): a note's sentence with its
// numbers, of any length (sized by a first call; a fixed buffer once cut the longest note short).
std::string format_text(const char* format, double a, double b = 0, double c = 0, double d = 0);
// "a + bi" / "a - bi" with format_number's parts: a complex number in a message.
std::string format_complex(std::complex<double> value);

// Throws BadInput("`name = value`: must be finite") when value is NaN or infinite.
void require_finite(const char* name, double value);
// Throws BadInput("`name = value`: must be > 0") unless value > 0 (and finite).
void require_positive(const char* name, double value);
// Throws BadInput("`name = value`: must be >= 0") unless value >= 0 (and finite).
void require_nonnegative(const char* name, double value);

}  // namespace delayspec
