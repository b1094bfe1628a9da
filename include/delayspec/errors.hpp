#pragma once
// The two error channels of delayspec (see docs/design.md, "Bad input"):
//  * BadInput: the caller asked for something invalid (a key, a value, a size).
//    The message names the offending key or value and the rule it broke.
//    The CLI maps it to exit status 2.
//  * NumericalFailure: the input was valid but a numerical method did not reach
//    its goal (Newton, Krylov, orbit search). The message carries the numbers
//    (iterations, residual). The CLI maps it to exit status 3.
#include <stdexcept>
#include <string>

namespace delayspec {

class BadInput : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

class NumericalFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Formats a double with the fewest digits that read back as the same double (messages,
// metadata, values passed on as text).
std::string format_number(double value);

// Throws BadInput("`name = value`: must be finite") when value is NaN or infinite.
void require_finite(const char* name, double value);
// Throws BadInput("`name = value`: must be > 0") unless value > 0 (and finite).
void require_positive(const char* name, double value);
// Throws BadInput("`name = value`: must be >= 0") unless value >= 0 (and finite).
void require_nonnegative(const char* name, double value);

}  // namespace delayspec
