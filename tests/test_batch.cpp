// Batch mode: one model structure, many parameter sets, in parallel, sharing one symbolic analysis.
#include <gtest/gtest.h>

#include <mutex>

#include "phiq/parsed_scene.hpp"
#include "phiq/phiq.hpp"

namespace phiq {
namespace {

// The crank-slider with crank length L2 and rod 1: x_B = L2 cos θ + sqrt(1 − L2² sin² θ), θ = 2t.
Model crank_slider_case(double l2, const Model* share) {
  ModelBuilder b;
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  Index th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", l2), ya = b.add_coordinate("yA", 0.0),
        xb = b.add_coordinate("xB", l2 + 1.0);
  b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, l2, S(th)});
  b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, 1.0});
  b.add_driver("motor", th, MotionLaw::linear(0.0, 2.0));
  b.set_length_scale(1.0);
  if (share) b.share_analysis_with(*share);
  return std::move(b).build();
}

// The rows of a scene's sweep as CSV text (the bytes `phiq run` writes).
std::string sweep_text(const Scene& scene) {
  Workspace ws(*scene.model);
  const CsvFormat format(*scene.model, scene.sweep);
  std::string text = format.header();
  SweepSummary sum;
  (void)run_sweep(
      *scene.model, scene.sweep, ws,
      [&](const StepView& s) {
        format.append_row(s, text);
        return true;
      },
      &sum);
  EXPECT_EQ(sum.status, SolveStatus::kSuccess) << sum.message;
  return text;
}

// A ParsedScene read again and again, with other parameters each time, gives what parse_scene gives for the text
// with those parameters written in (the same rows, byte for byte), also after a read its parameters made fail
// (a negative rod) and after a copy (its own tree); and the cases share the first one's symbolic analysis.
TEST(Batch, ParsedSceneReadsEachCaseAsParseSceneDoes) {
  const std::string text =
      "parameters: {L2: 0.3, L3: 1.0}\n"
      "coordinates: {theta2: 0.0, xA: 0.28, yA: 0.03, xB: 1.25}\n"
      "points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}\n"
      "constraints:\n"
      "  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}\n"
      "  - {name: rod, type: distance, points: [A, B], length: L3}\n"
      "drivers:\n"
      "  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}\n"
      "time: {start: 0, end: pi, steps: 36}\n";
  ParsedScene parsed(text, "cs.yaml");
  const Scene first = parsed.read();
  EXPECT_EQ(sweep_text(first), sweep_text(parse_scene(text, "cs.yaml")));
  const std::vector<std::pair<double, double>> cases{{0.2, 1.0}, {0.3, -1.0}, {0.4, 1.2}, {0.25, 0.9}};
  for (int copy = 0; copy < 2; ++copy) {
    ParsedScene own = copy ? ParsedScene(parsed) : ParsedScene(text, "cs.yaml");
    for (const auto& [l2, l3] : cases) {
      SceneOverrides o;
      o.parameters = {{"L2", l2}, {"L3", l3}};
      o.share_analysis_with = first.model.get();
      if (l3 < 0) {
        EXPECT_THROW((void)own.read(o), SceneError);
        continue;
      }
      const Scene scene = own.read(o);
      EXPECT_EQ(scene.model->symbolic(), first.model->symbolic());
      std::string written = text;
      written.replace(0, written.find('\n'),
                      "parameters: {L2: " + std::to_string(l2) + ", L3: " + std::to_string(l3) + "}");
      ASSERT_EQ(std::stod(std::to_string(l2)), l2);  // the text holds the very doubles
      EXPECT_EQ(sweep_text(scene), sweep_text(parse_scene(written, "cs.yaml"))) << l2 << " " << l3;
    }
  }
  EXPECT_THROW(ParsedScene("time: {start: 0, end: 1, steps: [\n", "bad.yaml"), SceneError);  // YAML syntax
}

TEST(Batch, EveryCaseMatchesItsClosedFormAndSharesTheAnalysis) {
  const std::vector<double> lengths{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8};
  std::vector<Model> models;
  models.reserve(lengths.size());  // the first model must not move: the others refer to its analysis
  for (double l : lengths) models.push_back(crank_slider_case(l, models.empty() ? nullptr : &models[0]));
  std::vector<const Model*> ptrs;
  for (const Model& m : models) ptrs.push_back(&m);
  SweepOptions opt;
  opt.t_end = M_PI;  // a full turn
  opt.steps = 90;
  std::vector<double> worst(lengths.size(), 0.0);
  std::vector<Index> rows(lengths.size(), 0);
  BatchSummary sum = run_batch(ptrs, opt, 2, [&](std::size_t c, const StepView& s) {
    // each case writes only its own slot: no synchronisation needed
    const double th = 2.0 * s.t, l = lengths[c];
    const double xb = l * std::cos(th) + std::sqrt(1.0 - l * l * std::sin(th) * std::sin(th));
    worst[c] = std::max(worst[c], std::fabs(s.q(3) - xb));
    ++rows[c];
    return true;
  });
  EXPECT_EQ(sum.threads, 2);
  EXPECT_EQ(sum.failed, 0);
  EXPECT_EQ(sum.shared_analyses, static_cast<Index>(lengths.size()) - 1);
  for (std::size_t c = 0; c < lengths.size(); ++c) {
    EXPECT_EQ(sum.cases[c].status, SolveStatus::kSuccess) << sum.cases[c].message;
    EXPECT_EQ(rows[c], 91);
    EXPECT_LT(worst[c], 1e-9) << "L2 = " << lengths[c];
  }
}

TEST(Batch, AFailedCaseDoesNotStopTheOthers) {
  // a crank longer than the rod cannot turn: that case fails, the others do not
  std::vector<Model> models;
  models.reserve(3);
  models.push_back(crank_slider_case(0.3, nullptr));
  models.push_back(crank_slider_case(1.5, &models[0]));
  models.push_back(crank_slider_case(0.5, &models[0]));
  SweepOptions opt;
  opt.t_end = M_PI;
  opt.steps = 60;
  std::mutex mu;
  Index delivered = 0;
  BatchSummary sum = run_batch({&models[0], &models[1], &models[2]}, opt, 0, [&](std::size_t, const StepView&) {
    std::lock_guard<std::mutex> lock(mu);
    ++delivered;
    return true;
  });
  EXPECT_EQ(sum.failed, 1);
  EXPECT_EQ(sum.cases[0].status, SolveStatus::kSuccess);
  EXPECT_NE(sum.cases[1].status, SolveStatus::kSuccess);
  EXPECT_NE(sum.cases[1].message.find("step "), std::string::npos) << sum.cases[1].message;
  EXPECT_EQ(sum.cases[2].status, SolveStatus::kSuccess);
  EXPECT_EQ(delivered, 61 + 61 + sum.cases[1].steps_completed);
}

// Each case's own start (what prepare_scene() gives a redundant scene): the first row is the assembly nearest it —
// here the crank-slider's two branches, the slider right of the crank (x_B > 0) or mirrored left of it — and a start
// of the wrong size or count is a programming error.
TEST(Batch, EachCaseStartsFromItsOwnPlacement) {
  std::vector<Model> models;
  models.reserve(2);
  models.push_back(crank_slider_case(0.3, nullptr));
  models.push_back(crank_slider_case(0.3, &models[0]));
  SweepOptions opt;
  opt.t_end = 1.0;
  opt.steps = 10;
  std::vector<Eigen::VectorXd> starts = {models[0].initial_positions(), models[1].initial_positions()};
  starts[1](3) = -starts[1](3);  // the slider mirrored: the other assembly branch
  std::vector<double> first_x(2, 0.0);
  std::mutex mu;
  BatchSummary sum = run_batch(
      {&models[0], &models[1]}, std::vector<SweepOptions>(2, opt), 1,
      [&](std::size_t c, const StepView& s) {
        std::lock_guard<std::mutex> lock(mu);
        if (s.step == 0) first_x[c] = s.q(3);
        return true;
      },
      &starts);
  ASSERT_EQ(sum.failed, 0);
  EXPECT_NEAR(first_x[0], 1.3, 1e-12);   // L2 cos 0 + sqrt(L3² − 0) with the slider to the right
  EXPECT_NEAR(first_x[1], -0.7, 1e-12);  // L2 cos 0 − L3: the mirrored branch
  starts[1].resize(2);
  EXPECT_THROW(run_batch({&models[0], &models[1]}, std::vector<SweepOptions>(2, opt), 1, nullptr, &starts), Error);
  starts.pop_back();
  EXPECT_THROW(run_batch({&models[0], &models[1]}, std::vector<SweepOptions>(2, opt), 1, nullptr, &starts), Error);
}

TEST(Batch, ModelsOfAnotherStructureAreAnalysedOnTheirOwn) {
  Model a = crank_slider_case(0.3, nullptr);
  ModelBuilder b;
  b.add_coordinate("x", 0.0);
  b.add_driver("d", 0, MotionLaw::linear(0.0, 1.0));
  b.share_analysis_with(a);
  Model c = std::move(b).build();
  ASSERT_NE(c.symbolic(), nullptr);
  EXPECT_NE(c.symbolic(), a.symbolic());
  EXPECT_THROW(run_batch({&a, nullptr}, SweepOptions{}, 1, nullptr), Error);
}

}  // namespace
}  // namespace phiq
