// Scene loading: valid scenes build the right model; bad scenes give one-line errors naming file, line, field;
// the solver settings a scene may give. Indexed families (`for i in A..B`) are test_scene_families.cpp.
#include <gtest/gtest.h>

#include <filesystem>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

const char* kGood = R"(phiq: 1
parameters: {L2: 0.3, L3: 2*L2 + 0.4}
coordinates:
  theta2: 0
  xA: 0.3
  yA: 0
  xB: 1.3
points:
  O: [0, 0]
  A: [xA, yA]
  B: [xB, 0]
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}
time: {start: 0, end: pi/2, steps: 4}
output: {velocities: true}
)";

// The good scene with the first occurrence of `from` replaced; the error a scene gives.
std::string variant(const std::string& from, const std::string& to) { return test::replace_first(kGood, from, to); }

TEST(Scene, GoodSceneBuildsTheModelItDescribes) {
  Scene s = parse_scene(kGood, "good.yaml");
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 4);
  EXPECT_EQ(m.num_equations(), 4);
  ASSERT_EQ(m.constraints().size(), 3u);
  EXPECT_EQ(m.constraints()[0].name, "crank");
  EXPECT_EQ(m.constraints()[0].kind, "polar");
  EXPECT_EQ(m.constraints()[2].name, "motor");
  EXPECT_TRUE(m.constraints()[2].depends_on_time);
  EXPECT_EQ(m.coordinate_unit(0), Unit::kAngle);
  EXPECT_EQ(m.coordinate_unit(3), Unit::kLength);
  EXPECT_DOUBLE_EQ(m.length_scale(), 1.0);  // L3 = 2*0.3 + 0.4, the longest link
  EXPECT_DOUBLE_EQ(s.sweep.t_end, M_PI / 2);
  EXPECT_EQ(s.sweep.steps, 4);
  EXPECT_TRUE(s.sweep.velocities);
  EXPECT_FALSE(s.sweep.accelerations);
  EXPECT_EQ(s.sweep.coordinate_columns.size(), 4u);
  // the polar row is a length, the driver row has the unit of its coordinate
  EXPECT_EQ(m.row_unit(0), Unit::kLength);
  EXPECT_EQ(m.row_unit(3), Unit::kAngle);
}

TEST(Scene, JsonIsReadAsWellAndGivesTheSameModel) {
  const char* json = R"({"parameters": {"L2": 0.3, "L3": "2*L2 + 0.4"},
 "coordinates": {"theta2": 0, "xA": 0.3, "yA": 0, "xB": 1.3},
 "points": {"O": [0, 0], "A": ["xA", "yA"], "B": ["xB", 0]},
 "constraints": [{"name": "crank", "type": "polar", "point": "A", "origin": "O", "length": "L2", "angle": "theta2"},
                 {"name": "rod", "type": "distance", "points": ["A", "B"], "length": "L3"}],
 "drivers": [{"name": "motor", "coordinate": "theta2", "law": {"type": "linear", "initial": 0, "rate": 2}}],
 "time": {"start": 0, "end": "pi/2", "steps": 4}, "output": {"velocities": true}})";
  Scene a = parse_scene(kGood, "good.yaml"), b = parse_scene(json, "good.json");
  test::Trace ta, tb;
  ASSERT_EQ(test::sweep(*a.model, a.sweep, &ta), SolveStatus::kSuccess);
  ASSERT_EQ(test::sweep(*b.model, b.sweep, &tb), SolveStatus::kSuccess);
  ASSERT_EQ(ta.q.size(), tb.q.size());
  for (std::size_t k = 0; k < ta.q.size(); ++k) {
    EXPECT_EQ(ta.q[k], tb.q[k]);  // bit for bit: the same model
    EXPECT_EQ(ta.qd[k], tb.qd[k]);
  }
}

TEST(Scene, YamlSyntaxErrorHasLineAndColumn) {
  std::string m = error_of(variant("points:\n  O: [0, 0]", "points:\n  O: [0, 0"));
  EXPECT_HAS(m, "YAML syntax error");
  EXPECT_HAS(m, "bad.yaml:");
}

TEST(Scene, UnknownFieldIsNamedWithItsPathAndLine) {
  std::string m = error_of(variant("time: {start: 0,", "time: {begin: 0, start: 0,"));
  EXPECT_HAS(m, "bad.yaml:17:");
  EXPECT_HAS(m, "time.begin");
  EXPECT_HAS(m, "unknown field 'begin'");
}

TEST(Scene, UnknownTopLevelField) {
  std::string m = error_of(std::string(kGood) + "outputs: {}\n");
  EXPECT_HAS(m, "unknown field 'outputs'");
  EXPECT_HAS(m, "bad.yaml:19:");
}

TEST(Scene, DuplicateCoordinateName) {
  std::string m = error_of(variant("  yA: 0\n", "  yA: 0\n  xA: 0.1\n"));
  EXPECT_HAS(m, "duplicate name 'xA'");
  EXPECT_HAS(m, "bad.yaml:7:");
}

TEST(Scene, DuplicateConstraintName) {
  std::string m = error_of(variant("{name: rod,", "{name: crank,"));
  EXPECT_HAS(m, "duplicate constraint or driver name 'crank'");
  EXPECT_HAS(m, "constraints[1].name");
}

TEST(Scene, UnknownPointAndCoordinateNames) {
  EXPECT_HAS(error_of(variant("points: [A, B]", "points: [A, Q]")), "unknown point 'Q'");
  std::string m = error_of(variant("coordinate: theta2", "coordinate: theta9"));
  EXPECT_HAS(m, "drivers[0].coordinate");
  EXPECT_HAS(m, "unknown coordinate 'theta9'");
  EXPECT_HAS(m, "bad.yaml:16:");
  EXPECT_HAS(error_of(variant("B: [xB, 0]", "B: [xQ, 0]")), "unknown name 'xQ'");
}

TEST(Scene, NanAndInfiniteNumbersAreRefused) {
  std::string m = error_of(variant("xA: 0.3", "xA: .nan"));
  EXPECT_HAS(m, "coordinates.xA");
  EXPECT_HAS(m, "not a finite number");
  EXPECT_HAS(error_of(variant("length: L3", "length: .inf")), "not a finite number");
  EXPECT_HAS(error_of(variant("L2: 0.3", "L2: 1e999")), "parameters.L2: '1e999' is out of the range of a double");
}

TEST(Scene, ImpossibleValuesAreRefused) {
  std::string m = error_of(variant("length: L3", "length: -1"));
  EXPECT_HAS(m, "constraints[1].length");
  EXPECT_HAS(m, "must be positive");
  EXPECT_HAS(error_of(variant("steps: 4", "steps: -4")), "time.steps");
  EXPECT_HAS(error_of(variant("steps: 4", "steps: 2.5")), "expected a whole number");
  EXPECT_HAS(error_of(variant("end: pi/2", "end: 0")), "end equals start");
  // steps that would not move time (run_sweep refuses them): below the rounding of the times, or an overflowing span
  const std::string time = "time: {start: 0, end: pi/2, steps: 4}";
  EXPECT_HAS(error_of(variant(time, "time: {start: 1, end: 1.000000000000001, steps: 4}")),
             "time.end: 4 steps from t = 1 to 1 are 2.78e-16 s each, below the rounding of the times");
  EXPECT_HAS(error_of(variant(time, "time: {start: -1e308, end: 1e308, steps: 4}")),
             "time.end: the span from t = -1e+308 to 1e+308 is not a finite number");
}

TEST(Scene, WrongTypes) {
  EXPECT_HAS(error_of(variant("points: [A, B]", "points: A")), "a segment is [from, to]");
  EXPECT_HAS(error_of(variant("O: [0, 0]", "O: [0, 0, 0]")), "a point is [x, y]");
  EXPECT_HAS(error_of(variant("velocities: true", "velocities: maybe")), "expected true or false");
  EXPECT_HAS(error_of(variant("output: {velocities: true}", "output: [velocities]")), "expected a mapping");
  EXPECT_HAS(error_of(variant("{name: crank, type: polar", "{name: [crank], type: polar")), "expected a single value");
}

TEST(Scene, UnknownKindsAndLaws) {
  EXPECT_HAS(error_of(variant("type: distance", "type: distanse")), "unknown constraint type 'distanse'");
  EXPECT_HAS(error_of(variant("type: linear", "type: linaer")), "unknown law type 'linaer'");
}

TEST(Scene, MissingSectionsAndFields) {
  std::string s = kGood;
  s = s.substr(0, s.find("time:"));
  EXPECT_HAS(error_of(s), "missing field 'time'");
  EXPECT_HAS(error_of(variant(", length: L3}", "}")), "missing field 'length'");
}

// A planar body written as a map brings NAME_x, NAME_y, NAME_psi: a crank pinned to ground, driven by its angle.
TEST(Scene, PlanarBodiesWrittenAsMapsBringTheirCoordinates) {
  const std::string text = R"(phiq: 1
bodies:
  crank: {at: [0.01, 0], angle: 0.2}
  base: {at: [1, 2], angle: pi/2, fixed: true}
constraints:
  - {name: pin, type: revolute, between: [{body: base, at: [-2, 1]}, {body: crank}]}
drivers:
  - {name: motor, coordinate: crank_psi, law: {type: linear, initial: 0.25, rate: 1}}
time: {start: 0, end: 1, steps: 2}
)";
  const Scene s = parse_scene(text, "map.yaml");
  const Model& m = *s.model;
  EXPECT_EQ(m.coordinate_names(), (std::vector<std::string>{"crank_x", "crank_y", "crank_psi"}));
  EXPECT_EQ(m.initial_positions()[0], 0.01);
  EXPECT_EQ(m.initial_positions()[2], 0.2);
  EXPECT_EQ(*m.grubler(), 1);
  Workspace ws(m);
  SweepSummary sum;
  ASSERT_EQ(run_sweep(m, s.sweep, ws, nullptr, &sum), SolveStatus::kSuccess) << sum.message;
  // the base's local (−2, 1) turned by 90° from (1, 2): (1 − 1, 2 − 2) = the origin; ψ = 1.25 at t = 1
  EXPECT_NEAR(ws.q[0], 0.0, 1e-12);
  EXPECT_NEAR(ws.q[1], 0.0, 1e-12);
  EXPECT_NEAR(ws.q[2], 1.25, 1e-12);
  EXPECT_HAS(test::scene_error(test::replace_first(text, "angle: 0.2", "orientation: {angle: 1}")),
             "bodies.crank.orientation: unknown field 'orientation' (allowed: at, angle, fixed)");
  EXPECT_HAS(test::scene_error(test::replace_first(text, "{body: crank}", "{body: crank, axis: [0, 0, 1]}")),
             "between[1].axis: in dimension 2 a side has no axis: a revolute turns about z, and a prismatic's sliding "
             "axis is its own field");
  EXPECT_HAS(test::scene_error(test::replace_first(text, "{at: [0.01, 0], angle: 0.2}", "[0.01, 0]")),
             "bodies.crank: a body is [x, y, psi], or {at: [x, y], angle: psi}");
}

TEST(Scene, EquationErrorsNameTheExpression) {
  std::string base = variant("  - {name: rod, type: distance, points: [A, B], length: L3}",
                             "  - {name: rod, type: equation, expr: \"(xA - xB)^2 + yA^2 - L3^2\"}");
  EXPECT_NO_THROW(parse_scene(base, "ok.yaml"));
  std::string m = error_of(variant("  - {name: rod, type: distance, points: [A, B], length: L3}",
                                   "  - {name: rod, type: equation, expr: \"(xA - xB)^2 + foo^2 - L3^2\"}"));
  EXPECT_HAS(m, "constraints[1]");
  EXPECT_HAS(m, "unknown name 'foo'");
  EXPECT_HAS(error_of(variant("  - {name: rod, type: distance, points: [A, B], length: L3}",
                              "  - {name: rod, type: equation, expr: \"(xA - xB\"}")),
             "constraints[1].expr");
  EXPECT_HAS(error_of(variant("  - {name: rod, type: distance, points: [A, B], length: L3}",
                              "  - {name: rod, type: equation, expr: \"gamma(xA)\"}")),
             "constraints[1].expr");
}

TEST(Scene, NonSquareModelLoadsAndTheAssemblySaysWhatIsMissing) {
  // Under-driven (no motor): loads; the square solve refuses it with both counts, the assembly names the freedom.
  Scene sc = parse_scene(
      variant("drivers:\n  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}\n", ""),
      "undriven.yaml");
  EXPECT_EQ(sc.model->num_coordinates(), 4);
  EXPECT_EQ(sc.model->num_equations(), 3);
  Workspace ws(*sc.model);
  PositionSummary ps;
  EXPECT_EQ(solve_position(*sc.model, 0.0, sc.sweep.assembly, ws, &ps), SolveStatus::kNotSquare);
  EXPECT_NE(ps.message.find("3 equations for 4 coordinates"), std::string::npos) << ps.message;
  Eigen::VectorXd q = sc.model->initial_positions();
  std::unique_ptr<Model> solved;
  AssemblySummary as;
  EXPECT_EQ(prepare_square(*sc.model, 0.0, {}, q, &solved, &as), SolveStatus::kNotSquare);
  EXPECT_EQ(as.rank.dof, 1);
  EXPECT_EQ(as.rank.driven_dof, 1);
  EXPECT_NE(as.message.find("1 degree(s) of freedom not driven"), std::string::npos) << as.message;
}

TEST(Scene, ReservedAndInvalidNames) {
  EXPECT_HAS(error_of(variant("  xB: 1.3\n", "  xB: 1.3\n  t: 0\n")), "'t' is reserved");
  EXPECT_HAS(error_of(variant("  xB: 1.3\n", "  xB: 1.3\n  x.v: 0\n")), "not a valid coordinate name");
}

TEST(Scene, FileErrors) {
  try {
    load_scene("/nonexistent/scene.yaml");
    ADD_FAILURE();
  } catch (const SceneError& e) {
    EXPECT_HAS(std::string(e.what()), "/nonexistent/scene.yaml: cannot open");
  }
  EXPECT_HAS(error_of(""), "the scene is empty");
}

TEST(Scene, HostileShapesAreRefusedBeforeTheTreeIsBuilt) {
  std::string deep = "coordinates: {x: 0}\nname: " + std::string(200, '[') + std::string(200, ']') + "\n";
  EXPECT_HAS(error_of(deep), "nested more than 32 levels deep");
  EXPECT_HAS(error_of(std::string(kGood) + "description: &a hello\nname: *a\n"), "aliases (*name) are not supported");
  EXPECT_HAS(error_of(std::string(kGood) + "---\nname: two\n"), "a scene is one YAML document");
  EXPECT_HAS(error_of(std::string(kGood) + "description: \"" + std::string(20000, 'x') + "\"\n"),
             "a value of 20000 bytes; the limit is 16384");
  EXPECT_HAS(error_of(std::string("name: a\0b\n", 11)), ":1:8: the scene is not text (a NUL byte)");
  EXPECT_HAS(error_of(std::string("\xff\xfen\0a\0", 6)), "the scene is UTF-16 (little-endian, with a byte order mark)");
  SceneLimits tiny;
  tiny.max_file_bytes = 100;
  try {
    parse_scene(kGood, "big.yaml", tiny);
    ADD_FAILURE();
  } catch (const SceneError& e) {
    EXPECT_HAS(std::string(e.what()), "big.yaml: the scene is 0 MiB; the limit is 0 MiB");
  }
  SceneLimits few;
  few.max_nodes = 20;
  try {
    parse_scene(kGood, "many.yaml", few);
    ADD_FAILURE();
  } catch (const SceneError& e) {
    EXPECT_HAS(std::string(e.what()), "more than 20 values; the scene is too large (write repeated entries as");
  }
  // a model converted from a robot file cannot be rewritten with families: the advice is not given there
  try {
    parse_scene(kGood, "many.urdf", few);
    ADD_FAILURE();
  } catch (const SceneError& e) {
    EXPECT_HAS(std::string(e.what()), "more than 20 values; the scene is too large for phiq to read");
    EXPECT_EQ(std::string(e.what()).find("families"), std::string::npos) << e.what();
  }
}

TEST(Scene, HostileExpressionsAreRefused) {
  auto with = [](const std::string& expr) {
    return variant("  - {name: rod, type: distance, points: [A, B], length: L3}",
                   "  - {name: rod, type: equation, expr: \"" + expr + "\"}");
  };
  EXPECT_HAS(error_of(with("xA" + std::string(4200, '+') + "xB")), "the limit is 4096");
  EXPECT_HAS(error_of(with(std::string(100, '(') + "xA" + std::string(100, ')'))), "parentheses deep");
  // a product of 340 factors fits in 4096 characters, but its gradient needs ~n²/2 instructions
  std::string product = "(xA+xB+1)";
  for (int k = 2; k <= 340; ++k) product += "*(xA+xB+" + std::to_string(k) + ")";
  const std::string m = error_of(with(product));
  EXPECT_HAS(m, "instructions; the limit is 50000");
  // ... while a product of 60 is an ordinary (if long) constraint, compiled in milliseconds
  std::string shorter = "(xA+xB+1)";
  for (int k = 2; k <= 60; ++k) shorter += "*(xA+xB+" + std::to_string(k) + ")";
  EXPECT_NO_THROW(parse_scene(with(shorter), "ok.yaml"));
}

TEST(Scene, NumbersBeyondADoubleAreRefusedWithoutSymbolicWork) {
  // 1e3082222222 once made the symbolic engine build a 3·10^9-digit integer (a hang found by the fuzzer)
  EXPECT_HAS(error_of(variant("xA: 0.3", "xA: 0.3e3082222222")), "is out of the range of a double");
  EXPECT_HAS(error_of(variant("xA: 0.3", "xA: 1e400")), "coordinates.xA");
  EXPECT_HAS(error_of(variant("length: L3", "length: 2*1e99999999")), "is out of the range of a double");
  // underflow is zero, as a double would have it
  Scene s = parse_scene(variant("xA: 0.3", "xA: 1e-400"), "tiny.yaml");
  EXPECT_EQ(s.model->initial_positions()(1), 0.0);
}

TEST(Scene, ErrorsQuotingMultiLineTextStayOneLine) {
  // a double-quoted YAML value may span lines; the error quotes it (found by the fuzzer)
  std::string m = error_of(variant("  - {name: rod, type: distance, points: [A, B], length: L3}",
                                   "  - {name: rod, type: equation, expr: \"xA - \\n\\t bogus\"}"));
  EXPECT_HAS(m, "unknown name 'bogus'");
  EXPECT_HAS(m, "\\n");  // escaped, not a line break
}

// Inputs the fuzzer once found a defect with (tests/fuzz/regressions/): each must load or fail with one line.
TEST(Scene, FuzzerRegressionInputs) {
  int n = 0;
  for (const auto& f : std::filesystem::directory_iterator(std::string(PHIQ_SOURCE_DIR) + "/tests/fuzz/regressions")) {
    ++n;
    try {
      load_scene(f.path().string());
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.find('\n'), std::string::npos) << f.path() << ": " << m;
      EXPECT_EQ(m.rfind(f.path().string(), 0), 0u) << m;
    }
  }
  EXPECT_GE(n, 1);
}

TEST(Scene, ALineOrSegmentBetweenOneFixedPointIsRefused) {
  // point_on_line with both line points the same constant (no direction anywhere) loaded and then failed at the
  // first step as a "singular position, rcond 0"; so did a constant_angle segment of two equal fixed ends.
  EXPECT_HAS(test::scene_error(R"(coordinates: {x: 0.5, y: 0.1}
points: {P: [x, y], A: [1, 1], B: [1, 1]}
constraints:
  - {name: online, type: point_on_line, point: P, line: [A, B]}
time: {start: 0, end: 1, steps: 10}
)"),
             "bad.yaml:4:5: constraints[0]: constraint 'online': point_on_line: the line's two points are the same "
             "fixed point");
  EXPECT_HAS(test::scene_error(R"(coordinates: {x: 0.5, y: 0.1}
points: {P: [x, y], O: [0, 0]}
constraints:
  - {name: ang, type: constant_angle, segments: [[O, P], [O, O]], angle: 0.5}
time: {start: 0, end: 1, steps: 10}
)"),
             "constraint 'ang': constant_angle: a segment's two ends are the same fixed point");
}

TEST(Scene, EverySeedSceneLoads) {
  for (const char* f : {"crank_slider_mixed.yaml", "crank_slider_equations.yaml", "fourbar_relative.yaml",
                        "fourbar_reference_point.yaml", "fourbar_natural.yaml", "fourbar_mixed.yaml"}) {
    EXPECT_NO_THROW(load_scene(test::model_path(std::string("seed/") + f))) << f;
  }
}

}  // namespace
}  // namespace phiq

namespace phiq {
namespace {

TEST(SceneSolver, NewtonModeIsASetting) {
  const std::string base =
      "coordinates: {x: 0.1}\ndrivers: [{coordinate: x, law: {type: linear, initial: 0, rate: 1}}]\n"
      "time: {start: 0, end: 1, steps: 2}\n";
  EXPECT_EQ(parse_scene(base, "s.yaml").sweep.newton.jacobian_update, JacobianUpdate::kWhenSlow);
  EXPECT_EQ(parse_scene(base + "solver: {newton: full}\n", "s.yaml").sweep.newton.jacobian_update,
            JacobianUpdate::kEveryIteration);
  EXPECT_EQ(parse_scene(base + "solver: {newton: modified}\n", "s.yaml").sweep.newton.jacobian_update,
            JacobianUpdate::kWhenSlow);
  try {
    parse_scene(base + "solver: {newton: quasi}\n", "s.yaml");
    ADD_FAILURE() << "accepted newton: quasi";
  } catch (const SceneError& e) {
    EXPECT_STREQ(e.what(), "s.yaml:4:18: solver.newton: newton is modified or full");
  }
}

TEST(SceneSolver, PredictorIsASettingThatNeedsItsDerivativesInTheOutput) {
  const std::string base =
      "coordinates: {x: 0.1}\ndrivers: [{coordinate: x, law: {type: linear, initial: 0, rate: 1}}]\n"
      "time: {start: 0, end: 1, steps: 2}\n";
  EXPECT_EQ(parse_scene(base, "s.yaml").sweep.predictor, Predictor::kAuto);
  EXPECT_EQ(
      parse_scene(base + "solver: {predictor: cubic}\noutput: {velocities: true, accelerations: true}\n", "s.yaml")
          .sweep.predictor,
      Predictor::kCubic);
  EXPECT_EQ(parse_scene(base + "solver: {predictor: parabolic}\noutput: {velocities: false, accelerations: false}\n",
                        "s.yaml")
                .sweep.predictor,
            Predictor::kParabolic);
  for (const auto& [text, message] :
       {std::pair<std::string, std::string>{"solver: {predictor: quartic}\n",
                                            "s.yaml:4:21: solver.predictor: predictor is auto, previous, secant, "
                                            "parabolic, linear, hermite, quadratic or cubic"},
        {"solver: {predictor: cubic}\noutput: {accelerations: false}\n",
         "s.yaml: solver.predictor: 'cubic' needs the derivatives it extrapolates with in the output (velocities / "
         "accelerations)"}}) {
    try {
      parse_scene(base + text, "s.yaml");
      ADD_FAILURE() << "accepted " << text;
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  }
}

}  // namespace
}  // namespace phiq
