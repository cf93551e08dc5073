// Linked into every executable of a PHIQ_SANITIZE build (CMake adds it), so that the settings hold for every run,
// including ctest's test discovery.
//
// LeakSanitizer, third-party only:
// - CLN (GiNaC's number library, Debian's libcln6) keeps a few bytes from its static initialisation.
// - GiNaC leaks its temporaries when its own differentiation throws (e.g. d/dy 0^y reaches log(0); found by the
//   fuzzer, tests/fuzz/regressions/ginac_throws_while_differentiating.yaml). phiq catches that exception and reports
//   a one-line error; the bytes are lost inside libginac. phiq holds GiNaC objects only as reference-counted values
//   on the stack while compiling, so a phiq leak would not hide behind this.
// - HDF5 1.10 keeps the blocks of metadata it failed to load (a corrupt file's wrong checksum), and says so at exit
//   when its error printing is on ("infinite loop closing library"); phiq closes every identifier it opened.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libcln.so\nleak:libginac.so\nleak:libhdf5_serial.so\n";
}
// UndefinedBehaviorSanitizer: print where.
extern "C" const char* __ubsan_default_options() { return "print_stacktrace=1"; }
// Do not list the suppression on stderr at exit: the CLI tests check that an error is exactly one line.
extern "C" const char* __lsan_default_options() { return "print_suppressions=0"; }
