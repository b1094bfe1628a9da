// The built-in dimensions of Monodromy<D>, compiled once (the bodies are in monodromy.hpp).
#include "delayspec/monodromy.hpp"

namespace delayspec {

template class Monodromy<1>;
template class Monodromy<2>;

}  // namespace delayspec
