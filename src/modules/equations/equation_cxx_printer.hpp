#pragma once
// GiNaC expressions as C++ text that does not depend on the run.
//
// GiNaC keeps the operands of a sum or product in an order of hash values, which depend on
// symbol serial numbers and on addresses (they differ between runs and between two readings of
// one scene in one process): its printed text, and the rounding of the sum, would change from
// run to run, and so would the plugin's cache key. This printer is GiNaC's C source printing for
// doubles (print_csrc_double, which prints the functions) with its own printing of numbers
// (exactly: ratios of exact doubles, or 17 significant digits), sums and products (operands
// sorted by their text, a sum as a factor with a fixed sign) and powers (integer powers as
// products, sqrt, pow).
#include <string>

#include <ginac/ginac.h>

namespace delayspec::cli {

// C++ text of e, the same for the same expression in every run. Not thread-safe (GiNaC).
std::string cxx_text(const GiNaC::ex& e);

}  // namespace delayspec::cli
