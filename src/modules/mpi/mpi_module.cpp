// The entry point of libdelayspec_mpi (mpi_module.hpp): the only symbol the program looks up.
#include "modules/mpi/mpi_module.hpp"

#include <type_traits>

#include "delayspec/version.hpp"
#include "modules/mpi/mpi_parts.hpp"

namespace {

const delayspec::cli::MpiModule module_table{DELAYSPEC_VERSION " " DELAYSPEC_REVISION,
                                             &delayspec::cli::mpi::start,
                                             &delayspec::cli::mpi::finish,
                                             &delayspec::cli::mpi::enter_point_loop,
                                             &delayspec::cli::mpi::lead_points,
                                             &delayspec::cli::mpi::worker_points};

}  // namespace

// The declaration checks the entry's type against the one load_module casts to.
extern "C" __attribute__((visibility("default"))) const delayspec::cli::MpiModule* delayspec_mpi_module();
static_assert(std::is_same_v<decltype(&delayspec_mpi_module), const delayspec::cli::MpiModule* (*)()>);

const delayspec::cli::MpiModule* delayspec_mpi_module() { return &module_table; }
