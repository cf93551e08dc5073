// The geometry of parts (phiq/shapes.hpp): the triangles of every shape closed and facing outwards, their volume
// tending to the exact one, mesh_is_closed on open and turned meshes, and STL and OBJ files written here read back
// with their exact values (a cube), refinements tending to the sphere, and bad files refused naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "phiq/orientation.hpp"
#include "phiq/shapes.hpp"
#include "phiq/types.hpp"
#include "scratch_path.hpp"

namespace phiq::shapes_test {

namespace fs = std::filesystem;
using kin3::V3;
constexpr double kPi = std::numbers::pi;

Shape make(ShapeKind kind, double radius = 0.0, double length = 0.0) {
  Shape s;
  s.kind = kind, s.radius = radius, s.length = length;
  return s;
}
Shape box(double a, double b, double c) {
  Shape s = make(ShapeKind::kBox);
  s.size = {a, b, c};
  return s;
}
Shape prism(std::vector<std::array<double, 2>> outline, double thickness) {
  Shape s = make(ShapeKind::kPolygon, 0.0, thickness);
  s.outline = std::move(outline);
  return s;
}
Shape curve(std::vector<V3> points, double width, bool closed) {
  Shape s = make(ShapeKind::kCurve, width / 2);  // the tube's radius
  s.points = std::move(points), s.closed = closed;
  return s;
}
double volume(const TriangleMesh& mesh) { return mesh_mass_properties(mesh).mass; }
V3 normal_of(const TriangleMesh& m, const std::array<int, 3>& t) {
  return kin3::cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]);
}
V3 centroid_of(const TriangleMesh& m, const std::array<int, 3>& t) {
  return (1.0 / 3.0) * (m.vertices[t[0]] + m.vertices[t[1]] + m.vertices[t[2]]);
}

struct TempDir {
  fs::path dir = phiq::test::test_scratch_path("phiq_shapes_");
  TempDir() { fs::remove_all(dir), fs::create_directories(dir); }
  ~TempDir() { fs::remove_all(dir); }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return path(name);
  }
};

// Binary STL: an 80-byte header (not starting with "solid"), the count, then per triangle its normal, three
// vertices (float32, little-endian as on x86) and a 16-bit attribute.
std::string binary_stl(const TriangleMesh& mesh) {
  std::string bytes(80, ' ');
  bytes.replace(0, 22, "binary STL, phiq tests");
  const auto put = [&](const void* p, std::size_t n) { bytes.append(static_cast<const char*>(p), n); };
  const std::uint32_t count = static_cast<std::uint32_t>(mesh.triangles.size());
  put(&count, 4);
  for (const auto& t : mesh.triangles) {
    const V3 n = normal_of(mesh, t);
    const V3 corners[4] = {(1.0 / kin3::norm(n)) * n, mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]};
    for (const V3& v : corners) {
      const float xyz[3] = {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
      put(xyz, 12);
    }
    const std::uint16_t attribute = 0;
    put(&attribute, 2);
  }
  return bytes;
}
std::string ascii_stl(const TriangleMesh& mesh) {
  std::string text = "solid cube\n";
  char line[160];
  for (const auto& t : mesh.triangles) {
    const V3 n = normal_of(mesh, t);
    std::snprintf(line, sizeof line, "  facet normal %.9g %.9g %.9g\n    outer loop\n", n.x, n.y, n.z);
    text += line;
    for (int k : t) {
      const V3& v = mesh.vertices[k];
      std::snprintf(line, sizeof line, "      vertex %.17g %.17g %.17g\n", v.x, v.y, v.z);
      text += line;
    }
    text += "    endloop\n  endfacet\n";
  }
  return text + "endsolid cube\n";
}
// OBJ: `v` lines, then faces of 1-based indices (any number of corners: Assimp triangulates them).
std::string obj(const std::vector<V3>& vertices, const std::vector<std::vector<int>>& faces) {
  std::string text = "# phiq tests\no shape\n";
  char line[120];
  for (const V3& v : vertices) {
    std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", v.x, v.y, v.z);
    text += line;
  }
  for (const auto& f : faces) {
    text += "f";
    for (int k : f) text += " " + std::to_string(k + 1);
    text += "\n";
  }
  return text;
}
std::string load_error(const std::string& path) {
  try {
    load_mesh_file(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// Errors of successive refinements that halve the step: positive, each at least `first_ratio` times the next,
// the ratio growing towards 4 (second order) and past `last_ratio` at the finest, never past 4 by more than 1 %.
void expect_second_order(const std::vector<double>& errors, double first_ratio, double last_ratio,
                         const std::string& what) {
  double ratio_before = 0.0;
  for (std::size_t k = 1; k < errors.size(); ++k) {
    const double ratio = errors[k - 1] / errors[k];
    EXPECT_GT(errors[k], 0.0) << what << " " << k;
    EXPECT_GT(ratio, std::max(first_ratio, ratio_before)) << what << " " << k;
    EXPECT_LT(ratio, 4.04) << what << " " << k;
    ratio_before = ratio;
  }
  EXPECT_GT(ratio_before, last_ratio) << what;
}

// ---- the triangles of shapes

TEST(ShapeTriangles, EveryConvexSolidIsClosedAndEveryTriangleFacesOutwards) {
  const int n = 32;
  struct Case {
    Shape shape;
    std::size_t triangles;  // the tessellation's count: fans at the axis, two per quad between rings
  };
  const std::vector<Case> cases{{box(0.3, 0.5, 0.7), 12},
                                {make(ShapeKind::kCylinder, 0.2, 0.9), 4 * n},
                                {make(ShapeKind::kCone, 0.3, 0.6), 2 * n},
                                {make(ShapeKind::kSphere, 0.4), 2 * n * (2 * (n / 4) - 1)},
                                {make(ShapeKind::kCapsule, 0.1, 0.5), 4 * n * (n / 4)}};
  for (const Case& c : cases) {
    const TriangleMesh mesh = shape_triangles(c.shape, n);
    const V3 inside = shape_mass_properties(c.shape, 1.0).center;
    EXPECT_TRUE(mesh_is_closed(mesh)) << static_cast<int>(c.shape.kind);
    EXPECT_EQ(mesh.triangles.size(), c.triangles) << static_cast<int>(c.shape.kind);
    int inward = 0;
    for (const auto& t : mesh.triangles) {
      const V3 normal = normal_of(mesh, t);
      EXPECT_GT(kin3::norm(normal), 0.0);
      if (kin3::dot(normal, centroid_of(mesh, t) - inside) <= 0.0) ++inward;
    }
    EXPECT_EQ(inward, 0) << static_cast<int>(c.shape.kind);
    EXPECT_GT(volume(mesh), 0.0);
  }
}

TEST(ShapeTriangles, LShapedPrismIsClosedAndFacesOutOfTheL) {
  const auto in_l = [](double x, double y) {
    return (x > 0 && x < 2 && y > 0 && y < 1) || (x > 0 && x < 1 && y > 0 && y < 3);
  };
  const TriangleMesh mesh = shape_triangles(prism({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 3}, {0, 3}}, 0.5));
  EXPECT_TRUE(mesh_is_closed(mesh));
  EXPECT_EQ(mesh.triangles.size(), 2u * 4 + 2 * 6);  // two caps of 4, two per side
  EXPECT_NEAR(volume(mesh), 4 * 0.5, 1e-14);
  for (const auto& t : mesh.triangles) {  // a step along the normal leaves the solid, a step against it enters it
    const V3 n = (1e-3 / kin3::norm(normal_of(mesh, t))) * normal_of(mesh, t), c = centroid_of(mesh, t);
    const V3 out = c + n, in = c - n;
    EXPECT_FALSE(in_l(out.x, out.y) && std::abs(out.z) < 0.25);
    EXPECT_TRUE(in_l(in.x, in.y) && std::abs(in.z) < 0.25);
  }
}

TEST(ShapeTriangles, VolumeAndInertiaApproachTheExactOnesAsSegmentsGrow) {
  const std::vector<Shape> solids{make(ShapeKind::kCylinder, 0.2, 0.9), make(ShapeKind::kCone, 0.3, 0.6),
                                  make(ShapeKind::kSphere, 0.4), make(ShapeKind::kCapsule, 0.1, 0.5)};
  for (const Shape& s : solids) {
    const MassProperties exact = shape_mass_properties(s, 1.0);
    std::vector<double> volume_errors, inertia_errors;
    for (int n : {8, 16, 32, 64, 128}) {
      const MassProperties mesh = mesh_mass_properties(shape_triangles(s, n));
      volume_errors.push_back((exact.mass - mesh.mass) / exact.mass);  // inscribed: always short of it
      inertia_errors.push_back(std::abs(exact.inertia[0] - mesh.inertia[0]) / exact.inertia[0]);
    }
    expect_second_order(volume_errors, 3.4, 3.98, "volume of kind " + std::to_string(static_cast<int>(s.kind)));
    expect_second_order(inertia_errors, 3.4, 3.98, "inertia of kind " + std::to_string(static_cast<int>(s.kind)));
    EXPECT_LT(volume_errors.back(), 2e-3);
  }
  // a cylinder's and a cone's are the inscribed regular polygon's: n/2 r² sin(2π/n) times h, or h/3
  for (int n : {8, 50}) {
    const double base = n / 2.0 * std::sin(2 * kPi / n);
    EXPECT_NEAR(volume(shape_triangles(make(ShapeKind::kCylinder, 0.2, 0.9), n)), base * 0.04 * 0.9, 1e-15);
    EXPECT_NEAR(volume(shape_triangles(make(ShapeKind::kCone, 0.3, 0.6), n)), base * 0.09 * 0.6 / 3, 1e-15);
  }
  EXPECT_EQ(shape_triangles(make(ShapeKind::kCone, 0.3, 0.6), 3).triangles.size(), 16u);  // at least 8 segments
}

TEST(ShapeTriangles, PlacementIsApplied) {
  Shape capsule = make(ShapeKind::kCapsule, 0.1, 0.3);
  const TriangleMesh local = shape_triangles(capsule, 16);
  capsule.at = {1.0, -2.0, 0.5};
  capsule.rotation = rotation_matrix(euler_parameters_from_axis_angle({1, 1, 0}, 0.9));
  const TriangleMesh placed = shape_triangles(capsule, 16);
  ASSERT_EQ(placed.vertices.size(), local.vertices.size());
  EXPECT_EQ(placed.triangles, local.triangles);
  const RotationMatrix& r = capsule.rotation;
  for (std::size_t i = 0; i < local.vertices.size(); ++i) {
    const V3 v = local.vertices[i], p = placed.vertices[i];
    EXPECT_NEAR(p.x, 1.0 + r[0] * v.x + r[1] * v.y + r[2] * v.z, 1e-14);
    EXPECT_NEAR(p.y, -2.0 + r[3] * v.x + r[4] * v.y + r[5] * v.z, 1e-14);
    EXPECT_NEAR(p.z, 0.5 + r[6] * v.x + r[7] * v.y + r[8] * v.z, 1e-14);
  }
  EXPECT_NEAR(volume(placed), volume(local), 1e-15);
}

TEST(ShapeTriangles, PlaneIsTwoTrianglesOfItsExtentFacingUp) {
  Shape plane = make(ShapeKind::kPlane);
  plane.size = {4, 2, 0};
  const TriangleMesh mesh = shape_triangles(plane);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    const V3 n = normal_of(mesh, t);
    EXPECT_EQ(n.x, 0.0);
    EXPECT_EQ(n.y, 0.0);
    EXPECT_GT(n.z, 0.0);
    area += n.z / 2;
  }
  EXPECT_DOUBLE_EQ(area, 8.0);
  EXPECT_FALSE(mesh_is_closed(mesh));
}

TEST(ShapeTriangles, PolygonOfEitherOrientationOrWithStraightRunsIsTheSamePrism) {
  const std::vector<std::array<double, 2>> ccw{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};
  const std::vector<std::array<double, 2>> cw(ccw.rbegin(), ccw.rend());
  const std::vector<std::array<double, 2>> runs{{0, 0}, {1, 0}, {2, 0}, {2, 1},  {1, 1},
                                                {1, 2}, {1, 3}, {0, 3}, {0, 1.5}};
  for (const auto& outline : {ccw, cw, runs}) {
    const TriangleMesh mesh = shape_triangles(prism(outline, 0.25));
    EXPECT_TRUE(mesh_is_closed(mesh)) << outline.size();
    EXPECT_NEAR(volume(mesh), 4 * 0.25, 1e-14) << outline.size();
  }
}

TEST(ShapeTriangles, CurvesAreClosedTubesOfTheirWidth) {
  // straight: the prism of the regular n-gon of radius w/2 along the segment
  const double w = 0.02;
  const TriangleMesh straight = shape_triangles(curve({{0, 0, 0}, {0.3, 0.4, 0}}, w, false), 16);
  EXPECT_TRUE(mesh_is_closed(straight));
  EXPECT_NEAR(volume(straight), 8 * std::sin(2 * kPi / 16) * (w / 2) * (w / 2) * 0.5, 1e-16);
  // bent, open and closed, out of one plane: closed surfaces facing out, every ring at w/2 from its point
  const std::vector<V3> points{{0, 0, 0}, {1, 0, 0}, {1, 1, 0.2}, {0, 1, 0.6}, {-0.5, 0.5, 0.3}};
  for (bool closed : {false, true}) {
    const TriangleMesh tube = shape_triangles(curve(points, w, closed), 12);
    EXPECT_TRUE(mesh_is_closed(tube)) << closed;
    EXPECT_GT(volume(tube), 0.0) << closed;
    for (std::size_t k = 0; k < points.size(); ++k)
      for (int j = 0; j < 12; ++j) EXPECT_NEAR(kin3::norm(tube.vertices[12 * k + j] - points[k]), w / 2, 1e-14);
  }
}

TEST(ShapeTriangles, ClosedTubeIsNotTwistedWhereItCloses) {
  // A (2, 3) torus knot: a frame carried once round it comes back turned by about 3 rad. From ring to ring the
  // twist is the turn of ring k's first vertex, carried by the smallest rotation between the rings' planes, to
  // ring k + 1's first vertex; spread over the rings it stays small everywhere, the closing pair included.
  const int n = 12, count = 48;
  std::vector<V3> points;
  for (int k = 0; k < count; ++k) {
    const double t = 2 * kPi * k / count;
    points.push_back(
        {std::cos(2 * t) * (2 + std::cos(3 * t)), std::sin(2 * t) * (2 + std::cos(3 * t)), std::sin(3 * t)});
  }
  const TriangleMesh tube = shape_triangles(curve(points, 0.05, true), n);
  ASSERT_TRUE(mesh_is_closed(tube));
  const auto unit = [](V3 v) { return (1.0 / kin3::norm(v)) * v; };
  for (int k = 0; k < count; ++k) {
    const int next = (k + 1) % count;
    const V3 o0 = tube.vertices[n * k] - points[k], o1 = tube.vertices[n * next] - points[next];
    const V3 t0 = unit(kin3::cross(o0, tube.vertices[n * k + n / 4] - points[k]));
    const V3 t1 = unit(kin3::cross(o1, tube.vertices[n * next + n / 4] - points[next]));
    const V3 axis = kin3::cross(t0, t1);
    const double sine = kin3::norm(axis), cosine = kin3::dot(t0, t1);
    V3 carried = o0;  // Rodrigues' rotation by the angle between t0 and t1 about their normal
    if (sine > 0.0) {
      const V3 u = (1.0 / sine) * axis;
      carried = cosine * o0 + sine * kin3::cross(u, o0) + (1 - cosine) * kin3::dot(u, o0) * u;
    }
    const double twist = std::atan2(kin3::dot(kin3::cross(carried, o1), t1), kin3::dot(carried, o1));
    EXPECT_LT(std::abs(twist), 0.1) << "rings " << k << " and " << next;
  }
}

TEST(ShapeTriangles, BadShapesAreRefusedNamingThem) {
  Shape ball = make(ShapeKind::kSphere, 0.0);
  ball.name = "ball";
  EXPECT_THROW(shape_triangles(ball), Error);
  Shape thread = curve({{0, 0, 0}, {0, 0, 0}}, 0.01, false);
  thread.name = "thread";
  try {
    shape_triangles(thread);
    ADD_FAILURE() << "a curve of one distinct point was drawn";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "curve 'thread': 1 distinct points, an open curve needs at least 2");
  }
  Shape mesh = make(ShapeKind::kMesh);
  mesh.name = "hull";
  EXPECT_THROW(shape_triangles(mesh), Error);  // no triangles
}

// ---- mesh_is_closed

TEST(ShapeMeshClosed, OpenTurnedAndDoubledSurfacesAreNotClosed) {
  const TriangleMesh cube = shape_triangles(box(1, 1, 1));
  EXPECT_TRUE(mesh_is_closed(cube));
  TriangleMesh open = cube;
  open.triangles.pop_back();
  EXPECT_FALSE(mesh_is_closed(open));
  TriangleMesh turned = cube;
  std::swap(turned.triangles[3][1], turned.triangles[3][2]);
  EXPECT_FALSE(mesh_is_closed(turned));
  TriangleMesh doubled = cube;
  doubled.triangles.push_back(cube.triangles[0]);
  EXPECT_FALSE(mesh_is_closed(doubled));
  EXPECT_FALSE(mesh_is_closed(TriangleMesh{}));
  TriangleMesh out_of_range = cube;
  out_of_range.triangles[0][0] = 8;
  EXPECT_FALSE(mesh_is_closed(out_of_range));
}

TEST(ShapeMeshClosed, CoincidentVerticesAreOneAndSeparateSolidsAreClosed) {
  const TriangleMesh cube = shape_triangles(box(1, 1, 1));
  TriangleMesh soup;  // every triangle with vertices of its own, as an STL file holds them
  for (const auto& t : cube.triangles) {
    const int first = static_cast<int>(soup.vertices.size());
    for (int k : t) soup.vertices.push_back(cube.vertices[k]);
    soup.triangles.push_back({first, first + 1, first + 2});
  }
  EXPECT_TRUE(mesh_is_closed(soup));
  TriangleMesh two = cube;
  for (const V3& v : cube.vertices) two.vertices.push_back(v + V3{3, 0, 0});
  for (const auto& t : cube.triangles) two.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  EXPECT_TRUE(mesh_is_closed(two));
  EXPECT_NEAR(volume(two), 2.0, 1e-14);
}

// ---- mesh files

// A 2 × 1 × 0.5 box at (0.25, −0.5, 1): every coordinate exact in float32, as STL stores them.
Shape float_exact_box() {
  Shape b = box(2.0, 1.0, 0.5);
  b.at = {0.25, -0.5, 1.0};
  return b;
}
void expect_cube_values(const TriangleMesh& mesh, double scale, const std::string& what) {
  EXPECT_EQ(mesh.vertices.size(), 8u) << what;
  EXPECT_EQ(mesh.triangles.size(), 12u) << what;
  EXPECT_TRUE(mesh_is_closed(mesh)) << what;
  Shape read = make(ShapeKind::kMesh);
  read.mesh = std::make_shared<TriangleMesh>(mesh);
  const MassProperties got = shape_mass_properties(read, 7800.0);
  const double m = 7800.0 * scale * scale * scale, s2 = scale * scale;
  EXPECT_NEAR(got.mass, m, 1e-12 * m) << what;
  EXPECT_NEAR(got.center.x, 0.25 * scale, 1e-12 * scale) << what;
  EXPECT_NEAR(got.center.y, -0.5 * scale, 1e-12 * scale) << what;
  EXPECT_NEAR(got.center.z, 1.0 * scale, 1e-12 * scale) << what;
  const std::array<double, 9> want{m * s2 * 1.25 / 12, 0, 0, 0, m * s2 * 4.25 / 12, 0, 0, 0, m * s2 * 5.0 / 12};
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(got.inertia[k], want[k], 1e-12 * m * s2) << what << " I" << k;
}

TEST(ShapeMeshFile, BinaryAndAsciiStlCubeGiveTheCubesExactValues) {
  const TempDir tmp;
  const TriangleMesh cube = shape_triangles(float_exact_box());
  const std::string binary = tmp.write("cube.stl", binary_stl(cube)),
                    text = tmp.write("cube_ascii.STL", ascii_stl(cube));
  expect_cube_values(load_mesh_file(binary), 1.0, "binary STL");
  expect_cube_values(load_mesh_file(text), 1.0, "ASCII STL");
  expect_cube_values(load_mesh_file(binary, 1e-3), 1e-3, "binary STL in millimetres");
}

TEST(ShapeMeshFile, ObjQuadsAreTriangulated) {
  const TempDir tmp;
  const TriangleMesh cube = shape_triangles(float_exact_box());
  // box_triangles' faces as quads: triangles 2f and 2f + 1 are (a, b, c), (a, c, d)
  std::vector<std::vector<int>> quads;
  for (std::size_t f = 0; f < 6; ++f) {
    const auto &t0 = cube.triangles[2 * f], &t1 = cube.triangles[2 * f + 1];
    quads.push_back({t0[0], t0[1], t0[2], t1[2]});
  }
  expect_cube_values(load_mesh_file(tmp.write("cube.obj", obj(cube.vertices, quads))), 1.0, "OBJ of quads");
}

// The icosahedron on the unit sphere, each triangle cut into four `level` times, midpoints pushed onto the sphere.
std::pair<std::vector<V3>, std::vector<std::vector<int>>> icosphere(int level) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<V3> v{{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                    {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  for (V3& p : v) p = (1.0 / kin3::norm(p)) * p;
  std::vector<std::vector<int>> f{{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                  {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                  {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> middle;
    const auto mid = [&](int a, int b) {
      const auto [at, added] = middle.try_emplace({std::min(a, b), std::max(a, b)}, static_cast<int>(v.size()));
      if (added) v.push_back((1.0 / kin3::norm(v[a] + v[b])) * (v[a] + v[b]));
      return at->second;
    };
    std::vector<std::vector<int>> finer;
    for (const auto& t : f) {
      const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      finer.insert(finer.end(), {{t[0], ab, ca}, {t[1], bc, ab}, {t[2], ca, bc}, {ab, bc, ca}});
    }
    f = std::move(finer);
  }
  return {v, f};
}

TEST(ShapeMeshFile, RefinedSpheresFromFilesApproachTheSphere) {
  const TempDir tmp;
  const double exact_volume = 4.0 / 3.0 * kPi, exact_inertia = 0.4 * exact_volume;  // unit radius and density
  const auto errors = [&](const TriangleMesh& mesh) {
    EXPECT_TRUE(mesh_is_closed(mesh));
    const MassProperties p = mesh_mass_properties(mesh);
    return std::pair{(exact_volume - p.mass) / exact_volume,
                     (exact_inertia - (p.inertia[0] + p.inertia[4] + p.inertia[8]) / 3) / exact_inertia};
  };
  std::vector<std::pair<double, double>> ico, uv;
  for (int level = 0; level <= 3; ++level) {
    const auto [v, f] = icosphere(level);
    const std::string path = tmp.write("ico" + std::to_string(level) + ".obj", obj(v, f));
    const TriangleMesh mesh = load_mesh_file(path);
    EXPECT_EQ(mesh.triangles.size(), 20u << (2 * level));
    ico.push_back(errors(mesh));
  }
  for (int n : {8, 16, 32, 64}) {
    const std::string path =
        tmp.write("uv" + std::to_string(n) + ".stl", binary_stl(shape_triangles(make(ShapeKind::kSphere, 1.0), n)));
    uv.push_back(errors(load_mesh_file(path)));
  }
  for (const auto* series : {&ico, &uv}) {
    std::vector<double> volume_errors, inertia_errors;
    for (const auto& [v, i] : *series) volume_errors.push_back(v), inertia_errors.push_back(i);
    expect_second_order(volume_errors, 2.7, 3.9, series == &ico ? "icosphere volume" : "UV sphere volume");
    expect_second_order(inertia_errors, 2.7, 3.85, series == &ico ? "icosphere inertia" : "UV sphere inertia");
  }
  EXPECT_LT(ico.back().first, 0.01);
  EXPECT_LT(uv.back().first, 0.005);
}

TEST(ShapeMeshFile, MissingCorruptForeignAndEmptyFilesAreRefusedNamingTheFile) {
  const TempDir tmp;
  std::string truncated = binary_stl(shape_triangles(box(1, 1, 1)));
  truncated.resize(84 + 3 * 50);  // the count still says 12 triangles
  fs::create_directories(tmp.dir / "folder.stl");
  const std::vector<std::pair<std::string, std::string>> cases{
      {tmp.path("missing.stl"), ": cannot read: No such file or directory"},
      {tmp.write("truncated.stl", truncated), ": not a readable STL file: "},
      {tmp.write("notes.txt", "a text file, not a mesh\n"), ": not a mesh file phiq reads (STL or OBJ"},
      {tmp.write("prose.stl", "Some prose, in a file named as a mesh.\n"), ": not a readable STL file: "},
      {tmp.write("empty.obj", ""), ": not a readable OBJ file: "},
      {tmp.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"), ": the OBJ file holds no triangles"},
      {tmp.write("no_facets.stl", "solid nothing\nendsolid nothing\n"), ": the STL file holds no triangles"},
      {tmp.path("folder.stl"), ": cannot read: is a directory"}};
  for (const auto& [path, says] : cases) {
    const std::string message = load_error(path);
    EXPECT_EQ(message.rfind(path + says, 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(ShapeMeshFile, OpenMeshFromAFileIsReadButHasNoMassProperties) {
  const TempDir tmp;
  TriangleMesh open = shape_triangles(box(1, 1, 1));
  open.triangles.resize(10);
  Shape shape = make(ShapeKind::kMesh);
  shape.name = "lid", shape.file = tmp.write("lid.stl", binary_stl(open));
  shape.mesh = std::make_shared<TriangleMesh>(load_mesh_file(shape.file));
  EXPECT_EQ(shape.mesh->triangles.size(), 10u);
  EXPECT_FALSE(mesh_is_closed(*shape.mesh));
  try {
    shape_mass_properties(shape, 1.0);
    ADD_FAILURE() << "an open mesh was given mass properties";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("mesh 'lid' (" + shape.file + "): the mesh is not closed", 0), 0u);
  }
}

}  // namespace phiq::shapes_test
