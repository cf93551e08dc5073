// `phiq run -o OUT.h5` and `phiq compare` on HDF5 (tools/cli/result_file.*): the format chosen by extension or
// --format, the file equal to the CSV of the same run, and HDF5 written as atomically as CSV: an unwritable place,
// a failed or interrupted run leave nothing, and an existing file is never damaged.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "phiq/hdf5_reader.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;
using Names = std::vector<std::string>;

// The same run writes the same bytes, whenever and on however many threads: HDF5 stores no object times (it
// does by default, to the second, so the runs are more than a second apart).
TEST_F(Cli, Hdf5ResultsAreTheSameBytesOnEveryRun) {
  const fs::path scene = write("fb.yaml", phiq::test::kFourbarOutputs);
  const fs::path a = dir_ / "a.h5", b = dir_ / "b.h5";
  ASSERT_EQ(run("run -q --threads 2 " + scene.string() + " -o " + a.string()).code, 0);
  ::usleep(1'100'000);
  ASSERT_EQ(run("run -q --threads 1 " + scene.string() + " -o " + b.string()).code, 0);
  const std::string bytes = slurp(a);
  EXPECT_GT(bytes.size(), 1000u);
  EXPECT_TRUE(bytes == slurp(b));
}

// The HDF5 of a run holds the CSV's doubles: compare agrees with tolerances 0, either side; the extension chooses
// the format, --format overrides it; the summary counts the HDF5 writing.
TEST_F(Cli, Hdf5ResultsEqualTheCsvOfTheSameRun) {
  const fs::path scene = write("fb.yaml", phiq::test::kFourbarOutputs);
  const fs::path csv = dir_ / "r.csv", h5 = dir_ / "r.h5", other = dir_ / "r.data", text = dir_ / "t.h5";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  Result r = run("run -q " + scene.string() + " -o " + h5.string() + " --summary " + (dir_ / "s.json").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(phiq::is_hdf5_file(h5.string()));
  EXPECT_NE(slurp(dir_ / "s.json").find("\"write_seconds\""), std::string::npos);
  for (const auto& [a, b] : {std::pair{h5, csv}, std::pair{csv, h5}, std::pair{h5, h5}}) {
    Result c = run("compare --rtol 0 --atol 0 " + a.string() + " " + b.string());
    EXPECT_EQ(c.code, 0) << c.err;
    EXPECT_NE(c.err.find("agree: 73 rows x 30 columns (identical)"), std::string::npos) << c.err;
  }
  // compressed: the same doubles
  ASSERT_EQ(run("run -q --deflate 6 " + scene.string() + " -o " + (dir_ / "z.h5").string()).code, 0);
  EXPECT_EQ(run("compare --rtol 0 --atol 0 " + (dir_ / "z.h5").string() + " " + csv.string()).code, 0);
  Result z = run("run -q --deflate 6 " + scene.string() + " -o " + (dir_ / "z.csv").string());
  EXPECT_EQ(z.code, 2);
  EXPECT_TRUE(one_phiq_line(z.err)) << z.err;
  EXPECT_NE(z.err.find("--deflate compresses HDF5 results only"), std::string::npos) << z.err;
  ASSERT_EQ(run("run -q --format hdf5 " + scene.string() + " -o " + other.string()).code, 0);
  EXPECT_TRUE(phiq::is_hdf5_file(other.string()));
  ASSERT_EQ(run("run -q --format csv " + scene.string() + " -o " + text.string()).code, 0);
  EXPECT_EQ(slurp(text), slurp(csv));
  // another run differs: exit 1, the worst cell named
  std::string shorter = phiq::test::kFourbarOutputs;
  shorter.replace(shorter.find("steps: 72"), 9, "steps: 71");
  ASSERT_EQ(run("run -q " + write("short.yaml", shorter).string() + " -o " + (dir_ / "s.h5").string()).code, 0);
  Result d = run("compare " + h5.string() + " " + (dir_ / "s.h5").string());
  EXPECT_EQ(d.code, 1) << d.err;
  EXPECT_NE(d.err.find("row counts differ: A has 73 rows, B has 72"), std::string::npos) << d.err;
  EXPECT_EQ(files(), (Names{"fb.yaml", "r.csv", "r.data", "r.h5", "s.h5", "s.json", "short.yaml", "stderr.txt",
                            "stdout.txt", "t.h5", "z.h5"}));
}

// HDF5 needs a file: without -o, or to a FIFO, it is refused before the solve with one line, and nothing appears.
TEST_F(Cli, Hdf5NeedsAFile) {
  const fs::path scene = write("fb.yaml", phiq::test::kFourbarOutputs);
  Result r = run("run --format hdf5 " + scene.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("--format hdf5 needs -o FILE"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  const fs::path fifo = dir_ / "fifo.h5";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  r = run("run " + scene.string() + " -o " + fifo.string());  // a FIFO would block until read: refused first
  EXPECT_EQ(r.code, 3);
  EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("fifo.h5: cannot write HDF5 to a device, FIFO or open descriptor"), std::string::npos) << r.err;
  EXPECT_EQ(files(), (Names{"fb.yaml", "fifo.h5", "stderr.txt", "stdout.txt"}));
}

// An HDF5 output where none can be written fails with exit 3 and one line before the sweep; an existing file at the
// target stays as it was when the run fails or is interrupted; nothing else is left.
TEST_F(Cli, Hdf5OutputIsAtomic) {
  const fs::path scene = write("fb.yaml", phiq::test::kFourbarOutputs);
  Result r = run("run " + scene.string() + " -o " + (dir_ / "nodir" / "r.h5").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("nodir/r.h5: cannot write: No such file or directory"), std::string::npos) << r.err;
  write("plain", "a file, not a directory\n");
  r = run("run " + scene.string() + " -o " + (dir_ / "plain" / "r.h5").string());
  EXPECT_EQ(r.code, 3);
  EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("plain/r.h5: cannot write: Not a directory"), std::string::npos) << r.err;
  if (::geteuid() != 0) {  // root writes anywhere: a read-only directory stops only others
    const fs::path ro = dir_ / "ro";
    fs::create_directory(ro);
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
    r = run("run " + scene.string() + " -o " + (ro / "r.h5").string());
    fs::permissions(ro, fs::perms::owner_all);
    EXPECT_EQ(r.code, 3);
    EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
    EXPECT_NE(r.err.find("ro/r.h5: cannot write: Permission denied"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(ro));
    fs::remove(ro);
  }

  // a run that fails at step 6 (the slider driven beyond reach) leaves the previous file
  const fs::path keep = dir_ / "keep.h5";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + keep.string()).code, 0);
  const std::string before = slurp(keep);
  const fs::path reach = write("reach.yaml", R"(coordinates: {theta2: 0.5, xA: 0.26, yA: 0.14, xB: 1.2}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: 0.3, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: 1.0}
drivers:
  - {name: slide, coordinate: xB, law: {type: linear, initial: 1.2, rate: 0.2}}
time: {start: 0, end: 1, steps: 10}
)");
  r = run("run " + reach.string() + " -o " + keep.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("no output written"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(keep), before);

  // interrupted in the middle of a sweep of minutes
  std::string long_scene = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  long_scene.replace(long_scene.find("steps: 180"), 10, "steps: 10000000");
  const fs::path slow = write("long.yaml", long_scene);
  r = run_prefixed("timeout --preserve-status -s INT 1 ", "run " + slow.string() + " -o " + keep.string());
  EXPECT_EQ(r.code, 130) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("interrupted (SIGINT); no output written"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(keep), before);
  EXPECT_EQ(files(), (Names{"fb.yaml", "keep.h5", "long.yaml", "plain", "reach.yaml", "stderr.txt", "stdout.txt"}));
}

// compare given a file that is not HDF5 results: one line naming it, exit 2.
TEST_F(Cli, CompareRefusesCorruptHdf5) {
  const fs::path scene = write("fb.yaml", phiq::test::kFourbarOutputs);
  const fs::path good = dir_ / "good.h5";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + good.string()).code, 0);
  const std::string bytes = slurp(good);
  const fs::path cut = write("cut.h5", bytes.substr(0, bytes.size() / 2));
  const fs::path text = write("text.h5", "not an HDF5 file\n");
  for (const fs::path& bad : {cut, text}) {
    Result r = run("compare " + good.string() + " " + bad.string());
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
    EXPECT_NE(r.err.find(bad.string() + ": not a readable HDF5 file: "), std::string::npos) << r.err;
    r = run("compare " + bad.string() + " " + good.string());
    EXPECT_EQ(r.code, 2) << bad;
  }
}

}  // namespace
