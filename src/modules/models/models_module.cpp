// The entry point of libdelayspec_models (models_module.hpp): the only symbol the program looks
// up. The explicit instantiations of the other units stay visible for the tests and the package's
// users (delayspec::models), which link the module directly.
#include "modules/models/models_module.hpp"

#include <type_traits>

#include "delayspec/builtin_analyses.hpp"
#include "delayspec/version.hpp"

namespace {

using namespace delayspec;

const cli::ModelsModule module_table{DELAYSPEC_VERSION " " DELAYSPEC_REVISION,
                                     &builtin_analyses<LinearModel>,
                                     &builtin_analyses<MathieuModel>,
                                     &builtin_analyses<MackeyGlassModel>,
                                     &builtin_analyses<MillingModel>,
                                     &builtin_analyses<VariablePitchMillingModel>,
                                     &cli::classic_multipliers_of};

}  // namespace

// The declaration checks the entry's type against the one load_module casts to.
extern "C" __attribute__((visibility("default"))) const delayspec::cli::ModelsModule* delayspec_models_module();
static_assert(std::is_same_v<decltype(&delayspec_models_module), const delayspec::cli::ModelsModule* (*)()>);

const delayspec::cli::ModelsModule* delayspec_models_module() { return &module_table; }
