#include "delayspec/errors.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

namespace delayspec {

std::string format_number(double value) {
  // The shortest text that reads back as the same double ("0.7", not "0.69999999999999996";
  // "10", not "1e+01"): exact, and what a person would have typed.
  char buffer[64];
  std::string best;
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    const bool exact = !std::isfinite(value) || std::strtod(buffer, nullptr) == value;
    if (exact && (best.empty() || std::string(buffer).size() < best.size())) best = buffer;
  }
  return best;
}

std::string format_number(double value, int significant_digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", significant_digits, value);
  return buffer;
}

NonFiniteStep::NonFiniteStep(const std::string& what, std::vector<ModelPoint> points)
    : NumericalFailure(what), points_(std::move(points)) {}

std::string describe_point(const ModelPoint& point) {
  auto vector = [](const std::vector<double>& v) {
    std::string text = "(";
    for (size_t i = 0; i < v.size(); ++i) {
      if (i > 0) text += ", ";
      text += format_number(v[i]);
    }
    return text + ")";
  };
  return " at t = " + format_number(point.t) + ": y = " + vector(point.y) + ", y(t - tau) = " + vector(point.y_tau);
}

void require_finite(const char* name, double value) {
  if (!std::isfinite(value))
    throw BadInput(std::string("`") + name + " = " + format_number(value) + "`: must be a finite number");
}

void require_positive(const char* name, double value) {
  require_finite(name, value);
  if (!(value > 0)) throw BadInput(std::string("`") + name + " = " + format_number(value) + "`: must be > 0");
}

void require_nonnegative(const char* name, double value) {
  require_finite(name, value);
  if (!(value >= 0)) throw BadInput(std::string("`") + name + " = " + format_number(value) + "`: must be >= 0");
}

}  // namespace delayspec
