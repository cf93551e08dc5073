// Reading phiq's command line: CLI11 validators whose messages are one readable line, the thread count capped to
// the cores, and CLI11's own errors rewritten as one line. Shared by every command's options (main.cpp, the
// register_* functions of commands.hpp).
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace phiq::tools {

// A whole number from lo to hi; `lo_means` explains the lowest value ("0: all cores").
CLI::Validator whole_number(long long lo, long long hi, const std::string& lo_means = "");
// A whole number of any size the option's type holds (its range is checked by the command).
CLI::Validator any_whole_number();
// A number (decimal or exponent form, an optional '+'); finite unless `allow_inf`, ≥ lo, ≤ hi.
CLI::Validator number(double lo, double hi, bool allow_inf, const std::string& what);
// Any finite number.
CLI::Validator any_number();
// One of the listed words.
CLI::Validator one_of(const std::vector<std::string>& words);
// An output path where "-" is standard output, as in most tools (a file named "-" is still `./-`); an empty one is
// refused (it used to mean standard output, silently), `instead` saying what to give. `spooled`: as if the option
// were absent (run, assemble: the CSV is spooled and written whole once the solve succeeded); otherwise
// /dev/stdout, the descriptor itself (written in place, as a pipe or a terminal is).
CLI::Validator output_path(const std::string& instead, bool spooled);
// The thread counts of --threads: 0 (all cores) to 1 000 000.
CLI::Validator thread_count();

// More threads than the cores TBB runs (tbb::info::default_concurrency(), which honours the process's affinity
// mask) would not run at once: TBB warns (several lines) and keeps its limit while the summary would claim the
// number asked for. Capped, with a note (unless `quiet`).
int cap_threads(const std::string& command, int threads, bool quiet);

// CLI11's error made one line: "phiq: <command>: <what>" on standard error; returns 2 (a command-line error).
int usage_error(CLI::App& app, int argc, char** argv, const CLI::ParseError& e);

}  // namespace phiq::tools
