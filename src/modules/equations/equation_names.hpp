#pragma once
// The names a scene's [equations] table gives (states, parameters, history keys): what a name may
// be. The names never reach the generated C++ (every name becomes a generated symbol), so these
// rules are defence in depth and keep the expressions unambiguous: a plain identifier, not a C++
// keyword or reserved identifier, not a name the expressions already give a meaning (t, pi, the
// functions, GiNaC's literals), not ending in `_tau` (NAME_tau is the delayed state).
#include <string>
#include <vector>

#include "delayspec/printable.hpp"  // printable: a name in a message

namespace delayspec::cli {

// The elementary functions an expression may call (each of one argument), in the order docs list them.
const std::vector<std::string>& equation_functions();

// BadInput "`item`: ..." naming `name` and the rule it breaks, unless the name is allowed.
void check_equation_name(const std::string& item, const std::string& name);

}  // namespace delayspec::cli
