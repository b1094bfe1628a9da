// LeakSanitizer's built-in suppressions for the programs of a DELAYSPEC_SANITIZE build
// (CMakeLists.txt adds this file to them; LSan calls the hook at start-up).
//
// CLN, GiNaC's number library (equation models, src/cli/equation_*), allocates tables in its
// static initialisers and never frees them: 26 bytes reported at exit of any program that links
// it, before a single equation is read. Not delayspec's memory, and not a leak that grows.
extern "C" const char* __lsan_default_suppressions() { return "leak:libcln.so\n"; }
