#pragma once
// The classic dense discretisations' method and result (classic_discretisation.hpp), apart from
// their templates: the scene layer names them without compiling the discretisations, which
// libdelayspec_models compiles for the built-in models (src/modules/models/classic_models.cpp).
#include "delayspec/multipliers.hpp"

namespace delayspec {

enum class ClassicMethod { sdm0, fdm1 };

struct ClassicResult {
  Multipliers multipliers;  // the nev largest in modulus
  long dimension = 0;       // n = d + m r
  double seconds = 0;       // coefficients, product and eigenvalues
};

}  // namespace delayspec
