// The command line itself: usage, help and version, and command-line errors as one `phiq: COMMAND: ...` line with
// readable ranges.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
namespace fs = std::filesystem;

TEST_F(Cli, UsageErrorsAndHelp) {
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("frobnicate x").code, 2);
  EXPECT_EQ(run("run").code, 2);
  Result h = run("run --help");
  EXPECT_EQ(h.code, 0);
  EXPECT_NE(h.out.find("--output"), std::string::npos);
  EXPECT_EQ(
      run("--version").out,
      "phiq 0.1.0 (scene format 1, CSV format 1, HDF5 results format 1, check --json format 1, run --summary "
      "format 2, batch --summary format 1, sweep-accuracy --json format 2, compare --json format 1, tolerance CSV "
      "format 1, tolerance --summary format 1, clearance HDF5 format 3, clearance --summary format 1)\n");
}

// Command-line errors are one line, "phiq: <command>: <what>", exit 2, with readable ranges.
TEST_F(Cli, CommandLineErrorsAreOneLineNamingTheCommand) {
  const std::string scene = phiq::test::model_path("seed/fourbar_natural.yaml");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run " + scene + " --threads -1",
       "phiq: run: --threads: expected a whole number from 0 (all cores) to 1000000, got '-1'"},
      {"run " + scene + " --threads abc", "phiq: run: --threads: expected a whole number"},
      {"run " + scene + " --memory -1", "phiq: run: --memory: expected a number of GB from 0"},
      {"run " + scene + " --memory nan", "phiq: run: --memory: expected a number of GB from 0"},
      {"run " + scene + " --frobnicate", "phiq: run: unknown option --frobnicate"},
      {"run " + scene + " " + scene, "phiq: run: unexpected argument"},
      {"run " + scene + " -o", "phiq: run: --output: a value is required"},
      {"run " + scene + " --progress sometimes",
       "phiq: run: --progress: expected auto, always or never, got 'sometimes'"},
      {"run", "phiq: run: scene is required"},
      {"frobnicate " + scene, "phiq: unknown command 'frobnicate' (commands: run, "},
      {"", "phiq: a command is required (run, "},
      {"--frobnicate", "phiq: unknown option --frobnicate"},
      {"plot " + scene + " x.csv -o x.svg --positions 0",
       "phiq: plot: --positions: expected a whole number from 1 to 50, got '0'"},
      {"batch " + scene + " x.csv -o out --threads -2", "phiq: batch: --threads: "},
      {"compare a.csv b.csv --rtol nan", "phiq: compare: --rtol: expected a number >= 0"},
      {"compare a.csv b.csv --atol -1", "phiq: compare: --atol: "},
      {"check " + scene + " --time inf", "phiq: check: --time: expected a finite number, got 'inf'"},
      {"check " + scene + " --time nan", "phiq: check: --time: expected a finite number, got 'nan'"},
      {"generate nfourbar many -o x.yaml", "phiq: generate: N: expected a whole number, got 'many'"},
      {"sweep-accuracy " + scene + " --repeat x",
       "phiq: sweep-accuracy: --repeat: expected a whole number from 1 to 1000"},
  };
  for (const auto& [args, says] : cases) {
    Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
    EXPECT_TRUE(one_phiq_line(r.err)) << args;
    EXPECT_EQ(r.err.rfind(says, 0), 0u) << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("1797693134862315"), std::string::npos) << r.err;  // no 309-digit bound
    EXPECT_TRUE(r.out.empty()) << args;
  }
  EXPECT_FALSE(fs::exists("x.yaml"));
}

}  // namespace
