// phiq — command line front end: the subcommands wired to CLI11 (each declared with its options in its own file,
// commands.hpp), and CLI11's errors made one line. See tools/README.md.
//
// Exit status: 0 success; 1 the mechanism could not be solved (the message names step, time and constraints), or
// `compare` found a difference; 2 bad input (scene, CSV or command line); 3 an output (a file, standard output)
// could not be written; 4 `clearance --fail-on-interference` found parts interfering; 128 + the signal when
// interrupted (130 SIGINT, 143 SIGTERM, 129 SIGHUP). An exception no command caught is one of these too (out of
// memory, an error of the file system, an internal error): exit 1, or 3 for the file system's, never a status the
// table of tools/README.md does not list.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <new>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "phiq/phiq.hpp"

namespace {

// "FILE: " for the first positional argument that is a file (SCENE, MODEL, RESULT), else "": what names a run that
// failed outside any step.
std::string first_positional(const phiq::tools::Command* c) {
  if (c == nullptr) return "";
  for (const CLI::Option* o : c->subcommand->get_options())
    if (o->get_positional() && !o->results().empty()) {
      std::error_code ec;  // a file, not generate's KIND
      if (std::filesystem::is_regular_file(o->results().front(), ec))
        return phiq::tools::printable(o->results().front()) + ": ";
    }
  return "";
}

// The line of a thread that could not start (std::thread's EAGAIN, TBB's "pthread_create has failed").
std::string no_thread(const phiq::tools::Command* c) {
  return first_positional(c) + "out of memory: cannot start a thread; no output written";
}

int run_command(int argc, char** argv) {
  using namespace phiq::tools;
  // before anything opens a file or starts a thread
  ensure_standard_descriptors();
  try {
    start_interrupts();
  } catch (const std::system_error&) {  // no thread can start: an address-space limit (ulimit -v), or no memory
    return fail("out of memory: cannot start a thread; nothing written", 1);
  }
  phiq::silence_hdf5_errors();  // phiq says what went wrong with an HDF5 file, in one line

  CLI::App app{"phiq: sparse, large-scale multibody kinematics"};
  // every format another program parses, with its version: a harness checks the ones it reads
  app.set_version_flag("--version", std::string("phiq ") + phiq::version() + " (scene format " +
                                        std::to_string(phiq::kSceneFormat) + ", CSV format " +
                                        std::to_string(phiq::kCsvFormat) + ", HDF5 results format " +
                                        std::to_string(phiq::kHdf5Format) + ", check --json format " +
                                        std::to_string(phiq::kCheckJsonFormat) + ", run --summary format " +
                                        std::to_string(phiq::kRunSummaryFormat) + ", batch --summary format " +
                                        std::to_string(phiq::kBatchSummaryFormat) + ", sweep-accuracy --json format " +
                                        std::to_string(phiq::kSweepAccuracyJsonFormat) + ", compare --json format " +
                                        std::to_string(phiq::kCompareJsonFormat) + ", tolerance CSV format " +
                                        std::to_string(phiq::kToleranceCsvFormat) + ", tolerance --summary format " +
                                        std::to_string(phiq::kToleranceSummaryFormat) + ", clearance HDF5 format " +
                                        std::to_string(phiq::kClearanceHdf5Format) + ", clearance --summary format " +
                                        std::to_string(phiq::kClearanceSummaryFormat) + ")");
  app.require_subcommand(1);
  const std::vector<Command> commands{
      register_run(app),      register_generate(app),       register_convert(app),   register_batch(app),
      register_assemble(app), register_check(app),          register_plot(app),      register_animate(app),
      register_compare(app),  register_sweep_accuracy(app), register_tolerance(app), register_clearance(app),
      register_modes(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return with_stdout_checked(app.exit(e));  // --help, --version
    return usage_error(app, argc, argv, e);
  }
  const Command* ran = nullptr;
  try {
    for (const Command& c : commands)
      if (*c.subcommand) return (ran = &c)->run();
  } catch (const std::bad_alloc&) {
    // named by the command's first file (its SCENE, MODEL or RESULT): the outputs, written atomically, are gone
    return fail(first_positional(ran) + "out of memory; no output written", 1);
  } catch (const std::filesystem::filesystem_error& e) {
    return fail(e.what(), 3);
  } catch (const std::system_error& e) {  // a thread that could not start (EAGAIN) is memory too
    if (e.code() == std::errc::resource_unavailable_try_again) return fail(no_thread(ran), 1);
    return fail(std::string("internal error: ") + e.what(), 1);
  } catch (const std::exception& e) {
    // TBB reports a worker it could not create as a std::runtime_error ("pthread_create has failed: …")
    if (std::string_view(e.what()).find("pthread_create") != std::string_view::npos) return fail(no_thread(ran), 1);
    return fail(std::string("internal error: ") + e.what(), 1);
  }
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  const int status = run_command(argc, argv);
  // An HDF5 file whose close failed (a full disk) would crash HDF5's exit handler, which closes it again: the
  // error is reported and every output committed or removed by now, so the process ends without the handlers.
  if (phiq::hdf5_file_left_open()) {
    std::fflush(nullptr);
    std::_Exit(status);
  }
  return status;
}
