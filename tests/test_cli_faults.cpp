// Faults a hostile-input case (tests/hostile/) cannot express, because they need a second process or a signal at a
// chosen moment: kill -9 in the middle of a run leaves no temporary; a commit waits for the lock of its directory,
// so that two runs writing the same CSV and summary leave one run's pair; an interrupted batch keeps the cases it
// finished. Each runs in a few seconds.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

// The crank-slider with `steps` steps: 10^7 sweep for minutes.
std::string crank_slider_text(long steps) {
  std::string scene = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  scene.replace(scene.find("steps: 180"), 10, "steps: " + std::to_string(steps));
  return scene;
}

// Starts `phiq ARGS` in `dir` (stdout and stderr to files there); returns its PID.
pid_t spawn(const fs::path& dir, const std::string& args, const std::string& tag) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string cmd = "cd '" + dir.string() + "' && exec " + std::string(PHIQ_CLI) + " " + args + " >" + tag +
                            ".out 2>" + tag + ".err";
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

int wait_status(pid_t pid) {
  int st = 0;
  ::waitpid(pid, &st, 0);
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

// kill -9 cannot be caught: the temporary must have no name while it is written (O_TMPFILE), so that nothing is
// left however the process ends; an existing output stays as it was.
TEST_F(Cli, KillNineInTheMiddleOfARunLeavesNoTemporary) {
  write("long.yaml", crank_slider_text(10000000));
  write("out.csv", "t,old\n0,0\n");
  const pid_t pid = spawn(dir_, "run long.yaml -o out.csv --summary s.json", "run");
  std::this_thread::sleep_for(700ms);  // loaded and sweeping, rows written to the temporary
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  EXPECT_EQ(wait_status(pid), 128 + SIGKILL);
  EXPECT_EQ(files(), (std::vector<std::string>{"long.yaml", "out.csv", "run.err", "run.out"}));
  EXPECT_EQ(slurp(dir_ / "out.csv"), "t,old\n0,0\n");
}

// Outputs are renamed onto their targets under the lock of their directory: while another process holds it, a
// finished run waits, with nothing published; once it is released, both files appear.
TEST_F(Cli, ACommitWaitsForTheLockOfItsDirectory) {
  write("s.yaml", crank_slider_text(36));
  const int dfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);  // (not inherited by phiq)
  ASSERT_GE(dfd, 0);
  ASSERT_EQ(::flock(dfd, LOCK_EX), 0);
  const pid_t pid = spawn(dir_, "run -q s.yaml -o out.csv --summary s.json", "run");
  std::this_thread::sleep_for(1500ms);  // the sweep of 36 steps takes milliseconds
  EXPECT_FALSE(fs::exists(dir_ / "out.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "s.json"));
  ::close(dfd);  // releases the lock
  EXPECT_EQ(wait_status(pid), 0) << slurp(dir_ / "run.err");
  EXPECT_TRUE(fs::exists(dir_ / "out.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "s.json"));
}

// Two runs of different scenes writing the same CSV and summary at the same time: whatever the order, the CSV and
// the summary that remain are one run's (the summary names its scene; the CSV's row count is that scene's).
TEST_F(Cli, ConcurrentWritersOfOnePairLeaveOneWritersPair) {
  write("a.yaml", crank_slider_text(2000));
  write("b.yaml", crank_slider_text(2001));
  for (int round = 0; round < 6; ++round) {
    const pid_t a = spawn(dir_, "run -q a.yaml -o out.csv --summary s.json", "a");
    const pid_t b = spawn(dir_, "run -q b.yaml -o out.csv --summary s.json", "b");
    EXPECT_EQ(wait_status(a), 0) << slurp(dir_ / "a.err");
    EXPECT_EQ(wait_status(b), 0) << slurp(dir_ / "b.err");
    const std::string csv = slurp(dir_ / "out.csv"), summary = slurp(dir_ / "s.json");
    const long rows = std::count(csv.begin(), csv.end(), '\n') - 1;
    const bool from_a = summary.find("\"scene\": \"a.yaml\"") != std::string::npos;
    EXPECT_EQ(rows, from_a ? 2001 : 2002)
        << "round " << round << ": the summary of " << (from_a ? "a" : "b") << " with a CSV of " << rows << " rows";
  }
}

// A batch interrupted after some cases completed keeps their files (each is committed when its case completes)
// and says how many; the cases still running leave nothing. The signal comes once the first case's file is there
// (not after a fixed time, which a loaded machine or a sanitizer build may not reach a case in).
TEST_F(Cli, AnInterruptedBatchKeepsTheCasesItFinished) {
  write("s.yaml", crank_slider_text(100000));  // a few tenths of a second a case
  std::string cases = "L2\n";
  for (int k = 0; k < 40; ++k) cases += "0.3\n";
  write("cases.csv", cases);
  const std::string cmd = "cd " + dir_.string() + " && { " + std::string(PHIQ_CLI) +
                          " batch --threads 1 s.yaml cases.csv -o o >stdout.txt 2>stderr.txt & p=$!; i=0; "
                          "while [ $i -lt 1200 ] && ! ls o 2>/dev/null | grep -q '^case[0-9]*\\.csv$'; do sleep 0.05; "
                          "i=$((i + 1)); done; kill -INT $p; wait $p; }";
  const int st = std::system(cmd.c_str());
  const Result r{WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(dir_ / "stdout.txt"), slurp(dir_ / "stderr.txt")};
  EXPECT_EQ(r.code, 130) << r.err;
  EXPECT_TRUE(phiq::test::one_phiq_line(r.err)) << r.err;
  std::vector<std::string> left;
  for (auto& e : fs::directory_iterator(dir_ / "o")) left.push_back(e.path().filename().string());
  ASSERT_GE(left.size(), 1u) << "no case finished in 60 s: " << r.err;
  ASSERT_LT(left.size(), 40u) << "every case finished before the signal";
  EXPECT_NE(r.err.find("s.yaml: interrupted (SIGINT); " + std::to_string(left.size()) +
                       " of 40 cases written (the others not)"),
            std::string::npos)
      << r.err;
  for (const std::string& f : left) {
    EXPECT_EQ(f.rfind("case", 0), 0u) << f << " (a temporary?)";
    const std::string csv = slurp(dir_ / "o" / f);
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 100002) << f << " is not whole";
  }
}

}  // namespace
