// `phiq run --summary`: the run summary (format 2) on success and on a failure to solve (status, failed step and
// time, message, worst constraints; the summary committed, no CSV), with phiq's version, the scene's name and
// path and the host; `phiq run -` reading the scene from standard input; `sweep-accuracy --json` on a failure;
// `batch --summary`, each case's outcome.
#include <gtest/gtest.h>

#include <unistd.h>

#include <climits>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "phiq/phiq.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;
using Json = nlohmann::json;

// The crank-slider driven by its slider beyond L2 + L3 = 1.3: the dead point at t = 0.5, no assembly at t = 0.6.
constexpr const char* kOutOfReach = R"(name: slider_out_of_reach
coordinates: {theta2: 0.5, xA: 0.26, yA: 0.14, xB: 1.2}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: 0.3, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: 1.0}
drivers:
  - {name: slide, coordinate: xB, law: {type: linear, initial: 1.2, rate: 0.2}}
time: {start: 0, end: 1, steps: 10}
)";

// 'name', as messages quote constraints (appended, not `"'" + name`: GCC 12 warns falsely on that, -Wrestrict).
std::string quoted(const std::string& name) { return std::string(1, '\'').append(name).append(1, '\''); }

// What every summary carries, whatever the outcome: the version, the scene, the host.
void expect_provenance(const Json& j, const std::string& scene_path) {
  EXPECT_EQ(j["format"], 2);
  EXPECT_EQ(j["phiq"], phiq::kVersion);
  EXPECT_EQ(j["scene"], scene_path);
  char host[HOST_NAME_MAX + 1] = {};
  ASSERT_EQ(gethostname(host, sizeof host - 1), 0);
  EXPECT_EQ(j["host"]["name"], std::string(host));
  // the first `model name` of /proc/cpuinfo, as this machine has one
  std::ifstream in("/proc/cpuinfo");
  std::string cpu = "unknown";
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  EXPECT_EQ(j["host"]["cpu"], cpu);
}

TEST_F(Cli, RunSummaryTellsWhyARunFailed) {
  const fs::path scene = write("reach.yaml", kOutOfReach), csv = dir_ / "r.csv", sum = dir_ / "r.json";
  write("r.csv", "previous good result\n");
  Result r = run("run " + scene.string() + " -o " + csv.string() + " --summary " + sum.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("step 6, t = 0.6: no assembly beyond t = 0.5"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("; wrote the summary only"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(csv), "previous good result\n") << "no CSV, not even a partial one";
  EXPECT_EQ(files(), (std::vector<std::string>{"r.csv", "r.json", "reach.yaml", "stderr.txt", "stdout.txt"}));
  const Json j = Json::parse(slurp(sum));
  expect_provenance(j, scene.string());
  EXPECT_EQ(j["name"], "slider_out_of_reach");
  EXPECT_EQ(j["status"], "not converged");
  EXPECT_EQ(j["failed_step"], 6);
  EXPECT_DOUBLE_EQ(j["failed_time"].get<double>(), 0.6);  // t_6 of the grid, 6 × 0.1
  // the message is stderr's line, less "phiq: SCENE: " and the note on the outputs
  const std::string message = j["message"];
  EXPECT_EQ(r.err, "phiq: " + scene.string() + ": " + message + "; wrote the summary only\n");
  EXPECT_EQ(message.rfind("step 6, t = 0.6: ", 0), 0u) << message;
  // the rows the message names, in its order: two constraints of the crank-slider beyond their tolerance
  ASSERT_FALSE(j["worst_constraints"].empty()) << j.dump(2);
  ASSERT_LE(j["worst_constraints"].size(), 3u);
  double previous = INFINITY;
  for (const Json& w : j["worst_constraints"]) {
    const std::string name = w["name"];
    const double residual = w["residual"];
    EXPECT_TRUE(name.rfind("crank", 0) == 0 || name.rfind("rod", 0) == 0 || name.rfind("slide", 0) == 0) << name;
    EXPECT_NE(message.find(quoted(name)), std::string::npos) << name << " not in: " << message;
    EXPECT_GT(residual, 1e-10) << "a worst row is beyond the tolerance";
    EXPECT_LE(residual, previous) << "largest first";
    previous = residual;
  }
  EXPECT_EQ(j["steps"], 6) << "rows 0 to 5 were delivered before step 6 failed";
  EXPECT_GT(j["newton_iterations"].get<int>(), 0);
  // without --summary: as before, nothing written
  r = run("run " + scene.string() + " -o " + csv.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("; no output written\n"), std::string::npos) << r.err;
}

// A model that cannot be made square (under-driven) fails at time.start, before any sweep: step 0, its time.
TEST_F(Cli, RunSummaryOfAnUnderDrivenScene) {
  std::string text = kOutOfReach;
  text = text.substr(0, text.find("drivers:")) + "time: {start: 0.25, end: 1, steps: 10}\n";
  const fs::path scene = write("free.yaml", text), sum = dir_ / "f.json";
  Result r = run("run -q " + scene.string() + " --summary " + sum.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(one_phiq_line(r.err));
  const Json j = Json::parse(slurp(sum));
  expect_provenance(j, scene.string());
  EXPECT_EQ(j["failed_step"], 0);
  EXPECT_EQ(j["failed_time"], 0.25);
  EXPECT_NE(j["status"], "success");
  EXPECT_EQ(r.err, "phiq: " + scene.string() + ": " + j["message"].get<std::string>() + "; wrote the summary only\n");
  EXPECT_EQ(j["steps"], 0);
  EXPECT_TRUE(r.out.empty()) << "no CSV on standard output either";
}

TEST_F(Cli, RunSummaryOnSuccessHasTheSameFields) {
  const fs::path scene = write("ok.yaml", phiq::test::kFourbarOutputs), sum = dir_ / "s.json";
  Result r = run("run -q " + scene.string() + " -o " + (dir_ / "ok.csv").string() + " --summary " + sum.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const Json j = Json::parse(slurp(sum));
  expect_provenance(j, scene.string());
  EXPECT_EQ(j["name"], "fourbar_outputs");
  EXPECT_EQ(j["status"], "success");
  EXPECT_EQ(j["message"], "");
  EXPECT_TRUE(j["failed_step"].is_null());
  EXPECT_TRUE(j["failed_time"].is_null());
  EXPECT_EQ(j["worst_constraints"], Json::array());
  EXPECT_EQ(j["steps"], 73);
  // a scene without a name: null, not ""
  std::string text = phiq::test::kFourbarOutputs;
  text.replace(text.find("name: fourbar_outputs\n"), 22, "");
  const fs::path unnamed = write("unnamed.yaml", text);
  ASSERT_EQ(run("run -q " + unnamed.string() + " -o " + (dir_ / "ok.csv").string() + " --summary " + sum.string()).code,
            0);
  EXPECT_TRUE(Json::parse(slurp(sum))["name"].is_null());
}

// `phiq run -`: the scene from standard input, the same rows as from its file; its errors name <stdin>.
TEST_F(Cli, RunReadsTheSceneFromStandardInput) {
  const fs::path scene = write("ok.yaml", phiq::test::kFourbarOutputs), sum = dir_ / "s.json";
  Result from_file = run("run -q " + scene.string());
  ASSERT_EQ(from_file.code, 0) << from_file.err;
  Result piped = run("run -q - --summary " + sum.string() + " <" + scene.string());
  ASSERT_EQ(piped.code, 0) << piped.err;
  EXPECT_EQ(piped.out, from_file.out);
  EXPECT_EQ(Json::parse(slurp(sum))["scene"], "<stdin>");
  const fs::path bad = write("bad.yaml", "coordinates: {x: 0}\ntime: {start: 0, end: 1, steps: 2}\nbogus: 1\n");
  Result r = run("run - <" + bad.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("phiq: <stdin>:3:1: bogus: unknown field 'bogus' (allowed: ", 0), 0u) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err));
  const fs::path reach = write("reach.yaml", kOutOfReach);
  r = run("run -q - <" + reach.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err.rfind("phiq: <stdin>: step 6, t = 0.6: ", 0), 0u) << r.err;
}

// sweep-accuracy --json, when the measurement cannot be made (the numerical reference fails at t = 0.6): the JSON
// says why, the CSV is not written.
TEST_F(Cli, SweepAccuracyJsonTellsWhyItFailed) {
  const fs::path scene = write("reach.yaml", kOutOfReach), json = dir_ / "a.json", csv = dir_ / "a.csv";
  Result r = run("sweep-accuracy " + scene.string() +
                 " --tolerances 1e-6 --steps-list 10 --predictors previous"
                 " --newton modified --linear-solvers klu --repeat 1 -o " +
                 csv.string() + " --json " + json.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_FALSE(fs::exists(csv));
  const Json j = Json::parse(slurp(json));
  EXPECT_EQ(j["format"], 2);
  EXPECT_EQ(j["phiq"], phiq::kVersion);
  EXPECT_EQ(j["status"], "failed");
  EXPECT_EQ(j["name"], "slider_out_of_reach");
  EXPECT_EQ(r.err, "phiq: sweep-accuracy: " + j["message"].get<std::string>() + "; wrote the JSON only\n");
  EXPECT_EQ(j["rows"], Json::array());
  EXPECT_FALSE(j.contains("reference"));
}

// batch --summary: every case's outcome, the failing one (the crank longer than the rod: stuck at θ2 where
// L2 sin θ2 = L3) with its step, time and worst constraints, the others with their files.
TEST_F(Cli, BatchSummaryHasEveryCasesOutcome) {
  const fs::path cases = write("cases.csv", "L2,L3\n0.2,1.0\n1.5,1.0\n0.4,1.2\n"), out = dir_ / "out",
                 sum = dir_ / "b.json";
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  Result r = run("batch -q " + scene + " " + cases.string() + " -o " + out.string() + " --threads 2 --summary " +
                 sum.string());
  EXPECT_EQ(r.code, 1) << r.err;
  const Json j = Json::parse(slurp(sum));
  EXPECT_EQ(j["format"], 1);
  EXPECT_EQ(j["phiq"], phiq::kVersion);
  EXPECT_EQ(j["scene"], scene);
  EXPECT_EQ(j["name"], "crank_slider_mixed");
  EXPECT_FALSE(j["host"]["cpu"].get<std::string>().empty());
  EXPECT_EQ(j["cases_file"], cases.string());
  EXPECT_EQ(j["cases"], 3);
  EXPECT_EQ(j["failed"], 1);
  EXPECT_EQ(j["written"], 2);
  ASSERT_EQ(j["results"].size(), 3u);
  for (int k : {0, 2}) {
    const Json& c = j["results"][k];
    const fs::path file = out / ("case" + std::to_string(k) + ".csv");
    EXPECT_EQ(c["case"], k);
    EXPECT_EQ(c["line"], k + 2);
    EXPECT_EQ(c["status"], "success");
    EXPECT_EQ(c["file"], file.string());
    EXPECT_TRUE(fs::exists(file));
    EXPECT_EQ(c["steps"], 181);
    EXPECT_TRUE(c["failed_step"].is_null());
  }
  const Json& bad = j["results"][1];
  EXPECT_EQ(bad["case"], 1);
  EXPECT_EQ(bad["line"], 3);
  EXPECT_TRUE(bad["file"].is_null());
  EXPECT_FALSE(fs::exists(out / "case1.csv"));
  EXPECT_NE(bad["status"], "success");
  const std::string message = bad["message"];
  // stderr's line for the case, less its prefix and the note on the output
  EXPECT_NE(r.err.find("case 1: " + message + "; no output written\n"), std::string::npos) << r.err;
  const std::string step = "step " + bad["failed_step"].dump() + ", t = ";
  EXPECT_EQ(message.rfind(step, 0), 0u) << message;
  EXPECT_GT(bad["failed_step"].get<int>(), 0);
  EXPECT_EQ(bad["steps"], bad["failed_step"]) << "the rows before the failed step";
  for (const Json& w : bad["worst_constraints"])
    EXPECT_NE(message.find(quoted(w["name"].get<std::string>())), std::string::npos) << message;
}

}  // namespace
