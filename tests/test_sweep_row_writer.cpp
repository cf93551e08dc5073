// run_sweep with a RowWriter: the rows encoded by the threads that compute them and written in order give the bytes
// a step callback formatting each row gives, on every thread count, for every scene under models/; each written row
// reaches write() once, in order; a write that returns false stops the sweep after its rows, and an encoding that
// throws stops it and is rethrown.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

namespace fs = std::filesystem;

// Rows encoded as `phiq run` writes its CSV, gathered in the order written.
class WrittenCsvRows : public RowWriter {
 public:
  explicit WrittenCsvRows(const CsvFormat& csv) : csv_(csv) {}
  void encode(const StepView& step, std::string& out) const override { csv_.append_row(step, out); }
  std::size_t max_row_bytes() const override { return csv_.max_row_chars(); }
  bool write(const std::string& encoded, Index rows, Index last_step) override {
    text += encoded;
    written_rows += rows;
    last_steps.push_back(last_step);
    return true;
  }
  std::string text;
  Index written_rows = 0;
  std::vector<Index> last_steps;  // of each write()

 private:
  const CsvFormat& csv_;
};

// The summary's counts and warnings, which a writer must leave as a step callback does.
std::string writer_summary_text(const SweepSummary& s) {
  std::string out = std::string(to_string(s.status)) + '|' + s.message + '|' + std::to_string(s.steps_completed) + '|' +
                    std::to_string(s.parallel_chunks) + '|' + std::to_string(s.subdivisions) + '|' +
                    std::to_string(s.counters.newton_iterations) + '|' + std::to_string(s.counters.factorizations) +
                    '|' + std::to_string(s.accuracy.converged.rows) + '|' + std::to_string(s.accuracy.singular.rows);
  for (const SweepWarning& w : s.warnings) out += '\n' + w.kind + ' ' + w.message;
  return out;
}

TEST(SweepRowWriter, EncodedRowsAreTheBytesAStepCallbackWritesOnEveryThreadCount) {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::recursive_directory_iterator(PHIQ_MODELS_DIR))
    if (e.path().extension() == ".yaml") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  ASSERT_GE(scenes.size(), 20u);
  int swept = 0;
  for (const fs::path& p : scenes) {
    const Scene sc = load_scene(p.string());
    // prepared as `phiq run` prepares it: redundant rows dropped, from the assembled position
    Eigen::VectorXd q = sc.model->initial_positions();
    std::unique_ptr<Model> solved;
    AssemblySummary assembly;
    (void)prepare_square(*sc.model, sc.sweep.t_begin, {}, q, &solved, &assembly);  // a failure leaves it null
    if (!solved) continue;  // (an inconsistent model by design: no sweep)
    SweepOptions opt = sc.sweep;
    opt.steps = std::min<Index>(opt.steps, 400);  // (the scene's own step; short of its end on the longest)
    opt.t_end = opt.t_begin + (sc.sweep.t_end - sc.sweep.t_begin) * static_cast<double>(opt.steps) /
                                  static_cast<double>(std::max<Index>(sc.sweep.steps, 1));
    const CsvFormat csv(*sc.model, opt);
    const std::string what = p.filename().string();
    std::string by_callback;
    SweepSummary callback_sum;
    opt.threads = 1;
    {
      Workspace ws(*solved);
      ws.q = q;
      (void)run_sweep(
          *solved, opt, ws, [&](const StepView& s) { return csv.append_row(s, by_callback), true; }, &callback_sum);
    }
    ASSERT_FALSE(by_callback.empty()) << what;
    for (int threads : {1, 2, 3}) {
      opt.threads = threads;
      Workspace ws(*solved);
      ws.q = q;
      WrittenCsvRows rows(csv);
      SweepSummary sum;
      (void)run_sweep(*solved, opt, ws, rows, &sum);
      EXPECT_TRUE(rows.text == by_callback)
          << what << ": the rows written on " << threads << " threads differ from a step callback's";
      EXPECT_EQ(writer_summary_text(sum), writer_summary_text(callback_sum)) << what << ", " << threads << " threads";
      EXPECT_EQ(rows.written_rows, std::count(by_callback.begin(), by_callback.end(), '\n')) << what;
    }
    ++swept;
  }
  EXPECT_GE(swept, 20);
}

// nfourbar N = 100, 640 steps in chunks of 40 on 2 threads, every 3rd row written, every coordinate.
SweepOptions writer_case_options(const Model& model) {
  SweepOptions opt;
  opt.steps = 640;
  opt.t_end = 0.1;  // θ from 45° to 117°: no flat position
  opt.chunk_steps = 40;
  opt.every = 3;
  opt.threads = 2;
  for (Index j = 0; j < model.num_coordinates(); ++j) opt.coordinate_columns.push_back(j);
  return opt;
}
struct WriterCase {
  Model model = test::nfourbar_model(100, M_PI / 4, 4 * M_PI);
  SweepOptions opt = writer_case_options(model);
  CsvFormat csv{model, opt};
};

TEST(SweepRowWriter, EveryWrittenRowReachesWriteOnceInOrder) {
  WriterCase c;
  Workspace ws(c.model);
  WrittenCsvRows rows(c.csv);
  SweepSummary sum;
  ASSERT_EQ(run_sweep(c.model, c.opt, ws, rows, &sum), SolveStatus::kSuccess) << sum.message;
  EXPECT_EQ(sum.parallel_chunks, 16);
  EXPECT_EQ(rows.written_rows, 214);  // rows 0, 3, …, 639
  EXPECT_EQ(std::count(rows.text.begin(), rows.text.end(), '\n'), 214);
  ASSERT_FALSE(rows.last_steps.empty());
  EXPECT_TRUE(std::is_sorted(rows.last_steps.begin(), rows.last_steps.end()));
  EXPECT_EQ(rows.last_steps.back(), 639);  // the last written row's step, not the sweep's last
  for (Index k : rows.last_steps) EXPECT_EQ(k % 3, 0) << k;
}

// A writer that stops after the rows up to t ≥ 0.05 were written: the sweep stops there, cancelled, with the
// caller's workspace at the last row written (as a step callback that stops leaves it).
TEST(SweepRowWriter, AWriteThatReturnsFalseStopsTheSweepAfterItsRows) {
  class StopHalfway : public WrittenCsvRows {
   public:
    using WrittenCsvRows::WrittenCsvRows;
    bool write(const std::string& encoded, Index rows, Index last_step) override {
      WrittenCsvRows::write(encoded, rows, last_step);
      return last_step < 320;
    }
  };
  WriterCase c;
  SweepOptions every_row = c.opt;
  every_row.every = 1;
  test::Trace all;
  ASSERT_EQ(test::sweep(c.model, every_row, &all), SolveStatus::kSuccess);
  Workspace ws(c.model);
  StopHalfway rows(c.csv);
  SweepSummary sum;
  EXPECT_EQ(run_sweep(c.model, c.opt, ws, rows, &sum), SolveStatus::kCancelled);
  const Index k = rows.last_steps.back();
  EXPECT_GE(k, 320);
  EXPECT_LT(k, 320 + 2 * c.opt.chunk_steps);  // the chunk holding row 320
  EXPECT_EQ(sum.message, "stopped by the caller after step " + std::to_string(k));
  EXPECT_EQ(rows.written_rows, k / 3 + 1);
  ASSERT_GT(all.q.size(), static_cast<std::size_t>(k));
  EXPECT_TRUE(test::same_bits(ws.q, all.q[static_cast<std::size_t>(k)])) << "the workspace ends at row " << k;
}

TEST(SweepRowWriter, AnEncodingThatThrowsStopsTheSweepAndIsRethrown) {
  class Throws : public WrittenCsvRows {
   public:
    using WrittenCsvRows::WrittenCsvRows;
    void encode(const StepView& step, std::string& out) const override {
      if (step.step == 600) throw Error("cannot encode row 600");
      WrittenCsvRows::encode(step, out);
    }
  };
  WriterCase c;
  Workspace ws(c.model);
  Throws rows(c.csv);
  SweepSummary sum;
  EXPECT_THROW(
      {
        try {
          (void)run_sweep(c.model, c.opt, ws, rows, &sum);
        } catch (const Error& e) {
          EXPECT_STREQ(e.what(), "cannot encode row 600");
          throw;
        }
      },
      Error);
  EXPECT_LT(rows.written_rows, 201);  // nothing from row 600 on was written
}

// A chunk keeps its rows encoded: the threads that fit in row_buffer_bytes are counted by the encoded rows (CSV
// text is wider than the doubles), while the chunks, cut by the doubles alone, stay those of every thread count.
TEST(SweepRowWriter, ThreadsFitTheEncodedRowsAndTheChunksStayTheSame) {
  const Model m = test::nfourbar_model(100, M_PI / 4, M_PI / 2);
  SweepOptions opt;
  opt.steps = 300;  // chunks of max(16, 300 / 16) = 18 steps
  const double row_bytes = 8.0 * static_cast<double>(3 * m.num_coordinates() + 1);  // q, q̇, q̈ and the time
  opt.row_buffer_bytes = static_cast<std::size_t>(40.5 * row_bytes);  // two chunks as doubles, not as CSV text
  for (Index j = 0; j < m.num_coordinates(); ++j) opt.coordinate_columns.push_back(j);  // q, q̇, q̈ of each
  const CsvFormat csv(m, opt);
  ASSERT_GT(static_cast<double>(csv.max_row_chars()), 2.0 * row_bytes);
  auto sweep = [&](int threads, SweepSummary& sum) {
    opt.threads = threads;
    Workspace ws(m);
    WrittenCsvRows rows(csv);
    EXPECT_EQ(run_sweep(m, opt, ws, rows, &sum), SolveStatus::kSuccess) << sum.message;
    return rows.text;
  };
  SweepSummary one, tight, roomy;
  const std::string by_one = sweep(1, one), by_tight = sweep(2, tight);
  EXPECT_EQ(tight.threads, 1);
  EXPECT_EQ(tight.parallel_chunks, 17);
  ASSERT_EQ(tight.warnings.size(), 1u);
  EXPECT_EQ(tight.warnings[0].kind, "threads_reduced");
  EXPECT_NE(tight.warnings[0].message.find("run on 1 thread instead of on 2 threads"), std::string::npos)
      << tight.warnings[0].message;
  opt.row_buffer_bytes = 3 * 18 * csv.max_row_chars();  // two chunks of encoded rows (and two rows of doubles each)
  const std::string by_roomy = sweep(2, roomy);
  EXPECT_EQ(roomy.threads, 2);
  EXPECT_EQ(roomy.parallel_chunks, 17);
  EXPECT_TRUE(roomy.warnings.empty());
  EXPECT_TRUE(by_one == by_tight && by_one == by_roomy) << "the same chunks: the same bytes";
}

}  // namespace
}  // namespace phiq
