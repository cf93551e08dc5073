// `phiq batch SCENE CASES -o OUT.csv --resume` (tools/cli/batch_resume.*): the cases an earlier run committed are
// kept and only the others run, so that OUT.csv ends as the file of one uninterrupted run, byte for byte; what is
// not an earlier output of the same batch is refused in one line and left as it was.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "phiq/hdf5_reader.hpp"
#include "phiq/hdf5_writer.hpp"
#include "phiq/scene.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

class BatchResume : public Cli {
 protected:
  void SetUp() override {
    Cli::SetUp();
    std::string text = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
    text.replace(text.find("steps: 180"), 10, "steps: 20");
    scene_ = write("cs.yaml", text).string();
    std::string cases = "L2\n";
    for (int k = 0; k < 12; ++k) cases += (k == 3 ? std::string("5.0") : std::to_string(0.2 + 0.01 * k)) + "\n";
    cases_ = write("cases.csv", cases).string();  // case 3: a crank longer than its rod, which cannot turn
    ASSERT_EQ(run("batch -q " + scene_ + " " + cases_ + " -o " + (dir_ / "full.csv").string()).code, 1);
    full_ = slurp(dir_ / "full.csv");
  }
  // full.csv's header and its first `cases` cases (cases 0 … cases − 1, case 3 left out): what an interrupted run
  // publishes.
  std::string first_cases(std::size_t cases) const {
    std::size_t at = full_.find('\n') + 1;
    while (at < full_.size() && std::stoul(full_.substr(at, full_.find(',', at) - at)) < cases)
      at = full_.find('\n', at) + 1;
    return full_.substr(0, at);
  }
  Result resume(const std::string& out, const std::string& more = "") {
    return run("batch -q " + scene_ + " " + cases_ + " -o " + (dir_ / out).string() + " --resume" + more);
  }
  std::string scene_, cases_, full_;
};

TEST_F(BatchResume, RunsOnlyTheCasesAfterThoseWrittenAndEndsAsOneRun) {
  for (std::size_t kept : {1u, 3u, 5u, 7u, 12u}) {  // from 5 on, case 3 (left out earlier) is before the last kept
    const std::string name = "part" + std::to_string(kept) + ".csv";
    write(name, first_cases(kept));
    const Result r = resume(name, " --summary " + (dir_ / "s.json").string());
    EXPECT_EQ(r.code, 1) << r.err;  // case 3 fails either way: run again, or left out earlier
    EXPECT_EQ(slurp(dir_ / name), full_) << kept;
    const std::string summary = slurp(dir_ / "s.json");
    // the cases kept are "written earlier" (case 3, left out, "failed earlier"); the others ran
    const std::size_t earlier = phiq::test::count(summary, "\"status\": \"written earlier\"");
    EXPECT_EQ(earlier, kept > 3 ? kept - 1 : kept) << kept;
    EXPECT_EQ(phiq::test::count(summary, "\"status\": \"failed earlier\""), kept > 3 ? 1u : 0u) << kept;
    EXPECT_EQ(phiq::test::count(summary, "\"status\": \"success\""), 11 - earlier) << kept;
    if (kept > 3) {
      EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
      EXPECT_NE(r.err.find("case 3: not in " + (dir_ / name).string() + " (left out by the run resumed)"),
                std::string::npos)
          << r.err;
    }
  }
}

// HDF5: the earlier file (the first 5 cases, as a 5-case batch of the same scene writes them) copied and appended
// to; the values those of one uninterrupted run, exactly (the bytes depend on how HDF5 laid the file out).
TEST_F(BatchResume, AnHdf5OutputIsCompletedToTheValuesOfOneRun) {
  const std::string first5 = write("first5.csv", slurp(cases_).substr(0, slurp(cases_).find("0.250000"))).string();
  ASSERT_EQ(run("batch -q " + scene_ + " " + first5 + " -o " + (dir_ / "part.h5").string()).code, 1);  // case 3
  ASSERT_EQ(run("batch -q " + scene_ + " " + cases_ + " -o " + (dir_ / "full.h5").string()).code, 1);
  const std::string earlier = slurp(dir_ / "part.h5");
  const Result r = resume("part.h5", " --summary " + (dir_ / "s.json").string());
  EXPECT_EQ(r.code, 1) << r.err;  // case 3, left out earlier
  const phiq::CsvTable part = phiq::read_result_table((dir_ / "part.h5").string());
  const phiq::CsvTable full = phiq::read_result_table((dir_ / "full.h5").string());
  EXPECT_EQ(part.columns, full.columns);
  EXPECT_EQ(part.rows, full.rows);  // every double, exactly
  EXPECT_EQ(part.rows.size(), 11u * 21u);
  const std::string summary = slurp(dir_ / "s.json");
  EXPECT_EQ(phiq::test::count(summary, "\"status\": \"written earlier\""), 4u);  // cases 0, 1, 2, 4
  EXPECT_EQ(phiq::test::count(summary, "\"status\": \"failed earlier\""), 1u);   // case 3
  EXPECT_NE(slurp(dir_ / "part.h5"), earlier);
}

// An earlier file cut inside a case (a full disk, a partial copy): the case is run again, not kept as complete.
TEST_F(BatchResume, ACaseCutInsideIsRunAgain) {
  for (std::size_t kept : {0u, 2u, 6u}) {
    const std::string whole = first_cases(kept), next = first_cases(kept + 1);
    std::size_t cut = whole.size();
    for (int row = 0; row < 8; ++row) cut = next.find('\n', cut) + 1;  // 8 of the case's 21 rows
    ASSERT_LT(cut, next.size());
    write("cut.csv", next.substr(0, cut));
    const Result r = resume("cut.csv");
    EXPECT_EQ(r.code, 1) << r.err;  // case 3
    EXPECT_EQ(slurp(dir_ / "cut.csv"), full_) << kept;
  }
}

// The same for HDF5: the file written as an earlier run would have, cut 8 rows into case 5.
TEST_F(BatchResume, AnHdf5CaseCutInsideIsRunAgain) {
  ASSERT_EQ(run("batch -q " + scene_ + " " + cases_ + " -o " + (dir_ / "full.h5").string()).code, 1);  // case 3
  const phiq::CsvTable full = phiq::read_result_table((dir_ / "full.h5").string());
  const phiq::Scene scene = phiq::load_scene(scene_);
  phiq::Hdf5Options o;
  o.case_column = true;
  {
    phiq::Hdf5Writer w((dir_ / "cut.h5").string(), *scene.model, scene.sweep, o);
    for (const std::vector<double>& row : full.rows) {
      if (row[0] == 5 && w.rows() == 4 * 21 + 8) break;  // cases 0, 1, 2, 4 whole
      w.append_values(row.data());
    }
    w.close();
  }
  ASSERT_EQ(phiq::read_result_table((dir_ / "cut.h5").string()).rows.size(), 4u * 21u + 8u);
  const Result r = resume("cut.h5");
  EXPECT_EQ(r.code, 1) << r.err;  // case 3, left out earlier
  const phiq::CsvTable resumed = phiq::read_result_table((dir_ / "cut.h5").string());
  EXPECT_EQ(resumed.columns, full.columns);
  EXPECT_EQ(resumed.rows, full.rows);  // every double, exactly
}

TEST_F(BatchResume, AMissingOutputIsTheWholeBatch) {
  const Result r = resume("new.csv");
  EXPECT_EQ(r.code, 1) << r.err;  // case 3
  EXPECT_EQ(slurp(dir_ / "new.csv"), full_);
}

TEST_F(BatchResume, WhatIsNotAnEarlierOutputOfThisBatchIsRefusedAndKept) {
  const std::string header = full_.substr(0, full_.find('\n') + 1);
  const std::string row = full_.substr(header.size(), full_.find('\n', header.size()) + 1 - header.size());
  const std::vector<std::pair<std::string, std::string>> bad{
      {"t,x\n0,1\n", "not an output of this batch: its header is not the scene's columns with the case first"},
      {header + row.substr(0, row.size() - 1), "line 2 ends without its newline"},
      {header + "x" + row, "line 2 does not begin with one of its 12 cases"},
      {header + "12," + row.substr(2), "line 2 does not begin with one of its 12 cases"},
      {first_cases(3) + row, "case 0 after case 2"},
      {first_cases(1) + row, "not an output of this batch: case 0 has 22 rows, more than its 21"},
  };
  for (const auto& [text, why] : bad) {
    write("bad.csv", text);
    const Result r = resume("bad.csv");
    EXPECT_EQ(r.code, 2) << why;
    EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
    EXPECT_NE(r.err.find((dir_ / "bad.csv").string() + ": --resume: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
    EXPECT_EQ(slurp(dir_ / "bad.csv"), text);
  }
  write("text.h5", "t,x\n0,1\n");  // not HDF5 at all
  const Result h5 = resume("text.h5");
  EXPECT_EQ(h5.code, 2);
  EXPECT_TRUE(one_phiq_line(h5.err)) << h5.err;
  EXPECT_NE(h5.err.find("text.h5: not a readable HDF5 file"), std::string::npos) << h5.err;
  EXPECT_EQ(slurp(dir_ / "text.h5"), "t,x\n0,1\n");
  // HDF5 results of another scene: other columns
  ASSERT_EQ(
      run("run -q " + phiq::test::model_path("seed/fourbar_natural.yaml") + " -o " + (dir_ / "other.h5").string()).code,
      0);
  const std::string other = slurp(dir_ / "other.h5");
  const Result o = resume("other.h5");
  EXPECT_EQ(o.code, 2);
  EXPECT_TRUE(one_phiq_line(o.err)) << o.err;
  EXPECT_NE(o.err.find("not an output of this batch: its columns are not the scene's with the case first"),
            std::string::npos)
      << o.err;
  EXPECT_EQ(slurp(dir_ / "other.h5"), other);
  const Result dir = run("batch -q " + scene_ + " " + cases_ + " -o " + (dir_ / "cases").string() + "/ --resume");
  EXPECT_EQ(dir.code, 2);
  EXPECT_TRUE(one_phiq_line(dir.err)) << dir.err;
  EXPECT_NE(dir.err.find("--resume continues a one-file output"), std::string::npos) << dir.err;
  EXPECT_FALSE(fs::exists(dir_ / "cases"));
}

}  // namespace
