// HDF5 files that fail: a write that meets a full disk (a file-size limit stands for it) ends as every output
// error does — one line, exit 3, nothing left — and not in a signal when the process exits; corrupt and crafted
// inputs to `compare` and `animate` are one line naming the file, exit 2, with nothing of HDF5's own printing.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "output/hdf5_handle.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;
namespace h5 = phiq::detail::h5;

class Hdf5Faults : public Cli {
 protected:
  // The command under a file-size limit of `kib` KiB, SIGXFSZ ignored: a write past it fails with EFBIG, as one
  // on a full disk fails with ENOSPC. The status is the shell's: 128 + N for a signal N.
  Result limited(int kib, const std::string& args) {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = "cd " + dir_.string() + " && bash -c 'trap \"\" XFSZ; ulimit -f " + std::to_string(kib) +
                            "; exec " + PHIQ_CLI + " " + args + "' >" + out.string() + " 2>" + err.string();
    const int st = std::system(cmd.c_str());
    return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(out), slurp(err)};
  }
  // What is left in the directory besides the named files.
  std::vector<std::string> others(const std::vector<std::string>& named) const {
    std::vector<std::string> v;
    for (const std::string& f : files())
      if (f != "stdout.txt" && f != "stderr.txt" && std::find(named.begin(), named.end(), f) == named.end())
        v.push_back(f);
    return v;
  }
  // A phiq results file of the crank-slider (21 rows), and the same run's CSV.
  void write_results() {
    std::string text = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
    text.replace(text.find("steps: 180"), 10, "steps: 20");
    scene_ = write("cs.yaml", text).string();
    ASSERT_EQ(run("run -q " + scene_ + " -o " + (dir_ / "good.h5").string()).code, 0);
    ASSERT_EQ(run("run -q " + scene_ + " -o " + (dir_ / "good.csv").string()).code, 0);
  }
  // `compare` and `animate` of `file` refused in one line naming it, exit 2, `why` in it.
  void expect_refused(const fs::path& file, const std::string& why) {
    for (const std::string& args : {"compare " + file.string() + " " + (dir_ / "good.csv").string(),
                                    "animate " + scene_ + " " + file.string() + " -o " + (dir_ / "a.html").string()}) {
      const Result r = run(args);
      EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
      EXPECT_TRUE(one_phiq_line(r.err)) << args << "\n" << r.err;
      EXPECT_NE(r.err.find(file.string() + ": "), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(dir_ / "a.html"));
    }
  }
  std::string scene_;
};

// 2 000 rows of 4 003 coordinates (64 MB) into a file limited to 2 MiB: the write fails in a block of rows, and
// the process exits 3 with the one line of an output error, not SIGSEGV from HDF5 closing the file at exit.
TEST_F(Hdf5Faults, AFailedWriteIsExit3AndNoSignal) {
  ASSERT_EQ(run("generate nfourbar 2000 --steps 2000 --outputs q -o " + (dir_ / "nf.yaml").string()).code, 0);
  for (const std::string& out : std::vector<std::string>{"r.h5", "d.h5"}) {
    const Result r = limited(2048, "run -q nf.yaml -o " + out + (out == "d.h5" ? " --deflate 1" : ""));
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
    EXPECT_NE(r.err.find(out + ": cannot write: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(": File too large"), std::string::npos) << r.err;
    EXPECT_EQ(others({"nf.yaml"}), std::vector<std::string>{}) << out;
  }
  // a batch into one HDF5 file: its first case already past the limit
  write("c.csv", "c\n0.7071067811865476\n0.7\n");
  const Result b = limited(2048, "batch -q nf.yaml c.csv -o b.h5");
  EXPECT_EQ(b.code, 3) << b.err;
  EXPECT_TRUE(one_phiq_line(b.err)) << b.err;
  EXPECT_NE(b.err.find("b.h5: cannot write: "), std::string::npos) << b.err;
  EXPECT_NE(b.err.find(": File too large"), std::string::npos) << b.err;
  EXPECT_EQ(others({"nf.yaml", "c.csv"}), std::vector<std::string>{});
}

// A byte of the root group's object header changed: HDF5 finds its checksum wrong. One line, exit 2 — and not
// HDF5's "infinite loop closing library" at exit (1.10 keeps blocks of the metadata it failed to load).
TEST_F(Hdf5Faults, ACorruptFileIsOneLine) {
  write_results();
  std::string bytes = slurp(dir_ / "good.h5");
  const std::size_t header = bytes.find("OHDR");  // the first object header: the root group's, with its attributes
  ASSERT_NE(header, std::string::npos);
  bytes[header + 8] = static_cast<char>(bytes[header + 8] ^ 0xff);
  const fs::path bad = write("bad.h5", bytes);
  expect_refused(bad, "checksum");
}

// Datasets that claim 10¹¹ rows in a file of a few KB (their chunks never written): refused naming the file and
// the dataset before anything is allocated, not "out of memory".
TEST_F(Hdf5Faults, ADatasetLargerThanItsFileIsRefused) {
  write_results();
  fs::copy_file(dir_ / "good.h5", dir_ / "huge.h5");
  {
    const h5::Hid f = h5::checked(H5Fopen((dir_ / "huge.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose, "huge");
    for (const char* name : {"t", "q", "qd", "qdd"}) {
      const h5::Hid d = h5::checked(H5Dopen2(f.get(), name, H5P_DEFAULT), H5Dclose, name);
      const hsize_t extent[2] = {100'000'000'000ull, 4};
      h5::check(H5Dset_extent(d.get(), extent), name);
    }
  }
  ASSERT_LT(fs::file_size(dir_ / "huge.h5"), 100'000u);
  expect_refused(dir_ / "huge.h5", "dataset /t claims 100000000000 rows of 1 columns, more than the file's");
}

}  // namespace
