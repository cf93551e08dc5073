// Scene loading: valid scenes build the right model; bad scenes give one-line errors naming file, line, field.
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
std::string error_of(const std::string& text) { return test::scene_error(text); }

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
  EXPECT_EQ(s.output_coordinates.size(), 4u);
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
  EXPECT_HAS(error_of(std::string("name: a\0b\n", 11)), "contains a NUL byte");
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
    EXPECT_HAS(std::string(e.what()), "more than 20 values; the scene is too large");
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

// ---- indexed families (`for i in A..B`) -------------------------------------------------------------------------

// The N = 3 four-bar of `phiq generate nfourbar 3` with families (line numbers matter: messages name them) ...
const char* kFamilies = R"(phiq: 1
parameters: {N: 3, c: 0.5, s: 0.8660254037844386}
coordinates:
  for i in 0..N:
    x{i}: i + c
    y{i}: s
  theta: 1.0471975511965976
points:
  O: [0, 0]
  for i in 0..N:
    P{i}: ["x{i}", "y{i}"]
constraints:
  - for i in 0..N:
      - {name: "crank{i}", type: distance, points: [[i, 0], "P{i}"], length: 1}
  - for i in 0..N-1:
      - {name: "coupler{i}", type: distance, points: ["P{i}", "P{i+1}"], length: 1}
  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}
drivers:
  - {name: motor, coordinate: theta, law: {type: linear, initial: 1.0471975511965976, rate: 1}}
time: {start: 0, end: 1, steps: 10}
)";

// ... and listed one by one.
const char* kListed = R"(phiq: 1
coordinates:
  x0: 0.5
  y0: 0.8660254037844386
  x1: 1.5
  y1: 0.8660254037844386
  x2: 2.5
  y2: 0.8660254037844386
  x3: 3.5
  y3: 0.8660254037844386
  theta: 1.0471975511965976
points:
  O: [0, 0]
  P0: [x0, y0]
  P1: [x1, y1]
  P2: [x2, y2]
  P3: [x3, y3]
constraints:
  - {name: crank0, type: distance, points: [[0, 0], P0], length: 1}
  - {name: crank1, type: distance, points: [[1, 0], P1], length: 1}
  - {name: crank2, type: distance, points: [[2, 0], P2], length: 1}
  - {name: crank3, type: distance, points: [[3, 0], P3], length: 1}
  - {name: coupler0, type: distance, points: [P0, P1], length: 1}
  - {name: coupler1, type: distance, points: [P1, P2], length: 1}
  - {name: coupler2, type: distance, points: [P2, P3], length: 1}
  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}
drivers:
  - {name: motor, coordinate: theta, law: {type: linear, initial: 1.0471975511965976, rate: 1}}
time: {start: 0, end: 1, steps: 10}
)";

std::string family_variant(const std::string& from, const std::string& to) {
  std::string s = kFamilies;
  auto p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return s.replace(p, from.size(), to);
}

TEST(SceneFamilies, ExpandToTheModelListedOneByOne) {
  Scene a = parse_scene(kFamilies, "families.yaml"), b = parse_scene(kListed, "listed.yaml");
  test::expect_same_model(*a.model, *b.model);
  EXPECT_EQ(a.model->coordinate_names().front(), "x0");
  EXPECT_EQ(a.model->coordinate_names()[1], "y0");
  EXPECT_EQ(a.model->coordinate_names().back(), "theta");
  EXPECT_EQ(a.model->constraints()[4].name, "coupler0");
  test::Trace ta, tb;
  ASSERT_EQ(test::sweep(*a.model, a.sweep, &ta), SolveStatus::kSuccess);
  ASSERT_EQ(test::sweep(*b.model, b.sweep, &tb), SolveStatus::kSuccess);
  for (std::size_t k = 0; k < ta.q.size(); ++k) EXPECT_EQ(ta.q[k], tb.q[k]);
}

TEST(SceneFamilies, NestedFamiliesExpandOuterIndexSlowest) {
  // three levels, a range that uses an enclosing index, equations with templates and indices as constants
  const char* grid = R"Y(phiq: 1
parameters: {M: 2}
coordinates:
  for i in 0..M:
    for j in 0..M:
      for k in 0..i:
        q{i}_{j}_{k}: 100*i + 10*j + k + 0.5
constraints:
  - for i in 0..M:
      - for j in 0..M:
          - for k in 0..i:
              - {name: "fix{i}_{j}_{k}", type: equation, expr: "q{i}_{j}_{k} - (100*i + 10*j + k)", unit: length}
time: {start: 0, end: 1, steps: 1}
)Y";
  Scene s = parse_scene(grid, "grid.yaml");
  const Model& m = *s.model;
  ASSERT_EQ(m.num_coordinates(), 18);  // 3 x (1 + 2 + 3)
  std::vector<std::string> names;
  for (int i = 0; i <= 2; ++i)
    for (int j = 0; j <= 2; ++j)
      for (int k = 0; k <= i; ++k) {
        std::string n = "q";  // appended, not "q" + ...: GCC 12 warns falsely on that (-Wrestrict, PR 105329)
        n += std::to_string(i), n += "_", n += std::to_string(j), n += "_", n += std::to_string(k);
        names.push_back(n);
      }
  EXPECT_EQ(m.coordinate_names(), names);
  for (Index r = 0; r < m.num_coordinates(); ++r) {
    const std::string& n = names[static_cast<std::size_t>(r)];
    EXPECT_EQ(m.initial_positions()(r), std::stod(n.substr(1, 1)) * 100 + std::stod(n.substr(3, 1)) * 10 +
                                            std::stod(n.substr(5, 1)) + 0.5);
    EXPECT_EQ(m.constraints()[static_cast<std::size_t>(r)].name, "fix" + n.substr(1));
  }
  // each row reads its own coordinate, with value 0.5 at the initial point and derivative 1
  std::vector<double> phi(18), jac(static_cast<std::size_t>(m.jacobian_pattern().nnz()));
  m.residual(m.initial_positions().data(), 0.0, phi.data());
  m.jacobian(m.initial_positions().data(), 0.0, jac.data());
  for (double v : phi) EXPECT_EQ(v, 0.5);
  ASSERT_EQ(jac.size(), 18u);
  for (double v : jac) EXPECT_EQ(v, 1.0);
  for (Index j = 0; j < 18; ++j) EXPECT_EQ(m.jacobian_pattern().row_idx[static_cast<std::size_t>(j)], j);
}

TEST(SceneFamilies, EquationsDriversLawsAndTemplatedParameters) {
  // the chain q_i = L_i (templated parameter names), written as equations, driven per member with an index in
  // the law; equations with two templated coordinates; a templated name of the same coordinate twice
  const char* text = R"Y(phiq: 1
parameters: {L0: 1, L1: 2, L2: 4}
coordinates:
  for i in 0..2:
    q{i}: L{i} + 0.25
    u{i}: 0.1*i
constraints:
  - for i in 1..2:
      - {name: "gap{i}", type: equation, expr: "q{i} - q{i-1} - (L{i} - L{i-1})", unit: length}
  - {name: first, type: equation, expr: "q0 - L0", unit: length}
drivers:
  - for i in 0..2:
      - {name: "drive{i}", expr: "u{i} + 0*u{i+0}", law: {type: expression, f: "i*t + 0.1*i"}}
time: {start: 0, end: 1, steps: 4}
)Y";
  Scene s = parse_scene(text, "eq.yaml");
  const Model& m = *s.model;
  EXPECT_EQ(m.coordinate_names(), (std::vector<std::string>{"q0", "u0", "q1", "u1", "q2", "u2"}));
  EXPECT_EQ(m.initial_positions()(4), 4.25);
  EXPECT_EQ(m.initial_positions()(3), 0.1);
  test::Trace tr;
  ASSERT_EQ(test::sweep(m, s.sweep, &tr), SolveStatus::kSuccess);
  const Eigen::VectorXd& q = tr.q.back();  // t = 1
  EXPECT_NEAR(q(0), 1.0, 1e-12);
  EXPECT_NEAR(q(2), 2.0, 1e-12);
  EXPECT_NEAR(q(4), 4.0, 1e-12);
  EXPECT_NEAR(q(5), 2 * 1.0 + 0.2, 1e-12);  // u2 = 2 t + 0.2
  EXPECT_EQ(m.constraints()[3].name, "drive0");
}

TEST(SceneFamilies, EmptyFamiliesAndBoundsFromEnclosingIndices) {
  // B < A: no member; a range given by expressions
  std::string s = family_variant("  - for i in 0..N-1:\n", "  - for k in 1..0:\n      - {type: bogus}\n  - for i in N-3..(N*2-2)/2:\n");
  Scene sc = parse_scene(s, "ok.yaml");
  EXPECT_EQ(sc.model->constraints().size(), 9u);
}

TEST(SceneFamilies, TemplatesAreNotNamesOutsideFamilies) {
  EXPECT_EQ(error_of(family_variant("  theta: 1.0471975511965976", "  theta{N}: 1.0471975511965976")),
            "bad.yaml:7:13: coordinates.theta{N}: 'theta{N}' is not a valid coordinate name");
}

TEST(SceneFamilies, ErrorsNameTheMember) {
  EXPECT_EQ(error_of(family_variant("\"P{i+1}\"], length", "\"P{i+2}\"], length")),
            "bad.yaml:16:63: constraints[1].for i in 0..N-1[i=2].points[1]: unknown point 'P4'");
  EXPECT_EQ(error_of(family_variant("P{i}: [\"x{i}\"", "P{i/2}: [\"x{i}\"")),
            "bad.yaml:11:13: points.for i in 0..N[i=1].P{i/2}: template 'P{i/2}': {i/2} is 0.5, not a whole number");
  EXPECT_EQ(error_of(family_variant("for i in 0..N-1:", "for i in 0..N/2:")),
            "bad.yaml:15:5: constraints[1].for i in 0..N/2: range bound 'N/2' is 1.5, not a whole number");
  EXPECT_EQ(error_of(family_variant("P{i}: [\"x{i}\"", "P{k}: [\"x{i}\"")),
            "bad.yaml:11:11: points.for i in 0..N[i=0].P{k}: template 'P{k}': unknown name 'k'");
  EXPECT_EQ(error_of(family_variant("\"crank{i}\", type", "\"crank{i-j}\", type")),
            "bad.yaml:14:16: constraints[0].for i in 0..N[i=0].name: template 'crank{i-j}': unknown name 'j'");
  EXPECT_EQ(error_of(family_variant("for i in 0..N-1:", "for i in 0..M:")),
            "bad.yaml:15:5: constraints[1].for i in 0..M: range bound 'M': unknown name 'M'");
  EXPECT_EQ(error_of(family_variant("length: 1}\n  - for i in 0..N-1", "length: i}\n  - for i in 0..N-1")),
            "bad.yaml:14:78: constraints[0].for i in 0..N[i=0].length: must be positive, got i = 0");
  EXPECT_EQ(error_of(family_variant("x{i}: i + c", "x{i}: i + d")),
            "bad.yaml:5:11: coordinates.for i in 0..N[i=0].x{i}: expression \"i + d\": unknown name 'd'");
  // a member error points at the member's item; with several items in the body, the item is named too
  EXPECT_EQ(error_of(family_variant("length: 1}\n  - for i in 0..N-1:\n",
                                    "length: 1}\n      - {name: \"extra{i}\", type: distance, points: [O, Q], length: 1}\n"
                                    "  - for i in 0..N-1:\n")),
            "bad.yaml:15:56: constraints[0].for i in 0..N[i=0][1].points[1]: unknown point 'Q'");
}

TEST(SceneFamilies, NamesThatCollideAfterExpansion) {
  EXPECT_EQ(error_of(family_variant("y{i}: s", "x{i+1}: s")),
            "bad.yaml:5:11: coordinates.for i in 0..N[i=1].x{i}: duplicate name 'x1'");
  EXPECT_EQ(error_of(family_variant("  theta: 1.0471975511965976", "  x3: 1.0471975511965976")),
            "bad.yaml:7:7: coordinates.x3: duplicate name 'x3'");
  EXPECT_EQ(error_of(family_variant("  O: [0, 0]", "  P2: [0, 0]")),
            "bad.yaml:11:11: points.for i in 0..N[i=2].P{i}: duplicate point or body name 'P2'");
  EXPECT_EQ(error_of(family_variant("\"coupler{i}\"", "\"crank{i}\"")),
            "bad.yaml:16:16: constraints[1].for i in 0..N-1[i=0].name: duplicate constraint or driver name 'crank0'");
  EXPECT_EQ(error_of(family_variant("{name: crank0_angle,", "{name: coupler2,")),
            "bad.yaml:17:12: constraints[2].name: duplicate constraint or driver name 'coupler2'");
}

TEST(SceneFamilies, IndexNamesMustNotShadow) {
  EXPECT_EQ(error_of(family_variant("for i in 0..N-1:", "for N in 0..2:")),
            "bad.yaml:15:5: constraints[1].for N in 0..2: index 'N' shadows the parameter 'N'");
  EXPECT_EQ(error_of(family_variant("for i in 0..N-1:", "for t in 0..2:")),
            "bad.yaml:15:5: constraints[1].for t in 0..2: index 't' is reserved");
  EXPECT_EQ(error_of(family_variant("for i in 0..N-1:", "for pi in 0..2:")),
            "bad.yaml:15:5: constraints[1].for pi in 0..2: index 'pi' is reserved");
  EXPECT_EQ(error_of(family_variant("for i in 0..N-1:", "for theta in 0..2:")),
            "bad.yaml:15:5: constraints[1].for theta in 0..2: index 'theta' shadows the coordinate 'theta'");
  EXPECT_EQ(error_of(family_variant("  - for i in 0..N-1:\n      - {name: \"coupler{i}\"",
                                    "  - for i in 0..N-1:\n      - for i in 0..1:\n        - {name: \"coupler{i}\"")),
            "bad.yaml:16:9: constraints[1].for i in 0..N-1.for i in 0..1: index 'i' shadows the index of an "
            "enclosing family");
}

TEST(SceneFamilies, MalformedFamiliesAndLimits) {
  EXPECT_EQ(error_of(family_variant("for i in 0..N-1:", "for i 0..N-1:")),
            "bad.yaml:15:5: constraints[1].for i 0..N-1: a family is 'for NAME in A..B' (A and B whole numbers, B "
            "included)");
  EXPECT_EQ(error_of(family_variant("for i in 0..N-1:", "for i in 0..100000000:")),
            "bad.yaml:15:5: constraints[1].for i in 0..100000000: the families would make 100000017 entries in all "
            "(coordinates 8, points 4, constraints 100000005), more than the 50000000 they may make "
            "(SceneLimits::max_family_instances)");
  EXPECT_EQ(error_of(family_variant("  for i in 0..N:\n    P{i}", "  for i in 0..N:\n    - P{i}")),
            "bad.yaml:10:3: points.for i in 0..N: the body of a family in a map is a map of entries: {for i in 0..N: "
            "{NAME: VALUE, ...}}");
  EXPECT_EQ(error_of(family_variant("  - for i in 0..N-1:\n", "  - for i in 0..N-1:\n    name: x\n    body:\n")),
            "bad.yaml:15:5: constraints[1]: a family item is a map with the one key 'for NAME in A..B' and nothing "
            "beside it");
  // the families of all sections together, counted before any is expanded
  SceneLimits few;
  few.max_family_instances = 12;
  // coordinates 4 x 2, points 4 x 1: the cranks take the count beyond 12
  EXPECT_EQ(test::scene_error(kFamilies, "few.yaml", few),
            "few.yaml:13:5: constraints[0].for i in 0..N: the families would make 19 entries in all (coordinates 8, "
            "points 4, constraints 7), more than the 12 they may make (SceneLimits::max_family_instances)");
  // the budget counts every entry made, nested families included: those whose range uses an enclosing index are
  // checked as they are expanded (here 2 x 1 counted beforehand, then 10 x 1 for i = 0 and 11 x 1 for i = 1)
  const std::string nested = "phiq: 1\nparameters: {N: 9}\ncoordinates:\n  for i in 0..1:\n    for j in 0..N+i:\n"
                             "      x{i}_{j}: 0\ntime: {start: 0, end: 1, steps: 1}\n";
  EXPECT_EQ(test::scene_error(nested, "few.yaml", few),
            "few.yaml:5:5: coordinates.for i in 0..1[i=1].for j in 0..N+i: the family would make 11 x 1 entries; "
            "families may make 12 entries in all and 0 are left (SceneLimits::max_family_instances)");
  // nesting deeper than the limit
  std::string deep = "coordinates:\n";
  std::string indent = "  ";
  for (int d = 0; d < 9; ++d) deep += indent + "for i" + std::to_string(d) + " in 0..0:\n", indent += "  ";
  deep += indent + "x: 0\ntime: {start: 0, end: 1, steps: 1}\n";
  EXPECT_EQ(error_of(deep), "bad.yaml:10:19: coordinates.for i0 in 0..0.for i1 in 0..0.for i2 in 0..0.for i3 in "
                            "0..0.for i4 in 0..0.for i5 in 0..0.for i6 in 0..0.for i7 in 0..0.for i8 in 0..0: "
                            "families nested more than 8 deep");
}

// A scene whose families fit one by one but not together is refused before any is expanded: the limit was consumed
// section by section, so that nfourbar with N = 10^7 was refused at its couplers after its coordinates, points and
// cranks were made (4.7 GB). Here the coordinates' body fails at the first member (an unknown name), which
// expanding them would report first.
TEST(SceneFamilies, FamiliesOverTheLimitTogetherAreRefusedBeforeAnyIsExpanded) {
  auto scene = [](std::int64_t n, const std::string& value) {
    return "phiq: 1\nparameters: {N: " + std::to_string(n) + "}\ncoordinates:\n  for k in 0..N-1:\n    q{k}: " +
           value + "\nconstraints:\n  - for k in 0..N-1:\n"
           "      - {name: \"fix{k}\", type: equation, expr: \"q{k} - 0.5*k\", unit: length}\n"
           "time: {start: 0, end: 1, steps: 1}\n";
  };
  auto error = [](const std::string& text, const SceneLimits& limits) -> std::string {
    try {
      parse_scene(text, "many.yaml", limits);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "(no error)";
  };
  SceneLimits limits;
  limits.max_family_instances = 1000;
  ASSERT_EQ(error(scene(600, "0.5*k + missing"), limits),
            "many.yaml:7:5: constraints[0].for k in 0..N-1: the families would make 1200 entries in all "
            "(coordinates 600, constraints 600), more than the 1000 they may make "
            "(SceneLimits::max_family_instances)");
  // within the limit, the coordinates are expanded (and say what is wrong with them); a scene within it loads
  EXPECT_EQ(error(scene(500, "0.5*k + missing"), limits),
            "many.yaml:5:11: coordinates.for k in 0..N-1[k=0].q{k}: expression \"0.5*k + missing\": unknown name "
            "'missing'");
  const Scene ok = parse_scene(scene(500, "0.5*k"), "many.yaml", limits);
  EXPECT_EQ(ok.model->num_coordinates(), 500);
  EXPECT_EQ(ok.model->constraints().size(), 500u);
  EXPECT_EQ(ok.model->constraints().back().name, "fix499");
  // a parameter given for the run counts as the file's would
  SceneOverrides bigger;
  bigger.parameters = {{"N", 501.0}};
  try {
    parse_scene(scene(500, "0.5*k"), "many.yaml", limits, bigger);
    ADD_FAILURE();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("the families would make 1002 entries in all"), std::string::npos)
        << e.what();
  }
  // nested families count one entry per member beforehand: they make at least that many
  const std::string nested = "phiq: 1\nparameters: {N: 1000}\ncoordinates:\n  for i in 0..N:\n"
                             "    for j in 0..1:\n      x{i}_{j}: 0\ntime: {start: 0, end: 1, steps: 1}\n";
  EXPECT_EQ(error(nested, limits),
            "many.yaml:4:3: coordinates.for i in 0..N: the families would make at least 1001 entries in all "
            "(coordinates 1001), more than the 1000 they may make (SceneLimits::max_family_instances)");
  // at the default limit: 3·10^7 coordinates fit, with their 3·10^7 equations not; expanding the coordinates
  // first would have made them (gigabytes) before the equations were refused
  EXPECT_EQ(error(scene(30000000, "0.5*k"), SceneLimits{}),
            "many.yaml:7:5: constraints[0].for k in 0..N-1: the families would make 60000000 entries in all "
            "(coordinates 30000000, constraints 30000000), more than the 50000000 they may make "
            "(SceneLimits::max_family_instances)");
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
)"), "bad.yaml:4:5: constraints[0]: constraint 'online': point_on_line: the line's two points are the same "
       "fixed point");
  EXPECT_HAS(test::scene_error(R"(coordinates: {x: 0.5, y: 0.1}
points: {P: [x, y], O: [0, 0]}
constraints:
  - {name: ang, type: constant_angle, segments: [[O, P], [O, O]], angle: 0.5}
time: {start: 0, end: 1, steps: 10}
)"), "constraint 'ang': constant_angle: a segment's two ends are the same fixed point");
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
  EXPECT_EQ(parse_scene(base + "solver: {predictor: cubic}\noutput: {velocities: true, accelerations: true}\n",
                        "s.yaml").sweep.predictor,
            Predictor::kCubic);
  EXPECT_EQ(parse_scene(base + "solver: {predictor: parabolic}\noutput: {velocities: false, accelerations: false}\n",
                        "s.yaml").sweep.predictor,
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
