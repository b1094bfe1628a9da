#pragma once
// The period of a sequence of Poincare-section states (basin classification): the smallest
// p in 1..max_period with |S[j + p] - S[j]|_inf <= tolerance (1 + |S[j]|_inf) for every
// j = 0..max_period; 0 when there is none. Needs S.size() >= 2 max_period + 1.
#include <vector>

#include <Eigen/Core>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

inline int section_period(const std::vector<Eigen::VectorXd>& S, long max_period, double tolerance) {
  if (max_period < 1 || static_cast<long>(S.size()) < 2 * max_period + 1)
    throw BadInput("section_period: need 2 max_period + 1 = " + std::to_string(2 * max_period + 1) +
                   " section states, got " + std::to_string(S.size()));
  for (long p = 1; p <= max_period; ++p) {
    bool repeats = true;
    for (long j = 0; j <= max_period && repeats; ++j) {
      const double scale = 1 + S[j].lpNorm<Eigen::Infinity>();
      repeats = (S[j + p] - S[j]).lpNorm<Eigen::Infinity>() <= tolerance * scale;
    }
    if (repeats) return static_cast<int>(p);
  }
  return 0;
}

}  // namespace delayspec::cli
