// The entry point of libdelayspec_equations (equations_module.hpp): the only symbol the program
// looks up. The module's other symbols stay visible for the tests, which link it directly.
#include "modules/equations/equations_module.hpp"

#include <type_traits>

#include "delayspec/version.hpp"

namespace {

const delayspec::cli::EquationsModule module_table{DELAYSPEC_VERSION " " DELAYSPEC_REVISION,
                                                   &delayspec::cli::generate_equation_model};

}  // namespace

// The declaration checks the entry's type against the one load_module casts to.
extern "C" __attribute__((visibility("default"))) const delayspec::cli::EquationsModule* delayspec_equations_module();
static_assert(std::is_same_v<decltype(&delayspec_equations_module), const delayspec::cli::EquationsModule* (*)()>);

const delayspec::cli::EquationsModule* delayspec_equations_module() { return &module_table; }
