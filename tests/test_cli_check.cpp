// `phiq check` and `phiq assemble`: counts and assembly in text and JSON, the rank analysis of redundant
// constraints (rank, dof, conflicts) at the time asked, `run` refusing inconsistent redundancy in one line, and
// failure times written with their digits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

TEST_F(Cli, CheckReportsCountsAndAssembly) {
  Result r = run("check " + phiq::test::model_path("seed/fourbar_reference_point.yaml"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("coordinates   9"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("equations     9 (8 kinematic, 1 rheonomic)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("assembly      success"), std::string::npos) << r.out;
}

// The zero of a driven joint angle is never chosen silently: check names the reference directions it uses.
TEST_F(Cli, CheckNamesWhereJointAnglesAreMeasuredFrom) {
  Result r = run("check " + phiq::test::model_path("spatial/rssr.yaml"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("joint angle   motor: joint crank_hinge from x_a = [1, 0, 0] (default: state `ref` to choose) "
                       "to x_b = [1, 0, 0] (default: state `ref` to choose), in the sides' body frames"),
            std::string::npos)
      << r.out;
  r = run("check --json " + phiq::test::model_path("spatial/cardan.yaml"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"joint_angles\": [\n    {\n      \"driver\": \"motor\",\n      \"joint\": \"hinge1\",\n"
                       "      \"ref_a\": [\n        1.0,\n        0.0,\n        0.0\n      ],"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("\"stated_a\": true,\n      \"stated_b\": true"), std::string::npos) << r.out;
}

// Each part's mass, centre and inertia with where they came from: a 1.2 × 0.04 × 0.01 m steel box of 3.768 kg and
// Izz = m (1.2² + 0.04²)/12 = 0.452662 kg·m², and a stated crank; the JSON gives the tensors whole.
TEST_F(Cli, CheckListsEachPartsMassAndItsSource) {
  const fs::path scene =
      write("parts.yaml", slurp(phiq::test::model_path("seed/fourbar_reference_point.yaml")) +
                              "\nparts:\n  coupler: {density: 7850, shapes: [{type: box, size: [1.2, 0.04, 0.01]}]}\n"
                              "  crank: {mass: 2, center_of_mass: [0.01, 0], inertia: 0.03}\n");
  Result r = run("check " + scene.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("part          coupler on body coupler, 1 shape: mass 3.768 kg (from density 7850 kg/m³), "
                       "centre [0, 0] m, Izz 0.452662 kg·m² about the centre\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("part          crank on body crank, 0 shapes: mass 2 kg (stated), centre [0.01, 0] m, Izz 0.03"),
            std::string::npos)
      << r.out;
  r = run("check --json " + scene.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"mass_source\": \"density\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"mass_source\": \"stated\""), std::string::npos) << r.out;
}

// Each applied load as phiq took it: what it is, what it acts on, its values as written (rates, laws).
TEST_F(Cli, CheckListsEachLoadAsWritten) {
  const fs::path scene = write(
      "loads.yaml", slurp(phiq::test::model_path("seed/fourbar_reference_point.yaml")) +
                        "\nloads:\n"
                        "  forces: [{name: drag, part: coupler, at: [0.1, 0], force: [-2*der(x3), 5], axes: part}]\n"
                        "  torques: [{name: brake, part: rocker, torque: {law: {type: linear, initial: 1, rate: 2}}}]\n"
                        "  springs: [{name: strut, between: [{part: crank}, {point: [1, 1]}], free_length: 0.3,\n"
                        "             law: {type: polynomial, coefficients: [0, 40]}, tension: 3*sin(t)}]\n"
                        "  torsional_springs: [{name: coil, angle: psi3 - psi2, stiffness: 4, damping: 0.2},\n"
                        "                      {name: gearbox, coordinate: psi2, friction: 0.5, inertia: 0.02}]\n"
                        "limits: [{name: swing, of: psi4, range: [-1, 2.5], rate: [-3, 3]}]\n");
  const Result r = run("check " + scene.string());
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* line :
       {"load          force 'drag' on 'coupler' at [0.1, 0]: [-2*der(x3), 5] (part axes) N\n",
        "load          torque 'brake' on 'rocker': linear 1 + 2*t of t N·m\n",
        "load          spring 'strut' between 'crank' [0, 0] and 'ground' [1, 1]: stiffness polynomial of degree 1, "
        "free length 0.3, damping 0, preload 0, tension 3*sin(t)\n",
        "load          torsional spring 'coil' on 'psi3 - psi2': stiffness 4, free angle 0, damping 0.2, moment 0\n",
        "load          torsional spring 'gearbox' on 'psi2': stiffness 0, free angle 0, damping 0, friction 0.5, "
        "inertia 0.02, moment 0\n",
        "limit         swing: 'psi4' in [-1, 2.5]\n", "limit         swing: the rate of 'psi4' in [-3, 3]\n"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << r.out;
}

TEST_F(Cli, CheckListsWhatPressesEachBearing) {
  // a pin's journal (models/dynamics/fourbar_pin_friction.yaml) and a cam follower's guide with a tilt arm
  const Result pins = run("check " + phiq::test::model_path("dynamics/fourbar_pin_friction.yaml"));
  ASSERT_EQ(pins.code, 0) << pins.err;
  EXPECT_NE(pins.out.find("torsional spring 'O_bearing' on 'psi2': stiffness 0, free angle 0, damping 0, moment 0, "
                          "bearing 'O' friction 0.15 x (0.01 m x |F_r|)\n"),
            std::string::npos)
      << pins.out;
  const fs::path scene =
      write("slide.yaml",
            phiq::test::replace_first(phiq::test::model_file_text("cams/eccentric_roller.yaml", "output:"), "time:",
                                      "parts: {rod: {mass: 1, center_of_mass: [0, 0], inertia: 1}}\n"
                                      "loads: {torsional_springs: [{name: rub, coordinate: yf, bearing: {joint: guide, "
                                      "coefficient: 0.3, moment_arm: 0.1}}]}\ntime:"));
  const Result slide = run("check " + scene.string());
  ASSERT_EQ(slide.code, 0) << slide.err;
  EXPECT_NE(slide.out.find("bearing 'guide' friction 0.3 x (|F_r| + |M| / 0.1 m)\n"), std::string::npos) << slide.out;
}

TEST_F(Cli, CheckJsonIsOneVersionedObject) {
  Result r = run("check --json " + phiq::test::model_path("seed/fourbar_natural.yaml"));
  ASSERT_EQ(r.code, 0) << r.err;
  // key order and values, without a JSON library in the test: the format is documented line by line
  for (const char* part : {"\"format\": 1", "\"coordinates\": 5", "\"equations\": 5", "\"kinematic_equations\": 4",
                           "\"driver_equations\": 1", "\"status\": \"success\"", "\"worst\": []"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  EXPECT_EQ(r.out.front(), '{');
  EXPECT_EQ(r.out.substr(r.out.size() - 2), "}\n");
}

TEST_F(Cli, CheckJsonNamesTheWorstConstraintsWhenAssemblyFails) {
  // a coupler too short to close the loop: no assembly exists
  std::string scene = slurp(phiq::test::model_path("seed/fourbar_natural.yaml"));
  scene.replace(scene.find("L3: 1.2"), 7, "L3: 0.1");
  fs::path p = write("open.yaml", scene);
  Result r = run("check --json " + p.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("\"status\": \"not converged\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"constraint\": \""), std::string::npos) << r.out;
}

const char* kPlanarDoorMisaligned = R"(phiq: 1
coordinates: {x: 0.01, y: -0.02, psi: 0.1}
bodies: {door: [x, y, psi]}
constraints:
  - {name: pin1, type: revolute, between: [{body: door, at: [0, 0]}, {body: ground, at: [0, 0]}]}
  - {name: pin2, type: revolute, between: [{body: door, at: [0, 0]}, {body: ground, at: [0.001, 0]}]}
drivers:
  - {name: motor, coordinate: psi, law: {type: linear, initial: 0.2, rate: 1}}
time: {start: 0, end: 1, steps: 10}
)";

TEST_F(Cli, CheckJsonReportsRankDofAndRedundantConstraints) {
  Result r = run("check --json " + phiq::test::model_path("redundant/parallelogram_fifth_bar.yaml"));
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  for (const char* part :
       {"\"coordinates\": 12", "\"equations\": 13", "\"rank\": 11", "\"dof\": 1", "\"driven_dof\": 0",
        "\"grubler\": ", "\"redundant\": [\n    \"A3\"\n  ]", "\"name\": \"A3[1]\"", "\"consistent\": true",
        "\"conflicts\": []", "\"rank_uncertain\": false"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  Result text = run("check " + phiq::test::model_path("redundant/parallelogram_fifth_bar.yaml"));
  EXPECT_NE(text.out.find("redundant     A3\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("dof           1 (0 not driven)\n"), std::string::npos) << text.out;
}

TEST_F(Cli, CheckNamesTheConflictsOfInconsistentRedundancy) {
  fs::path p = write("door.yaml", kPlanarDoorMisaligned);
  Result r = run("check --json " + p.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("\"consistent\": false"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"conflicts\": [\n    \"pin1\",\n    \"pin2\"\n  ]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"status\": \"inconsistent redundant constraints\""), std::string::npos) << r.out;
}

TEST_F(Cli, RunRefusesInconsistentRedundancyInOneLineAndWritesNothing) {
  fs::path p = write("door.yaml", kPlanarDoorMisaligned);
  Result r = run("run " + p.string() + " -o " + (dir_ / "out.csv").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("t = 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("conflicting constraints: pin1, pin2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no output written"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.csv"));
}

TEST_F(Cli, AssembleWritesTheAssembledCoordinatesAsOneCsvRow) {
  const fs::path out = dir_ / "q.csv";
  Result r =
      run("assemble " + phiq::test::model_path("redundant/parallelogram_fifth_bar.yaml") + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string text = slurp(out);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2) << text;
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,x1,y1,psi1,x2,y2,psi2,x3,y3,psi3,xc,yc,psic");
  // the row: every crank at pi/3 (the motor at t = 0), the coupler's left end at (cos, sin) of it
  std::vector<double> v;
  std::stringstream row(text.substr(text.find('\n') + 1));
  for (std::string cell; std::getline(row, cell, ',');) v.push_back(std::stod(cell));
  ASSERT_EQ(v.size(), 13u);
  for (int k : {3, 6, 9}) EXPECT_NEAR(v[k], M_PI / 3, 1e-10);
  EXPECT_NEAR(v[10], 0.5, 1e-10);
  EXPECT_NEAR(v[11], std::sqrt(3.0) / 2, 1e-10);
  // an inconsistent model: exit 1, nothing written
  fs::path p = write("door.yaml", kPlanarDoorMisaligned);
  EXPECT_EQ(run("assemble " + p.string() + " -o " + (dir_ / "door.csv").string()).code, 1);
  EXPECT_FALSE(fs::exists(dir_ / "door.csv"));
}

TEST_F(Cli, CheckAnalysesTheConfigurationAtTheTimeAsked) {
  const std::string scene = phiq::test::model_path("redundant/parallelogram_change_point.yaml");
  Result normal = run("check --json " + scene);
  ASSERT_EQ(normal.code, 0) << normal.err;
  EXPECT_NE(normal.out.find("\"rank\": 8"), std::string::npos) << normal.out;
  EXPECT_NE(normal.out.find("\"rank_uncertain\": false"), std::string::npos) << normal.out;
  // the crank driven to 0: flat, a change point; assembled only to about 1e-6 there, which the analysis reports
  Result flat = run("check --json --time -1.0471975511965976 " + scene);
  EXPECT_NE(flat.out.find("\"time\": -1.0471975511965976"), std::string::npos) << flat.out;
  EXPECT_NE(flat.out.find("\"rank_uncertain\": true"), std::string::npos) << flat.out;
  EXPECT_NE(flat.out.find("singular value"), std::string::npos) << flat.out;
}

// Times in failures keep their digits: time.start 1e-7 is "t = 1e-07", not std::to_string's "t = 0.000000" (run's
// refusal of an inconsistent model at the start, assemble's failure).
TEST_F(Cli, FailureTimesKeepTheirDigits) {
  std::string text = kPlanarDoorMisaligned;
  text.replace(text.find("start: 0,"), 9, "start: 1e-7,");
  const fs::path p = write("door.yaml", text);
  for (const std::string cmd : {"run ", "assemble "}) {
    Result r = run(cmd + p.string() + " -o " + (dir_ / "out.csv").string());
    EXPECT_EQ(r.code, 1) << cmd << r.err;
    EXPECT_TRUE(one_phiq_line(r.err)) << cmd;
    EXPECT_NE(r.err.find("door.yaml: t = 1e-07: "), std::string::npos) << cmd << r.err;
    EXPECT_EQ(r.err.find("0.000000"), std::string::npos) << cmd << r.err;
  }
  Result c = run("check " + p.string());
  EXPECT_NE(c.out.find(" at t = 1e-07 in "), std::string::npos) << c.out;
}

}  // namespace
