#pragma once
// GiNaC expressions as C++ text that does not depend on the run.
//
// GiNaC keeps the operands of a sum or product in an order of hash values, which depend on
// symbol serial numbers and on addresses (they differ between runs and between two readings of
// one scene in one process): its printed text, and the rounding of the sum, would change from
// run to run, and so would the plugin's cache key. This printer is GiNaC's C source printing for
// doubles (print_csrc_double: numbers as ratios of doubles or with 17 significant digits, which
// read back as the same double; powers, functions) with sums and products printed with their
// operands sorted by their text.
#include <string>

#include <ginac/ginac.h>

namespace delayspec::cli {

// C++ text of e, the same for the same expression in every run. Not thread-safe (GiNaC).
std::string cxx_text(const GiNaC::ex& e);

}  // namespace delayspec::cli
