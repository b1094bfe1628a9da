#pragma once
// Text from a scene or results file in a message: printable ASCII as itself, every other byte as
// \xNN, so that no byte read from an untrusted file reaches a terminal raw (escape sequences).
#include <string>

namespace delayspec {

std::string printable(const std::string& text);

}  // namespace delayspec
