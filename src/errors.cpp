#include "delayspec/errors.hpp"

#include <cmath>
#include <cstdio>

namespace delayspec {

std::string format_number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

void require_finite(const char* name, double value) {
  if (!std::isfinite(value))
    throw BadInput(std::string("`") + name + " = " + format_number(value) + "`: must be a finite number");
}

void require_positive(const char* name, double value) {
  require_finite(name, value);
  if (!(value > 0))
    throw BadInput(std::string("`") + name + " = " + format_number(value) + "`: must be > 0");
}

void require_nonnegative(const char* name, double value) {
  require_finite(name, value);
  if (!(value >= 0))
    throw BadInput(std::string("`") + name + " = " + format_number(value) + "`: must be >= 0");
}

}  // namespace delayspec
