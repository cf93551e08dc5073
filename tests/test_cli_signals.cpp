// Stopping a command: SIGINT, SIGTERM and SIGHUP during a sweep or outside one end it with 128 + the signal and
// leave no output or temporary; an output that cannot be written fails before a sweep of minutes starts.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "cli_support.hpp"
#include "cli_test_support.hpp"
#include "test_support.hpp"
#include "scratch_path.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

TEST_F(Cli, InterruptStopsCleanlyWithoutOutput) {
  // a sweep of 10^7 steps runs for minutes; SIGINT after half a second
  std::string scene = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  scene.replace(scene.find("steps: 180"), 10, "steps: 10000000");
  fs::path p = write("long.yaml", scene);
  const auto t0 = std::chrono::steady_clock::now();
  Result r =
      run_prefixed("timeout --preserve-status -s INT 0.5 ", "run " + p.string() + " -o " + (dir_ / "out.csv").string());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.code, 130) << r.err;
  EXPECT_LT(seconds, 5.0);
  EXPECT_NE(r.err.find("interrupted (SIGINT); no output written"), std::string::npos) << r.err;
  EXPECT_EQ(files(), (std::vector<std::string>{"long.yaml", "stderr.txt", "stdout.txt"}));
}

// A scene that sweeps for minutes (10^7 steps of the crank-slider).
std::string long_scene() {
  std::string scene = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  scene.replace(scene.find("steps: 180"), 10, "steps: 10000000");
  return scene;
}

// SIGTERM and SIGHUP stop a run as SIGINT does: exit 128 + the signal, one line naming it, no output and no
// temporary left (the CSV and the summary).
TEST_F(Cli, TermAndHangupStopARunLikeInterrupt) {
  const fs::path p = write("long.yaml", long_scene());
  for (const auto& [sig, status] : {std::pair<std::string, int>{"TERM", 143}, {"HUP", 129}, {"INT", 130}}) {
    const auto t0 = std::chrono::steady_clock::now();
    Result r = run_prefixed(
        "timeout --preserve-status -s " + sig + " 0.5 ",
        "run " + p.string() + " -o " + (dir_ / "out.csv").string() + " --summary " + (dir_ / "s.json").string());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.code, status) << sig << ": " << r.err;
    EXPECT_LT(seconds, 5.0) << sig;
    EXPECT_TRUE(one_phiq_line(r.err)) << sig;
    EXPECT_NE(r.err.find("long.yaml: interrupted (SIG" + sig + "); no output written"), std::string::npos) << r.err;
    EXPECT_EQ(files(), (std::vector<std::string>{"long.yaml", "stderr.txt", "stdout.txt"})) << sig;
  }
}

// A signal while no sweep runs (here: waiting for a FIFO's reader, with another output's temporary already
// created) ends the command at once, removing the temporaries.
TEST_F(Cli, SignalOutsideTheSweepRemovesTheTemporaries) {
  const fs::path fifo = dir_ / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  Result r = run_prefixed("timeout --preserve-status -s TERM 0.5 ",
                          "sweep-accuracy " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " -o " +
                              (dir_ / "acc.csv").string() + " --json " + fifo.string());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_EQ(r.code, 143) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("interrupted (SIGTERM); no output written"), std::string::npos) << r.err;
  EXPECT_EQ(files(), (std::vector<std::string>{"fifo", "stderr.txt", "stdout.txt"}));
}

// Every output is created before the sweep: an unusable --summary fails at once (exit 3, the sweep of minutes not
// run) and no file appears, nor is an existing one replaced; the same for sweep-accuracy's two outputs.
TEST_F(Cli, UnwritableOutputsFailBeforeTheSweepAndNoneAppears) {
  const fs::path p = write("long.yaml", long_scene());
  write("a.csv", "previous\n");
  const auto t0 = std::chrono::steady_clock::now();
  Result r = run("run " + p.string() + " -o " + (dir_ / "a.csv").string() + " --summary " +
                 (dir_ / "nodir" / "s.json").string());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("nodir/s.json: cannot write: No such file or directory"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir_ / "a.csv"), "previous\n");
  r = run("run " + p.string() + " -o " + dir_.string());  // a directory
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find(": cannot write: is a directory"), std::string::npos) << r.err;
  r = run("sweep-accuracy " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " --repeat 1 -o " +
          (dir_ / "acc.csv").string() + " --json " + (dir_ / "nodir" / "acc.json").string());
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_EQ(files(), (std::vector<std::string>{"a.csv", "long.yaml", "stderr.txt", "stdout.txt"}));
}

// A command that has printed its error line and is leaving when SIGTERM comes (under mpirun: the other ranks are
// terminated when one leaves with an error, and this one with them) exits with its own status and no second line.
// In a child process, which installs phiq's signal thread as the command does.
TEST(Interrupts, ASignalAfterTheErrorLineAddsNoSecondLineAndKeepsItsStatus) {
  const fs::path err = phiq::test::scratch_path("phiq_settle").concat(".txt");
  auto child = [&](bool settled) {
    const pid_t pid = ::fork();
    if (pid == 0) {
      const int fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, STDERR_FILENO);
      phiq::tools::start_interrupts();
      if (settled) phiq::tools::settle_interrupts(2);  // what fail() does after its line
      ::kill(::getpid(), SIGTERM);
      for (;;) ::pause();
    }
    int st = 0;
    ::waitpid(pid, &st, 0);
    return std::pair{WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(err)};
  };
  const auto [plain_code, plain_err] = child(false);
  EXPECT_EQ(plain_code, 143);
  EXPECT_NE(plain_err.find("interrupted (SIGTERM)"), std::string::npos) << plain_err;
  const auto [code, text] = child(true);
  EXPECT_EQ(code, 2);
  EXPECT_EQ(text, "");
  fs::remove(err);
}

}  // namespace
