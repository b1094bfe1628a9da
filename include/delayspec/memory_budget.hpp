#pragma once
// Sizes bounded before allocation: a run whose arrays cannot fit is refused with BadInput naming
// what asked for them, instead of being killed by the kernel half-way (exit 137, no message) or
// failing inside a library with a misleading message.
//
// The budget is what this process may still allocate: the smaller of the machine's physical
// memory and the address space left under `ulimit -v` (RLIMIT_AS minus what is mapped now).
// Estimates compared against it are lower bounds of what the computation will hold at once (the
// arrays it cannot do without), so a refused run could not have finished; a run that passes
// may still need more (factor fill-in, temporaries) and then ends in "out of memory", exit 3.
#include <string>

namespace delayspec {

// Bytes this process may still allocate (header comment); at least 1.
double memory_budget_bytes();

// BadInput "<what> needs about X GB (<how>), more than the Y GB this process may use (...)"
// when bytes > budget. what: the keys and values that ask for it, e.g. "`period_guess = 1e6`
// (N = 200: 30303030 steps per period)"; how: the arrays counted.
void require_memory(double bytes, const std::string& what, const std::string& how);
// The same against a given budget (tests).
void require_memory(double bytes, const std::string& what, const std::string& how, double budget);

}  // namespace delayspec
