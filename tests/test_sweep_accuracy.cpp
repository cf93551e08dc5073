// `phiq sweep-accuracy` (tools/accuracy/sweep_accuracy.hpp): the grid's rows, errors that fall with the tolerance, the
// reference chosen (closed form, or the numerical run when no closed form fits), the scene's default marked, and
// bad input refused with one line and no file. Timings are measured but never asserted (bench/README.md).
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "phiq/csv_compare.hpp"
#include "sweep_accuracy.hpp"
#include "test_support.hpp"
#include "scratch_path.hpp"

namespace fs = std::filesystem;

namespace phiq {
namespace {

class SweepAccuracy : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = phiq::test::test_scratch_path("phiq_accuracy_");
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  struct Result {
    int code;
    std::string out, err;
  };
  Result run(const std::string& args) {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd =
        std::string(PHIQ_CLI) + " sweep-accuracy " + args + " >" + out.string() + " 2>" + err.string();
    const int st = std::system(cmd.c_str());
    return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, test::file_text(out), test::file_text(err)};
  }
  // Rows of a sweep-accuracy CSV as maps column → text.
  std::vector<std::map<std::string, std::string>> rows(const fs::path& csv) {
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);
    std::vector<std::string> cols;
    std::stringstream hs(line);
    for (std::string c; std::getline(hs, c, ',');) cols.push_back(c);
    std::vector<std::map<std::string, std::string>> out;
    while (std::getline(in, line)) {
      std::map<std::string, std::string> r;
      std::stringstream ls(line);
      std::string v;
      for (const std::string& c : cols) std::getline(ls, v, ','), r[c] = v;
      out.push_back(r);
    }
    return out;
  }
  std::string seed(const std::string& name) { return test::model_path("seed/" + name + ".yaml"); }
  fs::path dir_;
};

constexpr const char* kHeader =
    "scene,reference,tolerance,steps,predictor,newton,linear_solver,err_q,err_v,err_a,iterations_per_step,"
    "factorizations_per_step,us_per_step,status,default";

TEST_F(SweepAccuracy, CrankSliderGridAgainstItsClosedForm) {
  const fs::path csv = dir_ / "acc.csv";
  Result r = run(seed("crank_slider_mixed") +
                 " --tolerances 1e-6,1e-10,1e-12 --steps-list 45,180 --predictors previous,cubic --newton modified"
                 " --linear-solvers klu --repeat 1 -o " +
                 csv.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(test::file_text(csv).substr(0, test::file_text(csv).find('\n')), kHeader);
  const auto rs = rows(csv);
  ASSERT_EQ(rs.size(), 12u);            // 3 tolerances × 2 step counts × 2 predictors
  std::map<std::string, double> err_q;  // "steps/predictor/tolerance" → err_q
  int defaults = 0;
  for (const auto& row : rs) {
    EXPECT_EQ(row.at("scene"), "crank_slider_mixed");
    EXPECT_EQ(row.at("reference"), "closed-form:crank-slider");
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("linear_solver"), "klu");
    EXPECT_GE(std::stod(row.at("factorizations_per_step")), 1.0);  // q̇ and q̈ need Φq at the solution every step
    EXPECT_GT(std::stod(row.at("us_per_step")), 0.0);
    for (const char* e : {"err_q", "err_v", "err_a"}) EXPECT_GE(std::stod(row.at(e)), 0.0) << e;
    err_q[row.at("steps") + "/" + row.at("predictor") + "/" + row.at("tolerance")] = std::stod(row.at("err_q"));
    // the scene's own settings: 180 steps, tolerance 1e-10, auto = cubic (it outputs q̈), modified Newton, KLU
    const bool is_default =
        row.at("steps") == "180" && row.at("tolerance") == "1e-10" && row.at("predictor") == "cubic";
    EXPECT_EQ(row.at("default"), is_default ? "1" : "0");
    defaults += is_default;
  }
  EXPECT_EQ(defaults, 1);
  for (const char* k : {"45/previous/", "45/cubic/", "180/previous/", "180/cubic/"}) {
    const std::string key(k);
    EXPECT_LT(err_q.at(key + "1e-12"), err_q.at(key + "1e-06")) << key;
    EXPECT_LT(err_q.at(key + "1e-12"), 1e-9) << key;
    EXPECT_LT(err_q.at(key + "1e-10"), 1e-8) << key;
  }
}

TEST_F(SweepAccuracy, JsonHasTheSettingsTheDefaultAndTheReference) {
  const fs::path json = dir_ / "acc.json";
  Result r = run(seed("fourbar_natural") +
                 " --tolerances 1e-5,1e-12 --steps-list 90 --predictors quadratic"
                 " --newton modified,full --linear-solvers klu,umfpack --repeat 1 --json " +
                 json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());  // with --json and no -o, nothing on standard output
  const auto j = nlohmann::json::parse(test::file_text(json));
  EXPECT_EQ(j["format"], 2);
  EXPECT_EQ(j["phiq"], phiq::kVersion);
  EXPECT_EQ(j["status"], "success");
  EXPECT_EQ(j["message"], "");
  EXPECT_FALSE(j["host"]["name"].get<std::string>().empty());
  EXPECT_FALSE(j["host"]["cpu"].get<std::string>().empty());
  EXPECT_EQ(j["reference"], "closed-form:fourbar:L1=1,L2=0.4,L3=1.2,L4=1,theta0=0,omega=1,branch=1");
  EXPECT_EQ(j["scene_default"]["tolerance"], 1e-10);
  EXPECT_EQ(j["scene_default"]["predictor"], "cubic");
  EXPECT_EQ(j["scene_default"]["newton"], "modified");
  EXPECT_EQ(j["scene_default"]["linear_solver"], "klu");
  ASSERT_EQ(j["rows"].size(), 8u);
  for (const auto& row : j["rows"]) {
    const double tol = row["tolerance"];
    // positions within a few tolerances of the exact four-bar: the error estimate is of the right size
    EXPECT_LT(row["err_q"].get<double>(), 20 * tol) << row.dump();
    EXPECT_LT(row["err_a"].get<double>(), tol < 1e-10 ? 1e-9 : 1e-3) << row.dump();
  }
}

TEST_F(SweepAccuracy, WithoutAClosedFormTheReferenceIsTheSceneAtTightTolerance) {
  // The crank-slider under another name: no closed form is suggested, the numerical reference is used.
  std::string text = test::file_text(seed("crank_slider_mixed"));
  text.replace(text.find("name: crank_slider_mixed"), 24, "name: my_slider");
  std::ofstream(dir_ / "slider.yaml") << text;
  // A scene named like a four-bar that is not one: the closed form does not fit, the run falls back with a note.
  std::string wrong = test::file_text(seed("crank_slider_mixed"));
  wrong.replace(wrong.find("name: crank_slider_mixed"), 24, "name: fourbar_not_really");
  std::ofstream(dir_ / "wrong.yaml") << wrong;
  for (const char* scene : {"slider.yaml", "wrong.yaml"}) {
    const fs::path csv = dir_ / "acc.csv";
    // modified Newton: full Newton's quadratic convergence overshoots any tolerance here (error 2e-16 at 1e-5)
    Result r = run((dir_ / scene).string() +
                   " --tolerances 1e-4,1e-12 --steps-list 60 --predictors quadratic"
                   " --newton modified --linear-solvers klu --repeat 1 -o " +
                   csv.string());
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rs = rows(csv);
    ASSERT_EQ(rs.size(), 2u);
    EXPECT_EQ(rs[0].at("reference"), "numerical");
    EXPECT_LT(std::stod(rs[1].at("err_q")), 1e-11) << scene;
    EXPECT_LT(std::stod(rs[1].at("err_q")), std::stod(rs[0].at("err_q"))) << scene;
    EXPECT_GT(std::stod(rs[0].at("err_q")), 1e-6) << scene;  // a 1e-4 run differs from the 1e-14 reference
    if (std::string(scene) == "wrong.yaml") {
      EXPECT_NE(r.err.find("note: the scene's name suggests closed-form:fourbar"), std::string::npos) << r.err;
    }
  }
}

TEST_F(SweepAccuracy, RedundantScenesAreSweptAsPhiqRunSweepsThem) {
  // A door on three hinges (10 consistent redundant equations): swept on its independent rows, as `phiq run` does,
  // against the numerical reference of that same square model; it was refused as "not square" before.
  const fs::path csv = dir_ / "acc.csv";
  Result r = run(test::model_path("redundant/door_three_hinges.yaml") +
                 " --tolerances 1e-4,1e-11 --steps-list 30 --predictors previous --newton full --linear-solvers klu"
                 " --repeat 1 -o " +
                 csv.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const auto rs = rows(csv);
  ASSERT_EQ(rs.size(), 2u);
  for (const auto& row : rs) {
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("reference"), "numerical");
  }
  EXPECT_LT(std::stod(rs[1].at("err_q")), 1e-10);
  EXPECT_LT(std::stod(rs[1].at("err_q")), std::stod(rs[0].at("err_q")));
  // Its third hinge 5 mm off the axis: inconsistent, refused as `phiq run` refuses it (exit 1), naming the hinges.
  const fs::path refused = dir_ / "refused.csv";
  r = run(test::model_path("redundant/door_misaligned.yaml") + " --tolerances 1e-6 -o " + refused.string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("t = 0: inconsistent redundant constraints"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("conflicting constraints: hinge1, hinge3"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(refused));
}

TEST_F(SweepAccuracy, BadInputIsOneLineAndWritesNothing) {
  const std::string out = " -o " + (dir_ / "acc.csv").string();
  const std::string cs = seed("crank_slider_mixed");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {cs + " --tolerances 2", "--tolerances"},
      {cs + " --tolerances 1e-6,,1e-8", "--tolerances"},
      {cs + " --tolerances abc", "--tolerances"},
      {cs + " --steps-list 0", "--steps-list"},
      {cs + " --predictors previous,magic", "--predictors"},
      {cs + " --newton half", "--newton"},
      {cs + " --linear-solvers mumps", "--linear-solvers"},
      {cs + " --repeat 0", "--repeat"},
      {cs + " --reference closed-form:fourbar", "does not satisfy"},  // the wrong mechanism, asked for explicitly
      {cs + " --reference closed-form:crank-slider:omega=3", "does not satisfy"},  // the wrong drive
      {cs + " --reference closed-form:pendulum", "unknown closed form"},
      {seed("fourbar_natural") + " --reference closed-form:fourbar:branch=-1", "another assembly branch"},
      {cs + " --reference exact", "--reference"},
      {(dir_ / "missing.yaml").string(), "cannot open"},
  };
  for (const auto& [args, what] : cases) {
    Result r = run(args + out);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << args << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "acc.csv")) << args;
  }
  std::vector<std::string> left;
  for (auto& e : fs::directory_iterator(dir_)) left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"stderr.txt", "stdout.txt"}));  // no temporaries left behind
  Result r = run(cs + " --tolerances 1e-6 -o " + (dir_ / "no_such_dir" / "acc.csv").string());
  EXPECT_EQ(r.code, 3) << r.err;
}

TEST(SweepAccuracyLists, ParseAndRefuse) {
  EXPECT_EQ(tools::parse_tolerances("1e-4,1e-14"), (std::vector<double>{1e-4, 1e-14}));
  EXPECT_EQ(tools::parse_steps("45,180"), (std::vector<Index>{45, 180}));
  EXPECT_EQ(tools::parse_predictors("previous,quadratic"),
            (std::vector<Predictor>{Predictor::kPrevious, Predictor::kQuadratic}));
  EXPECT_EQ(tools::parse_newton("full"), (std::vector<JacobianUpdate>{JacobianUpdate::kEveryIteration}));
  EXPECT_EQ(tools::parse_linear_solvers("umfpack,klu"),
            (std::vector<LinearSolverKind>{LinearSolverKind::kUmfpack, LinearSolverKind::kKlu}));
  EXPECT_THROW(tools::parse_tolerances("0"), std::invalid_argument);
  EXPECT_THROW(tools::parse_tolerances("1e-6x"), std::invalid_argument);
  EXPECT_THROW(tools::parse_steps("-3"), std::invalid_argument);
  EXPECT_THROW(tools::parse_steps(""), std::invalid_argument);
}

TEST(SweepAccuracyApi, AStopRequestEndsTheMeasurement) {
  Scene s = load_scene(test::model_path("seed/crank_slider_mixed.yaml"));
  tools::AccuracyOptions o;
  o.tolerances = {1e-6};
  std::atomic<bool> stop{true};
  o.stop = &stop;
  EXPECT_THROW(tools::measure_accuracy(s, o), tools::AccuracyCancelled);
  o.reference = "numerical";  // stopped inside the reference run as well
  EXPECT_THROW(tools::measure_accuracy(s, o), tools::AccuracyCancelled);
  stop = false;
  o.steps = {10};
  o.predictors = {Predictor::kQuadratic};
  o.repeat = 1;
  EXPECT_EQ(tools::measure_accuracy(s, o).rows.size(), 4u);  // newton × LU
}

TEST_F(SweepAccuracy, CtrlCWritesNothing) {
  // nfourbar 200 over a long grid, interrupted after a moment (SIGINT, or SIGTERM as from a job scheduler): exit
  // 128 + the signal, no file, no temporary left
  const fs::path scene = dir_ / "nf.yaml", csv = dir_ / "acc.csv", json = dir_ / "acc.json";
  ASSERT_EQ(std::system((std::string(PHIQ_CLI) + " generate nfourbar 200 --steps 400 -o " + scene.string()).c_str()),
            0);
  for (const auto& [sig, status] : {std::pair<std::string, std::string>{"INT", "130\n"}, {"TERM", "143\n"}}) {
    const std::string cmd = "sh -c '" + std::string(PHIQ_CLI) + " sweep-accuracy " + scene.string() + " -o " +
                            csv.string() + " --json " + json.string() + " 2>" + (dir_ / "err.txt").string() +
                            " & pid=$!; sleep 1; kill -" + sig + " $pid; wait $pid; echo $? >" +
                            (dir_ / "status.txt").string() + "'";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_EQ(test::file_text(dir_ / "status.txt"), status) << test::file_text(dir_ / "err.txt");
    EXPECT_NE(test::file_text(dir_ / "err.txt").find("interrupted (SIG" + sig + "); no output written"),
              std::string::npos)
        << test::file_text(dir_ / "err.txt");
    std::vector<std::string> left;
    for (auto& e : fs::directory_iterator(dir_)) left.push_back(e.path().filename().string());
    std::sort(left.begin(), left.end());
    EXPECT_EQ(left, (std::vector<std::string>{"err.txt", "nf.yaml", "status.txt"}));
  }
}

TEST(SweepAccuracyApi, DefaultGridSkipsPredictorsTheSceneCannotFeed) {
  // Positions only: linear, quadratic and cubic need q̇ / q̈, which the scene does not compute; they are left out,
  // said so.
  std::string text =
      "phiq: 1\nname: crank_slider_positions\nparameters: {L2: 0.3, L3: 1.0}\n"
      "coordinates: {theta2: 0.0, xA: 0.28, yA: 0.03, xB: 1.25}\n"
      "points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}\n"
      "constraints:\n"
      "  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}\n"
      "  - {name: rod, type: distance, points: [A, B], length: L3}\n"
      "drivers:\n  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}\n"
      "time: {start: 0, end: pi, steps: 40}\noutput: {velocities: false, accelerations: false}\n";
  Scene s = parse_scene(text, "positions.yaml");
  tools::AccuracyOptions o;
  o.tolerances = {1e-6, 1e-12};
  o.newton = {JacobianUpdate::kEveryIteration};
  o.linear_solvers = {LinearSolverKind::kKlu};
  o.repeat = 1;
  const tools::AccuracyReport rep = tools::measure_accuracy(s, o);
  EXPECT_EQ(rep.reference_kind, "closed-form:crank-slider");
  ASSERT_EQ(rep.rows.size(), 18u);  // 3 step counts (10, 40, 160) × previous, secant, parabolic × 2 tolerances
  for (const auto& row : rep.rows) {
    EXPECT_TRUE(row.setting.predictor == Predictor::kPrevious || row.setting.predictor == Predictor::kSecant ||
                row.setting.predictor == Predictor::kParabolic);
    EXPECT_TRUE(std::isnan(row.err_v) && std::isnan(row.err_a));
    EXPECT_LT(row.err_q, row.setting.tolerance == 1e-12 ? 1e-10 : 1e-4);
  }
  EXPECT_EQ(rep.notes.size(), 4u);  // linear, hermite, quadratic and cubic skipped, each with a note
  EXPECT_EQ(rep.scene_default.predictor, Predictor::kParabolic);  // auto without derivatives
}

}  // namespace
}  // namespace phiq
