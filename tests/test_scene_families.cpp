// Indexed families in scenes (`for i in A..B`): they expand to the model listed one by one (nested, in equations,
// drivers, laws, parameters and parts, empty or bounded by enclosing indices; parts on one mesh share it), and
// malformed families, collisions, shadowing index names and families over the size limit are one-line errors naming
// the member. Separate from test_scene.cpp, which loads scenes written entry by entry.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "phiq/applied_loads.hpp"
#include "phiq/phiq.hpp"
#include "phiq/text.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// The error a scene gives.

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

// Parts from families (a stated mass on each crank, a density over a box on each coupler, sizes from the index)
// are the parts listed one by one, bit for bit; a name a family repeats is refused at its member.
TEST(SceneFamilies, PartsFromFamiliesAreThePartsListed) {
  const std::string families = std::string(kFamilies) +
                               "parts:\n"
                               "  for i in 0..N:\n"
                               "    \"crank{i}\": {frame: {origin: [i, 0], x: \"P{i}\"}, mass: 1 + i, center_of_mass: "
                               "[0.5, 0.1*i], inertia: 0.1*(i+1), colour: [0, 0, 1]}\n"
                               "  for i in 0..N-1:\n"
                               "    \"coupler{i}\": {frame: {origin: \"P{i}\", x: \"P{i+1}\"}, density: 2700, shapes: "
                               "[{type: box, size: [1, 0.02*(i+1), 0.01]}]}\n";
  std::string listed = std::string(kFamilies) + "parts:\n";
  for (int i = 0; i <= 3; ++i)
    listed += "  crank" + std::to_string(i) + ": {frame: {origin: [" + std::to_string(i) + ", 0], x: P" +
              std::to_string(i) + "}, mass: " + std::to_string(1 + i) + ", center_of_mass: [0.5, " + shortest(0.1 * i) +
              "], inertia: " + shortest(0.1 * (i + 1)) + ", colour: [0, 0, 1]}\n";
  for (int i = 0; i < 3; ++i)
    listed += "  coupler" + std::to_string(i) + ": {frame: {origin: P" + std::to_string(i) + ", x: P" +
              std::to_string(i + 1) + "}, density: 2700, shapes: [{type: box, size: [1, " + shortest(0.02 * (i + 1)) +
              ", 0.01]}]}\n";
  const Scene a = parse_scene(families, "families.yaml"), b = parse_scene(listed, "listed.yaml");
  ASSERT_EQ(a.parts.size(), 7u);
  ASSERT_EQ(b.parts.size(), 7u);
  for (std::size_t k = 0; k < a.parts.size(); ++k) {
    const Part &x = a.parts[k], &y = b.parts[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.name, k <= 3 ? "crank" + std::to_string(k) : "coupler" + std::to_string(k - 4));
    EXPECT_EQ(x.mass_source, y.mass_source);
    EXPECT_EQ(x.mass.mass, y.mass.mass) << x.name;
    EXPECT_EQ(x.mass.center.y, y.mass.center.y) << x.name;
    EXPECT_EQ(x.mass.inertia, y.mass.inertia) << x.name;
    EXPECT_EQ(x.colour, y.colour) << x.name;
    EXPECT_EQ(x.frame.origin.r[0], y.frame.origin.r[0]) << x.name;
    EXPECT_EQ(x.frame.x_toward.r[1], y.frame.x_toward.r[1]) << x.name;
    ASSERT_EQ(x.shapes.size(), y.shapes.size());
    if (!x.shapes.empty()) EXPECT_EQ(x.shapes[0].size.y, y.shapes[0].size.y) << x.name;
  }
  EXPECT_EQ(a.parts[2].mass.mass, 3.0);
  EXPECT_NEAR(a.parts[6].mass.mass, 2700 * 1 * 0.06 * 0.01, 1e-12);  // coupler2's box, 0.02·3 wide
  EXPECT_EQ(a.parts[6].frame.x_toward.r[0].coord(), a.model->coordinate_index("x3"));
  EXPECT_NE(error_of(std::string(kFamilies) + "parts:\n  crank2: {frame: {origin: [2, 0], x: P2}}\n  for i in 0..N:\n" +
                     "    \"crank{i}\": {frame: {origin: [i, 0], x: \"P{i}\"}}\n")
                .find("parts.for i in 0..N[i=2].crank{i}: part 'crank2' is defined twice"),
            std::string::npos);
}

// Loads from families (a force on each coupler growing with the index, a torque, a spring to the ground and a
// torsional spring on each crank's tip) are the loads listed one by one: the same names, parts and generalized
// forces, bit for bit; a name a family repeats is refused at its member.
TEST(SceneFamilies, LoadsFromFamiliesAreTheLoadsListed) {
  const std::string parts = std::string(kFamilies) +
                            "parts:\n"
                            "  for i in 0..N-1:\n"
                            "    \"coupler{i}\": {frame: {origin: \"P{i}\", x: \"P{i+1}\"}, mass: 1, "
                            "center_of_mass: [0.5, 0], inertia: 0.1}\n";
  const std::string families =
      parts +
      "loads:\n"
      "  forces:\n"
      "    - for i in 0..N-1:\n"
      "        - {name: \"push{i}\", part: \"coupler{i}\", at: [0.5, 0], force: [i + 1, t*i]}\n"
      "  torques:\n"
      "    - for i in 0..N-1: [{name: \"turn{i}\", part: \"coupler{i}\", torque: 2*i - y0}]\n"
      "  springs:\n"
      "    - for i in 0..N-1:\n"
      "        - {name: \"pull{i}\", between: [{part: \"coupler{i}\", at: [1, 0]}, {point: [i, "
      "2]}], stiffness: 10 + i, free_length: 0.5}\n"
      "  torsional_springs:\n"
      "    - for i in 0..N: [{name: \"wind{i}\", angle: \"atan2(y{i}, x{i} - i)\", stiffness: "
      "i + 1}]\n";
  std::string listed = parts + "loads:\n  forces:\n";
  for (int i = 0; i < 3; ++i)
    listed += "    - {name: push" + std::to_string(i) + ", part: coupler" + std::to_string(i) +
              ", at: [0.5, 0], force: [" + std::to_string(i + 1) + ", t*" + std::to_string(i) + "]}\n";
  listed += "  torques:\n";
  for (int i = 0; i < 3; ++i)
    listed += "    - {name: turn" + std::to_string(i) + ", part: coupler" + std::to_string(i) +
              ", torque: " + std::to_string(2 * i) + " - y0}\n";
  listed += "  springs:\n";
  for (int i = 0; i < 3; ++i)
    listed += "    - {name: pull" + std::to_string(i) + ", between: [{part: coupler" + std::to_string(i) +
              ", at: [1, 0]}, {point: [" + std::to_string(i) + ", 2]}], stiffness: " + std::to_string(10 + i) +
              ", free_length: 0.5}\n";
  listed += "  torsional_springs:\n";
  for (int i = 0; i <= 3; ++i)
    listed += "    - {name: wind" + std::to_string(i) + ", angle: \"atan2(y" + std::to_string(i) + ", x" +
              std::to_string(i) + " - " + std::to_string(i) + ")\", stiffness: " + std::to_string(i + 1) + "}\n";
  const Scene a = parse_scene(families, "families.yaml"), b = parse_scene(listed, "listed.yaml");
  ASSERT_TRUE(a.loads.applied && b.loads.applied);
  const AppliedLoads &x = *a.loads.applied, &y = *b.loads.applied;
  ASSERT_EQ(x.forces.size(), 3u);
  ASSERT_EQ(x.torques.size(), 3u);
  ASSERT_EQ(x.springs.size(), 3u);
  ASSERT_EQ(x.torsional_springs.size(), 4u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(x.forces[k].name, "push" + std::to_string(k));
    EXPECT_EQ(x.forces[k].part, y.forces[k].part);
    EXPECT_EQ(x.torques[k].name, y.torques[k].name);
    EXPECT_EQ(x.springs[k].name, y.springs[k].name);
    EXPECT_EQ(x.springs[k].stiffness, 10.0 + static_cast<double>(k));
    EXPECT_EQ(x.springs[k].b.at.x, y.springs[k].b.at.x);
  }
  EXPECT_EQ(x.torsional_springs[3].name, "wind3");
  EXPECT_EQ(x.torsional_springs[3].stiffness, 4.0);
  // the generalized forces at a moved placement and time: equal to the bit, and not zero
  Eigen::VectorXd q = a.model->initial_positions(), qd = Eigen::VectorXd::Zero(q.size());
  for (Index j = 0; j < q.size(); ++j) q(j) += 0.01 * static_cast<double>(j % 5), qd(j) = 0.1 * static_cast<double>(j);
  Eigen::VectorXd qa = Eigen::VectorXd::Zero(q.size()), qb = qa;
  add_applied_forces(x, q.data(), qd.data(), nullptr, 0.7, qa);
  add_applied_forces(y, q.data(), qd.data(), nullptr, 0.7, qb);
  EXPECT_EQ(qa, qb);
  EXPECT_GT(qa.norm(), 1.0);
  EXPECT_NE(error_of(parts + "loads:\n  forces:\n    - {name: push1, part: coupler0, force: [1, 0]}\n"
                             "    - for i in 0..N-1: [{name: \"push{i}\", part: \"coupler{i}\", force: [1, 0]}]\n")
                .find("loads.forces[1].for i in 0..N-1[i=1]"),
            std::string::npos)
      << error_of(parts +
                  "loads:\n  forces:\n    - {name: push1, part: coupler0, force: [1, 0]}\n"
                  "    - for i in 0..N-1: [{name: \"push{i}\", part: \"coupler{i}\", force: [1, 0]}]\n");
}

// A family of parts on one mesh file reads it once: every member shares the mesh (10⁴ links, one STL parsed); another
// scale of the same file is a mesh of its own.
TEST(SceneFamilies, PartsOnOneMeshShareIt) {
  const std::filesystem::path stl =
      std::filesystem::temp_directory_path() / ("phiq_family_mesh_" + std::to_string(::getpid()) + ".stl");
  std::ofstream(stl) << "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                        "endloop\nendfacet\nendsolid t\n";
  const std::string mesh = "{type: mesh, file: \"" + stl.string() + "\"";
  const Scene s = parse_scene(std::string(kFamilies) + "parts:\n  for i in 0..N:\n    \"crank{i}\": {frame: {origin: " +
                                  "[i, 0], x: \"P{i}\"}, shapes: [" + mesh +
                                  "}]}\n  big: {frame: {origin: P0, x: " + "P1}, shapes: [" + mesh + ", scale: 2}]}\n",
                              "families.yaml");
  std::filesystem::remove(stl);
  ASSERT_EQ(s.parts.size(), 5u);
  for (const Part& p : s.parts) ASSERT_TRUE(p.shapes.at(0).mesh) << p.name;
  for (std::size_t k = 1; k < 4; ++k) EXPECT_EQ(s.parts[k].shapes[0].mesh, s.parts[0].shapes[0].mesh) << k;
  EXPECT_NE(s.parts[4].shapes[0].mesh, s.parts[0].shapes[0].mesh);
  EXPECT_EQ(s.parts[0].shapes[0].mesh.use_count(), 4);
  double widest = 0.0;  // (1, 0, 0) scaled by 2
  for (const kin3::V3& v : s.parts[4].shapes[0].mesh->vertices) widest = std::max(widest, v.x);
  EXPECT_EQ(widest, 2.0);
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
    EXPECT_EQ(m.initial_positions()(r),
              std::stod(n.substr(1, 1)) * 100 + std::stod(n.substr(3, 1)) * 10 + std::stod(n.substr(5, 1)) + 0.5);
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
  std::string s = family_variant("  - for i in 0..N-1:\n",
                                 "  - for k in 1..0:\n      - {type: bogus}\n  - for i in N-3..(N*2-2)/2:\n");
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
  EXPECT_EQ(
      error_of(family_variant("length: 1}\n  - for i in 0..N-1:\n",
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
  const std::string nested =
      "phiq: 1\nparameters: {N: 9}\ncoordinates:\n  for i in 0..1:\n    for j in 0..N+i:\n"
      "      x{i}_{j}: 0\ntime: {start: 0, end: 1, steps: 1}\n";
  EXPECT_EQ(test::scene_error(nested, "few.yaml", few),
            "few.yaml:5:5: coordinates.for i in 0..1[i=1].for j in 0..N+i: the family would make 11 x 1 entries; "
            "families may make 12 entries in all and 0 are left (SceneLimits::max_family_instances)");
  // nesting deeper than the limit
  std::string deep = "coordinates:\n";
  std::string indent = "  ";
  for (int d = 0; d < 9; ++d) deep += indent + "for i" + std::to_string(d) + " in 0..0:\n", indent += "  ";
  deep += indent + "x: 0\ntime: {start: 0, end: 1, steps: 1}\n";
  EXPECT_EQ(error_of(deep),
            "bad.yaml:10:19: coordinates.for i0 in 0..0.for i1 in 0..0.for i2 in 0..0.for i3 in "
            "0..0.for i4 in 0..0.for i5 in 0..0.for i6 in 0..0.for i7 in 0..0.for i8 in 0..0: "
            "families nested more than 8 deep");
}

// A scene whose families fit one by one but not together is refused before any is expanded: the limit was consumed
// section by section, so that nfourbar with N = 10^7 was refused at its couplers after its coordinates, points and
// cranks were made (4.7 GB). Here the coordinates' body fails at the first member (an unknown name), which
// expanding them would report first.
TEST(SceneFamilies, FamiliesOverTheLimitTogetherAreRefusedBeforeAnyIsExpanded) {
  auto scene = [](std::int64_t n, const std::string& value) {
    return "phiq: 1\nparameters: {N: " + std::to_string(n) + "}\ncoordinates:\n  for k in 0..N-1:\n    q{k}: " + value +
           "\nconstraints:\n  - for k in 0..N-1:\n"
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
    EXPECT_NE(std::string(e.what()).find("the families would make 1002 entries in all"), std::string::npos) << e.what();
  }
  // nested families count one entry per member beforehand: they make at least that many
  const std::string nested =
      "phiq: 1\nparameters: {N: 1000}\ncoordinates:\n  for i in 0..N:\n"
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

}  // namespace
}  // namespace phiq
