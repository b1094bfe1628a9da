#include "delayspec/multipliers.hpp"

#include <algorithm>

namespace delayspec {

void sort_by_modulus(Multipliers& values) {
  std::stable_sort(values.begin(), values.end(), [](const auto& a, const auto& b) {
    const double ma = std::abs(a), mb = std::abs(b);
    if (ma != mb) return ma > mb;
    if (a.real() != b.real()) return a.real() > b.real();
    return a.imag() > b.imag();
  });
}

}  // namespace delayspec
