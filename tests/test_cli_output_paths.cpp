// Where the commands' outputs go: `-` as standard output, devices and FIFOs written in place, symbolic links
// followed to their target, outputs that are inputs or each other refused, empty paths refused, and lost standard
// output an error. What AtomicOutputFile does below the command is test_output_files.cpp.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

// "-" is standard output, as in most tools: run -o - gives the bytes run gives without -o (one thread: the same
// bytes in every run), generate -o - a scene that loads, plot -o - an SVG, --summary - the JSON; no file named "-"
// appears; batch refuses it for its directory.
TEST_F(Cli, ADashIsStandardOutput) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  struct Cwd {  // in dir_ (a file named "-" would land there), back however the test ends
    fs::path was = fs::current_path();
    explicit Cwd(const fs::path& to) { fs::current_path(to); }
    ~Cwd() { fs::current_path(was); }
  } in_dir(dir_);
  Result plain = run("run -q --threads 1 " + scene);
  Result dash = run("run -q --threads 1 " + scene + " -o -");
  ASSERT_EQ(dash.code, 0) << dash.err;
  EXPECT_EQ(dash.out, plain.out);
  EXPECT_EQ(dash.out.rfind("t,theta2,", 0), 0u);
  Result gen = run("generate nfourbar 3 --steps 4 -o -");
  ASSERT_EQ(gen.code, 0) << gen.err;
  EXPECT_EQ(phiq::parse_scene(gen.out, "generated.yaml").model->num_coordinates(), 9);  // θ and 4 tips
  const fs::path csv = dir_ / "cs.csv";
  Result sum = run("run -q --threads 1 " + scene + " -o " + csv.string() + " --summary -");
  ASSERT_EQ(sum.code, 0) << sum.err;
  EXPECT_EQ(sum.out.rfind("{", 0), 0u) << sum.out;
  EXPECT_NE(sum.out.find("\"steps\": 181"), std::string::npos) << sum.out;
  Result svg = run("plot " + scene + " " + csv.string() + " -o -");
  ASSERT_EQ(svg.code, 0) << svg.err;
  EXPECT_NE(svg.out.find("<svg"), std::string::npos);
  Result batch = run("batch " + scene + " " + write("c.csv", "L2\n0.2\n").string() + " -o -");
  EXPECT_EQ(batch.code, 2);
  EXPECT_NE(batch.err.find("'-' (standard output) cannot hold the case files"), std::string::npos) << batch.err;
  EXPECT_FALSE(fs::exists(dir_ / "-"));
}

// A device node (as /dev/null: character device 1, 3) given to -o is written in place and stays a device, as does
// a FIFO (its reader gets the whole CSV); several outputs may share a device. Creating the node needs root (mknod):
// skipped otherwise. The real /dev/null is never used: the node lives in the test's directory.
TEST_F(Cli, DeviceAndFifoOutputsAreWrittenInPlace) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  const fs::path fifo = dir_ / "fifo", copy = dir_ / "copy.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
  const std::string cmd = "cat " + fifo.string() + " > " + copy.string() + " & " + std::string(PHIQ_CLI) + " run -q " +
                          scene + " -o " + fifo.string() + " >" + out.string() + " 2>" + err.string() +
                          "; s=$?; wait; exit $s";
  const int st = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << slurp(err);
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(std::count_if(std::istreambuf_iterator<char>(*std::make_unique<std::ifstream>(copy)),
                          std::istreambuf_iterator<char>(), [](char c) { return c == '\n'; }),
            182);  // the header and 181 rows
  EXPECT_EQ(files(), (std::vector<std::string>{"copy.csv", "fifo", "stderr.txt", "stdout.txt"}));  // no temporary

  const fs::path null = dir_ / "null";
  if (::mknod(null.c_str(), S_IFCHR | 0666, ::makedev(1, 3)) != 0) GTEST_SKIP() << "mknod needs root";
  Result r = run("run -q " + scene + " -o " + null.string() + " --summary " + null.string());
  EXPECT_EQ(r.code, 0) << r.err;
  struct stat sb;
  ASSERT_EQ(::stat(null.c_str(), &sb), 0);
  EXPECT_TRUE(S_ISCHR(sb.st_mode));
  EXPECT_EQ(::major(sb.st_rdev), 1u);
  EXPECT_EQ(::minor(sb.st_rdev), 3u);
  r = run("assemble -q " + scene + " -o " + null.string());
  EXPECT_EQ(r.code, 0) << r.err;
  r = run("generate nfourbar 3 -o " + null.string());
  EXPECT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(::stat(null.c_str(), &sb), 0);
  EXPECT_TRUE(S_ISCHR(sb.st_mode));
  EXPECT_EQ(files(), (std::vector<std::string>{"copy.csv", "fifo", "null", "stderr.txt", "stdout.txt"}));
}

// -o through a symbolic link (relative, into another directory) replaces the link's target and leaves the link;
// the temporary lives beside the target. /dev/stdout (one of the process's own descriptors) is written through the
// descriptor: appended to what the shell opened with >>, not replacing it.
TEST_F(Cli, SymlinkOutputsReplaceTheirTargetAndKeepTheLink) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  fs::create_directories(dir_ / "results");
  write("results/cs.csv", "old result\n");
  fs::create_symlink("results/cs.csv", dir_ / "latest.csv");
  Result r = run("run -q " + scene + " -o " + (dir_ / "latest.csv").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir_ / "latest.csv"));
  EXPECT_EQ(fs::read_symlink(dir_ / "latest.csv"), "results/cs.csv");
  EXPECT_EQ(slurp(dir_ / "results/cs.csv").rfind("t,theta2,", 0), 0u);
  std::vector<std::string> in_results;
  for (auto& e : fs::directory_iterator(dir_ / "results")) in_results.push_back(e.path().filename().string());
  EXPECT_EQ(in_results, std::vector<std::string>{"cs.csv"});
  // a dangling link: its target is created
  fs::create_symlink("results/new.csv", dir_ / "next.csv");
  ASSERT_EQ(run("assemble -q " + scene + " -o " + (dir_ / "next.csv").string()).code, 0);
  EXPECT_TRUE(fs::is_symlink(dir_ / "next.csv"));
  EXPECT_EQ(slurp(dir_ / "results/new.csv").rfind("t,theta2,", 0), 0u);

  write("log.txt", "before\n");
  const std::string cmd =
      std::string(PHIQ_CLI) + " assemble -q " + scene + " -o /dev/stdout >>" + (dir_ / "log.txt").string();
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_EQ(slurp(dir_ / "log.txt").rfind("before\nt,theta2,", 0), 0u) << slurp(dir_ / "log.txt");
  EXPECT_FALSE(fs::is_symlink(dir_ / "log.txt"));
}

// An output that is an input (the scene, through a link or a hard link too), or two outputs that are one file, are
// refused in one line before anything is solved; the files are untouched.
TEST_F(Cli, OutputsThatAreInputsOrEachOtherAreRefused) {
  const std::string original = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  const fs::path scene = write("s.yaml", original);
  fs::create_symlink("s.yaml", dir_ / "link.yaml");
  fs::create_hard_link(scene, dir_ / "hard.yaml");
  const fs::path csv = write("r.csv", "t,theta2\n0,0\n");
  const std::string s = scene.string(), d = dir_.string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run " + s + " -o " + s, "run: -o " + s + ": the same file as the scene " + s},
      {"run " + s + " -o " + d + "/link.yaml", "the same file as the scene"},
      {"run " + s + " -o " + d + "/hard.yaml", "the same file as the scene"},
      {"run " + s + " -o " + d + "/./s.yaml", "the same file as the scene"},
      {"run " + s + " --summary " + s, "run: --summary " + s + ": the same file as the scene"},
      {"run " + s + " -o " + d + "/a.csv --summary " + d + "/a.csv",
       "-o " + d + "/a.csv and --summary " + d + "/a.csv are the same file"},
      {"assemble " + s + " -o " + d + "/link.yaml", "assemble: -o "},
      {"sweep-accuracy " + s + " -o " + d + "/x.csv --json " + d + "/x.csv", "are the same file"},
      {"sweep-accuracy " + s + " --json " + s, "the same file as the scene"},
      {"plot " + s + " " + csv.string() + " -o " + csv.string(),
       "plot: -o " + csv.string() + ": the same file as the result"},
      {"plot " + s + " " + csv.string() + " -o " + s, "the same file as the scene"},
  };
  for (const auto& [args, says] : cases) {
    Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
    EXPECT_TRUE(one_phiq_line(r.err)) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
  }
  EXPECT_EQ(slurp(scene), original);
  EXPECT_EQ(slurp(csv), "t,theta2\n0,0\n");
  // batch: a case file that is the cases file
  fs::create_directories(dir_ / "out");
  const fs::path cases_csv = write("out/case0.csv", "L2\n0.2\n");
  Result r = run("batch " + s + " " + cases_csv.string() + " -o " + d + "/out");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("the same file as the cases"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(cases_csv), "L2\n0.2\n");
  EXPECT_EQ(files(),
            (std::vector<std::string>{"hard.yaml", "link.yaml", "out", "r.csv", "s.yaml", "stderr.txt", "stdout.txt"}));
}

// An empty output path is refused (it used to mean standard output); nothing goes to standard output.
TEST_F(Cli, EmptyOutputPathsAreRefused) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  for (const std::string& args : std::vector<std::string>{
           "run " + scene + " -o ''", "run " + scene + " --summary ''", "assemble " + scene + " -o ''",
           "generate nfourbar 3 -o ''", "sweep-accuracy " + scene + " --json ''", "batch " + scene + " x.csv -o ''",
           "plot " + scene + " x.csv -o ''"}) {
    Result r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_TRUE(one_phiq_line(r.err)) << args;
    EXPECT_NE(r.err.find("the path is empty"), std::string::npos) << args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
  }
}

// What goes to standard output and is lost (a full device, a closed descriptor) is an error, exit 3 in one line:
// check, check --json, assemble, run.
TEST_F(Cli, LostStandardOutputIsAnError) {
  const std::string scene = phiq::test::model_path("seed/fourbar_natural.yaml");
  const fs::path err = dir_ / "err.txt";
  // the command with standard output redirected as given: its exit status, its stderr in err.txt
  auto status = [&](const std::string& args, const std::string& redirect) {
    const int st = std::system((std::string(PHIQ_CLI) + " " + args + " " + redirect + " 2>" + err.string()).c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  };
  if (fs::exists("/dev/full")) {
    for (const std::string& args : std::vector<std::string>{"check " + scene, "check --json " + scene,
                                                            "assemble -q " + scene, "run -q " + scene}) {
      EXPECT_EQ(status(args, ">/dev/full"), 3) << args << ": " << slurp(err);
      EXPECT_TRUE(one_phiq_line(slurp(err))) << args;
      EXPECT_NE(slurp(err).find("standard output: cannot write: No space left on device"), std::string::npos)
          << slurp(err);
    }
  }
  for (const std::string& args :
       std::vector<std::string>{"run -q " + scene, "check " + scene, "assemble -q " + scene}) {
    EXPECT_EQ(status(args, ">&-"), 3) << args << ": " << slurp(err);
    EXPECT_TRUE(one_phiq_line(slurp(err))) << args;
    EXPECT_NE(slurp(err).find("standard output: cannot write: it is closed"), std::string::npos) << slurp(err);
  }
}

}  // namespace
