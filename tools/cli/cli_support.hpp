// What the phiq commands share about their effects on the outside (tools/README.md, "Exit status and errors"):
// the signals that stop them, their output files (created before the work, committed together at the end), the
// checks of output paths against the inputs and against each other, and standard output's errors.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "atomic_file.hpp"
#include "phiq/types.hpp"  // Error, which OutputSet throws

namespace phiq::tools {

// SIGINT, SIGTERM and SIGHUP. start_interrupts(), first thing in main() (before any thread exists), blocks them in
// every thread and waits for them in a thread of its own, which acts on the current mode:
//  - by default, it removes the temporaries of every live OutputSet, prints "phiq: SUBJECT: interrupted (SIGTERM)
//    SUFFIX" and exits with 128 + the signal (130 for SIGINT, 143 for SIGTERM, 129 for SIGHUP);
//  - while a StopOnSignal lives (a sweep that polls stop_flag()), the first signal only sets the flag: the sweep
//    stops at its next row and the command cleans up and reports (interrupt_message(), interrupt_exit_status()); a
//    second signal exits at once, as by default;
//  - once an OutputSet is committed, a signal exits with 128 + the signal without a word (the outputs are complete).
// Without start_interrupts() (the library's users, the tests) nothing is installed and stop_flag() stays false.
void start_interrupts();
// What the message names ("SCENE", "sweep-accuracy: SCENE") and what it adds ("; no output written").
void set_interrupt_subject(const std::string& subject, const std::string& suffix = "");
// "SIGINT", "SIGTERM", "SIGHUP" (what messages call a signal).
const char* signal_name(int sig);
// A second signal (or one outside a StopOnSignal) exits without a word: a worker rank of an MPI batch, which
// writes no file and leaves the talking to rank 0.
void quiet_interrupts();
// The command has printed its error line and is leaving with `status`: a signal from now on removes the temporaries
// and exits with that status without a word. Under mpirun, the ranks still running when one leaves with an error
// are sent SIGTERM, this one too while it finishes; its one line stays the only one. fail() calls it.
void settle_interrupts(int status);
// Whether a signal came (or, in a StopOnSignal, asked the sweep to stop), and which one.
const std::atomic<bool>& stop_flag();
int interrupt_signal();           // 0 when none
int interrupt_exit_status();      // 128 + interrupt_signal()
std::string interrupt_message();  // "interrupted (SIGTERM)"

// The mode in which a signal asks the running sweep to stop (stop_flag()) instead of exiting at once.
class StopOnSignal {
 public:
  StopOnSignal();
  ~StopOnSignal();
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;
};

// The output files of one command: all created before the work (so that an unwritable path fails at once, and a
// signal removes them), all committed together at the end, or none. `phiq batch` instead commits each case's file
// as the case completes (commit_one), so that an interrupted batch keeps the cases it finished. Thread-safe for
// add, commit_one and drop of different files (the cases of a batch run concurrently).
class OutputSet {
 public:
  OutputSet() = default;
  ~OutputSet();  // removes the temporaries of files not committed
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // Creates the output at `path` now (AtomicOutputFile: a temporary in its target's directory, or a device / FIFO
  // opened in place). Throws phiq::Error "PATH: cannot write: REASON".
  AtomicOutputFile& add(const std::string& path, AtomicOutputFile::Hold hold = AtomicOutputFile::Hold::kOpen);
  // Finishes every file (flush, fsync), then renames them all onto their targets under the lock of their
  // directories (DirectoryLock: two commands writing the same pair commit one after the other, so the pair is
  // one command's); no file is renamed unless every one was written. Afterwards signals exit quietly. Throws
  // phiq::Error (the set's temporaries are then removed).
  void commit();
  // Finishes and renames one file of the set onto its target now, under its directory's lock (a batch's case).
  // Throws phiq::Error (the file's temporary is then removed with the set, or by drop()).
  void commit_one(AtomicOutputFile& file);
  // Removes one file of the set (and its temporary, if not committed) now.
  void drop(AtomicOutputFile& file);

 private:
  std::vector<std::unique_ptr<AtomicOutputFile>> files_;
};

// An output path of the command line with what it is ("-o", "--summary", "the scene").
struct NamedPath {
  std::string what, path;
};
// The one-line reason when an output would overwrite an input (`phiq run S.yaml -o S.yaml`) or two outputs are the
// same file (`-o X --summary X`); several outputs may go to one device or FIFO (`/dev/null`). Empty paths are
// refused too. Nothing when the paths are fine.
std::optional<std::string> output_clash(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs);

// Makes sure descriptors 0, 1 and 2 are open, so that no file the command opens takes their place (with standard
// output closed, a temporary file would become "standard output"). A closed one is replaced by /dev/null opened
// read-only: writing to it fails, and the failure is reported. Call first in main().
void ensure_standard_descriptors();
// Standard output was closed when the command started.
bool stdout_was_closed();
// Flushes std::cout and stdout; the one-line reason when anything written to standard output was lost
// ("standard output: cannot write: No space left on device"), else nothing.
std::optional<std::string> stdout_error();

}  // namespace phiq::tools
