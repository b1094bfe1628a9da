#pragma once
// Where the libdelayspec of this process lies: what a compiled equation model links against
// (equation_plugin.cpp), and the directory of the modules delayspec loads on first use
// (equations_module_loader.hpp). The same for the program, the tests and the Python module, in
// the build tree and installed (wherever the prefix is now).
#include <filesystem>

namespace delayspec::cli {

// The library's file, canonical (symbolic links resolved). BadInput if dladdr cannot tell.
std::filesystem::path running_library();

}  // namespace delayspec::cli
