// LeakSanitizer's built-in suppressions for the programs of a DELAYSPEC_SANITIZE build
// (CMakeLists.txt adds this file to them; LSan calls the hook at start-up).
//
// CLN, GiNaC's number library (equation models: src/modules/equations, the module
// libdelayspec_equations), allocates tables in its static initialisers and never frees them: 26
// bytes reported at exit of any program that loads it (the tests link it), before a single
// equation is read. GiNaC itself keeps one 40-byte object it allocates on
// first use: the test suite, which prints a dozen models, leaks those 40 bytes once, as a single
// printed model does. Neither is delayspec's memory, and neither grows with use.
extern "C" const char* __lsan_default_suppressions() { return "leak:libcln.so\nleak:libginac.so\n"; }
