#pragma once
// Multipliers: eigenvalues of a monodromy, and the one order every result lists them in.
#include <complex>
#include <vector>

namespace delayspec {

using Multipliers = std::vector<std::complex<double>>;

// Sorts by modulus, largest first (ties: by real part, then imaginary part descending, so
// complex pairs come + then -).
void sort_by_modulus(Multipliers& values);

}  // namespace delayspec
