// What a design parameter reaches (engine/src/solve/parameter_reach.cpp, ParameterReach in sensitivity.hpp): the
// constraints whose data its models change, exactly; the product Φq v of ConstraintBlock::add_jacobian_product()
// against the model's CSC Jacobian on every scene of models/; and sensitivities evaluated over the reach against
// those evaluated over every constraint, in both forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

namespace fs = std::filesystem;

const char* kReachCrankSlider = R"(phiq: 1
parameters: {L2: 0.3, L3: 1.0, unused: 5}
coordinates: {theta2: 0.0, xA: 0.28, yA: 0.03, xB: 1.25}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}
time: {start: 0, end: pi, steps: 90}
output: {velocities: true, accelerations: true}
)";

// 41 cranks and 40 couplers: crank7's length is R7, every coupler's L.
const char* kBars = R"(phiq: 1
parameters: {N: 40, R7: 1, L: 1}
coordinates:
  for i in 0..N:
    x{i}: i + 0.7071067811865476
    y{i}: 0.7071067811865475
  theta: 0.7853981633974483
points:
  O: [0, 0]
  for i in 0..N:
    P{i}: ["x{i}", "y{i}"]
constraints:
  - for i in 0..6:
      - {name: "crank{i}", type: distance, points: [[i, 0], "P{i}"], length: 1}
  - {name: crank7, type: distance, points: [[7, 0], P7], length: R7}
  - for i in 8..N:
      - {name: "crank{i}", type: distance, points: [[i, 0], "P{i}"], length: 1}
  - for i in 0..N-1:
      - {name: "coupler{i}", type: distance, points: ["P{i}", "P{i+1}"], length: L}
  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}
drivers:
  - {name: motor, coordinate: theta, law: {type: linear, initial: 0.7853981633974483, rate: 1.5707963267948966}}
time: {start: 0, end: 1, steps: 10}
)";

// The names of the constraints owning the reach's rows, in row order, each once.
std::vector<std::string> reached(const Model& m, const ParameterReach& r) {
  std::vector<std::string> names;
  for (const Index row : r.rows) {
    const std::string& name = m.constraints()[static_cast<std::size_t>(m.constraint_of_row(row))].name;
    if (names.empty() || names.back() != name) names.push_back(name);
  }
  return names;
}

// A length reaches its one constraint, and nothing else: the driver's law is the same law in every model.
TEST(ParameterReach, ALengthReachesItsConstraintOnly) {
  const Scene s = parse_scene(kReachCrankSlider, "c.yaml");
  const OutputSensitivity l2 = sensitivity_along(s, "L2", 0.3), l3 = sensitivity_along(s, "L3", 1.0);
  ASSERT_TRUE(l2.reach && l3.reach);  // sensitivity_along() finds it
  EXPECT_EQ(reached(*s.model, *l2.reach), (std::vector<std::string>{"crank"}));
  EXPECT_EQ(reached(*s.model, *l3.reach), (std::vector<std::string>{"rod"}));
  const Index crank = s.model->constraint("crank").first_row, rod = s.model->constraint("rod").first_row;
  EXPECT_EQ(l2.reach->rows, (std::vector<Index>{crank, crank + 1}));
  EXPECT_EQ(l3.reach->rows, (std::vector<Index>{rod}));
  EXPECT_FALSE(l2.reach->everything);
  // the same as parameter_reach() finds afresh: one span of one constraint
  const ParameterReach again = parameter_reach(*s.model, l2);
  EXPECT_EQ(again.rows, l2.reach->rows);
  ASSERT_EQ(again.spans.size(), 1u);
  EXPECT_EQ(again.spans[0].end - again.spans[0].begin, 1u);
  // a parameter nothing reads reaches nothing
  const OutputSensitivity unused = sensitivity_along(s, "unused", 5.0);
  EXPECT_TRUE(unused.reach->spans.empty());
  EXPECT_TRUE(unused.reach->rows.empty());
}

// A parameter of the driver's law reaches the driver alone, and its sensitivities are the law's: θ2 = w t, so
// ∂θ2/∂w = t, ∂θ̇2/∂w = 1, ∂θ̈2/∂w = 0, with the crank-slider following (x_B moves as ∂x_B/∂θ2 · t). Not reported
// as a parameter nothing reads.
TEST(ParameterReach, ALawsCoefficientReachesItsDriver) {
  const std::string text = test::replace_first(test::replace_first(kReachCrankSlider, "unused: 5}", "unused: 5, w: 2}"),
                                               "rate: 2}", "rate: w}");
  const Scene s = parse_scene(text, "c.yaml");
  OutputSensitivity w = sensitivity_along(s, "w", 2.0);
  EXPECT_EQ(reached(*s.model, *w.reach), (std::vector<std::string>{"motor"}));
  SweepOptions o = s.sweep;
  o.sensitivities = {w};
  const Index n = s.model->num_coordinates(), theta = s.model->coordinate_index("theta2");
  const Index xb = s.model->coordinate_index("xB");
  const SensitivityLayout layout{n};
  int rows = 0;
  SweepSummary sum;
  Workspace ws(*s.model);
  ASSERT_EQ(run_sweep(
                *s.model, o, ws,
                [&](const StepView& v) {
                  const double t = v.t, th = v.q[theta];
                  EXPECT_NEAR(v.sensitivities[layout.offset(0, 0) + theta], t, 1e-12) << t;
                  EXPECT_NEAR(v.sensitivities[layout.offset(0, 1) + theta], 1.0, 1e-12) << t;
                  EXPECT_NEAR(v.sensitivities[layout.offset(0, 2) + theta], 0.0, 1e-11) << t;
                  // x_B = L2 cos θ + √(L3² − L2² sin² θ): ∂x_B/∂w = ∂x_B/∂θ · t
                  const double r = std::sqrt(1.0 - 0.09 * std::sin(th) * std::sin(th));
                  const double dx = -0.3 * std::sin(th) - 0.09 * std::sin(th) * std::cos(th) / r;
                  EXPECT_NEAR(v.sensitivities[layout.offset(0, 0) + xb], dx * t, 1e-10) << t;
                  ++rows;
                  return true;
                },
                &sum),
            SolveStatus::kSuccess);
  EXPECT_EQ(rows, 91);
  for (const SweepWarning& warning : sum.warnings) EXPECT_NE(warning.kind, "no_dependence") << warning.message;
}

// Laws, curves and expressions are compared by what they hold, not by address: each build of a scene makes its own.
TEST(ParameterReach, LawsCurvesAndExpressionsCompareByValue) {
  EXPECT_EQ(MotionLaw::linear(0, 2), MotionLaw::linear(0, 2));
  EXPECT_NE(MotionLaw::linear(0, 2), MotionLaw::linear(0, 2.000000001));
  EXPECT_NE(MotionLaw::linear(0, 2), MotionLaw::polynomial({0, 2, 0}));  // another polynomial's coefficients
  EXPECT_EQ(MotionLaw::harmonic(0, 1, 2, 0.5), MotionLaw::harmonic(0, 1, 2, 0.5));
  EXPECT_NE(MotionLaw::harmonic(0, 1, 2, 0.5), MotionLaw::harmonic(0, 1, 2, 0.25));
  EXPECT_EQ(MotionLaw::table({0, 1, 2, 3}, {0, 1, 4, 9}), MotionLaw::table({0, 1, 2, 3}, {0, 1, 4, 9}));
  EXPECT_NE(MotionLaw::table({0, 1, 2, 3}, {0, 1, 4, 9}), MotionLaw::table({0, 1, 2, 3}, {0, 1, 4, 9.5}));
  EXPECT_NE(MotionLaw::linear(0, 2), MotionLaw{});
  EXPECT_EQ(MotionLaw{}, MotionLaw{});
  const NameResolver names = [](const std::string& name) -> std::optional<NameBinding> {
    if (name == "x") return NameBinding{NameBinding::Kind::kCoordinate, 0};
    if (name == "t") return NameBinding{NameBinding::Kind::kTime};
    return std::nullopt;
  };
  const auto g1 = CompiledExpression::compile("x^2 + 0.5*t", names);
  const auto g2 = CompiledExpression::compile("x^2 + 0.5*t", names);
  const auto g3 = CompiledExpression::compile("x^2 + 0.25*t", names);
  EXPECT_EQ(*g1, *g2);
  EXPECT_FALSE(*g1 == *g3);
  const auto f1 = CompiledExpression::compile("0.5*t^2", names), f2 = CompiledExpression::compile("0.5*t^2", names);
  EXPECT_EQ(MotionLaw::expression(f1), MotionLaw::expression(f2));
  EXPECT_NE(MotionLaw::expression(f1), MotionLaw::expression(CompiledExpression::compile("0.25*t^2", names)));
  EquationSpec e1{g1, std::nullopt, Unit::kNone}, e2{g2, std::nullopt, Unit::kNone};
  const EquationSpec e3{g3, std::nullopt, Unit::kNone};
  EXPECT_TRUE(e1 == e2);
  EXPECT_FALSE(e1 == e3);
  e2.law = MotionLaw::linear(0, 1);
  EXPECT_FALSE(e1 == e2);
  const CurveOn c1{Frame2{}, Curve::circle({0, 0}, 0.5)}, c2{Frame2{}, Curve::circle({0, 0}, 0.5)};
  const CurveOn c3{Frame2{}, Curve::circle({0, 0}, 0.5000001)};
  EXPECT_TRUE(c1 == c2);
  EXPECT_FALSE(c1 == c3);
  const auto spline = [](double last) { return Curve::spline({{0, 0}, {1, 0}, {2, 1}, {3, last}}, false); };
  EXPECT_TRUE(*spline(3) == *spline(3));
  EXPECT_FALSE(*spline(3) == *spline(3.5));
}

// A family of 41 bars of which one reads the parameter: one span of one constraint in the distance block.
TEST(ParameterReach, OneBarOfAFamilyIsOneSpan) {
  const Scene s = parse_scene(kBars, "bars.yaml");
  const OutputSensitivity r7 = sensitivity_along(s, "R7", 1.0);
  EXPECT_EQ(reached(*s.model, *r7.reach), (std::vector<std::string>{"crank7"}));
  std::size_t in_distances = 0;
  for (const auto& span : r7.reach->spans)
    if (std::string(s.model->blocks()[span.block]->kind()) == "distance") {
      ++in_distances;
      EXPECT_EQ(span.begin, 7u);
      EXPECT_EQ(span.end, 8u);
    }
  EXPECT_EQ(in_distances, 1u);
  // L, every coupler's length: one span over the 40 couplers, after the 41 cranks in the distance block
  const OutputSensitivity l = sensitivity_along(s, "L", 1.0);
  EXPECT_EQ(l.reach->rows.size(), 40u);  // the 40 couplers
  bool couplers = false;
  for (const auto& span : l.reach->spans)
    if (std::string(s.model->blocks()[span.block]->kind()) == "distance") couplers = span.begin == 41 && span.end == 81;
  EXPECT_TRUE(couplers);
}

// Models whose blocks cannot be matched to the swept model's (here another scene's) reach everything.
TEST(ParameterReach, ModelsWhoseBlocksDoNotMatchReachEverything) {
  const Scene s = parse_scene(kReachCrankSlider, "c.yaml");
  const Scene other = load_scene(test::model_path("seed/fourbar_natural.yaml"));
  SceneOverrides keep;
  keep.keep_sensitivity_models = true;
  OutputSensitivity p = sensitivity_along(s, "L2", 0.3, 0.0, {}, keep);
  p.models[2] = std::shared_ptr<const Model>(other.model.get(), [](const Model*) {});
  const ParameterReach r = parameter_reach(*s.model, p);
  EXPECT_TRUE(r.everything);
  ASSERT_EQ(r.rows.size(), static_cast<std::size_t>(s.model->num_equations()));
  for (std::size_t i = 0; i < r.rows.size(); ++i) EXPECT_EQ(r.rows[i], static_cast<Index>(i));
  std::size_t constraints = 0;
  for (const auto& span : r.spans) constraints += span.end - span.begin;
  EXPECT_EQ(constraints, s.model->constraints().size());
}

// Φq v constraint by constraint (add_jacobian_product over every block) is the CSC Jacobian's product, to rounding,
// at a random point near the placement, for every scene of models/ (every kind the scenes use).
TEST(ParameterReach, AddJacobianProductIsTheJacobiansProductOnEveryScene) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int scenes = 0;
  for (const auto& e : fs::recursive_directory_iterator(PHIQ_MODELS_DIR)) {
    if (e.path().extension() != ".yaml" || e.path().parent_path().filename() == "reference") continue;
    if (fs::file_size(e.path()) > 20000) continue;  // the generated large ones add no kind
    const Scene s = load_scene(e.path().string());
    const Model& m = *s.model;
    const Index n = m.num_coordinates(), rows = m.num_equations();
    Eigen::VectorXd q = m.initial_positions(), v(n);
    for (Index j = 0; j < n; ++j) q[j] += 0.01 * u(rng), v[j] = u(rng);
    const double t = s.sweep.t_begin;
    std::vector<double> values(static_cast<std::size_t>(m.jacobian_pattern().nnz()));
    m.jacobian(q.data(), t, values.data());
    const CscPattern& p = m.jacobian_pattern();
    Eigen::VectorXd expected = Eigen::VectorXd::Zero(rows), got = Eigen::VectorXd::Zero(rows);
    double scale = 0.0;
    for (Index c = 0; c < p.cols; ++c)
      for (Index k = p.col_ptr[c]; k < p.col_ptr[c + 1]; ++k) {
        const double term = values[static_cast<std::size_t>(k)] * v[c];
        expected[p.row_idx[k]] += term, scale = std::max(scale, std::fabs(term));
      }
    for (const auto& b : m.blocks()) b->add_jacobian_product(0, b->size(), q.data(), t, v.data(), got.data());
    EXPECT_LE((got - expected).lpNorm<Eigen::Infinity>(), 1e-13 * std::max(1.0, scale)) << e.path();
    ++scenes;
  }
  EXPECT_GT(scenes, 30);
}

// same_data(): a constraint is the same as itself in another build of the scene (its driver's law too), and differs
// exactly where the parameter moved its data.
TEST(ParameterReach, SameDataComparesTheConstraintsData) {
  const Scene a = parse_scene(kReachCrankSlider, "c.yaml");
  const Scene b = parse_scene(kReachCrankSlider, "c.yaml");
  SceneOverrides o;
  o.parameters = {{"L3", 1.25}};
  const Scene c = parse_scene(kReachCrankSlider, "c.yaml", {}, o);
  for (std::size_t k = 0; k < a.model->blocks().size(); ++k) {
    const ConstraintBlock& x = *a.model->blocks()[k];
    const std::string kind = x.kind();
    for (std::size_t i = 0; i < x.size(); ++i) {
      EXPECT_TRUE(x.same_data(i, *b.model->blocks()[k])) << kind;
      EXPECT_EQ(x.same_data(i, *c.model->blocks()[k]), kind != "distance") << kind;
      EXPECT_FALSE(x.same_data(i + 1, *b.model->blocks()[k])) << "past the other block's end";
    }
    if (k > 0) {
      EXPECT_FALSE(x.same_data(0, *a.model->blocks()[0])) << "another kind's block";
    }
  }
}

// The sensitivities evaluated over the reach are those evaluated over every constraint, in the direct and the
// adjoint forms, at a row of a sweep: localised parameters (one crank's length among 40 bars, the crank-slider's
// lengths) and one that reaches every bar. A parameter given without its reach gets it found: the same values, bit
// for bit.
void expect_reach_changes_nothing(const Scene& s, const std::vector<std::string>& names) {
  std::vector<OutputSensitivity> with, without, unfound;
  for (const auto& name : names) {
    double value = 0.0;
    for (const auto& [n, v] : s.parameters)
      if (n == name) value = v;
    SceneOverrides keep;  // (whole_model_reach() reads every constraint of the models)
    keep.keep_sensitivity_models = true;
    with.push_back(sensitivity_along(s, name, value, 0.0, {}, keep));
    without.push_back(with.back());
    without.back().reach = std::make_shared<const ParameterReach>(whole_model_reach(*s.model));
    unfound.push_back(with.back());
    unfound.back().reach = nullptr;
  }
  SweepOptions o = s.sweep;
  o.steps = 10;
  o.velocities = o.accelerations = true;
  Workspace ws(*s.model);
  test::Trace tr;
  ASSERT_EQ(test::sweep(*s.model, o, &tr, nullptr, &ws), SolveStatus::kSuccess);
  const std::size_t k = 6;
  ws.q = tr.q[k], ws.qd = tr.qd[k], ws.qdd = tr.qdd[k];
  const SensitivityLayout layout{s.model->num_coordinates()};
  const std::size_t size = static_cast<std::size_t>(layout.size(names.size()));
  std::vector<Index> all(static_cast<std::size_t>(s.model->num_coordinates()));
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<Index>(i);
  for (const bool adjoint : {false, true}) {
    std::vector<double> a(size), b(size), c(size);
    if (adjoint) {
      ASSERT_EQ(solve_sensitivities_adjoint(*s.model, with, all, tr.t[k], 2, ws, a.data()), SolveStatus::kSuccess);
      ASSERT_EQ(solve_sensitivities_adjoint(*s.model, without, all, tr.t[k], 2, ws, b.data()), SolveStatus::kSuccess);
      ASSERT_EQ(solve_sensitivities_adjoint(*s.model, unfound, all, tr.t[k], 2, ws, c.data()), SolveStatus::kSuccess);
    } else {
      ASSERT_EQ(solve_sensitivities(*s.model, with, tr.t[k], 2, ws, a.data()), SolveStatus::kSuccess);
      ASSERT_EQ(solve_sensitivities(*s.model, without, tr.t[k], 2, ws, b.data()), SolveStatus::kSuccess);
      ASSERT_EQ(solve_sensitivities(*s.model, unfound, tr.t[k], 2, ws, c.data()), SolveStatus::kSuccess);
    }
    for (std::size_t i = 0; i < size; ++i) EXPECT_EQ(std::memcmp(&a[i], &c[i], sizeof(double)), 0) << i;
    double scale = 0.0;
    for (double v : b) scale = std::max(scale, std::fabs(v));
    ASSERT_GT(scale, 1e-3);
    for (std::size_t i = 0; i < size; ++i)
      EXPECT_NEAR(a[i], b[i], 1e-11 * scale) << (adjoint ? "adjoint " : "direct ") << i;
  }
}

TEST(ParameterReach, SensitivitiesOverTheReachAreThoseOverEveryConstraint) {
  expect_reach_changes_nothing(parse_scene(kReachCrankSlider, "c.yaml"), {"L2", "L3"});
  expect_reach_changes_nothing(parse_scene(kBars, "bars.yaml"), {"R7", "L"});
  expect_reach_changes_nothing(load_scene(test::model_path("spatial/rssr.yaml")), {"L"});
}

}  // namespace
}  // namespace phiq
