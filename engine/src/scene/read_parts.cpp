// The `parts` section (part_reader.hpp, models/README.md "Parts"): each part a frame on a body, natural points and
// vectors, or expressions of the coordinates; its shapes (read_shapes.cpp); its mass, stated or from a density.
#include <Eigen/Eigenvalues>

#include <cmath>
#include <string>
#include <unordered_set>

#include "phiq/text.hpp"
#include "scene/family_expansion.hpp"
#include "scene/part_reader.hpp"

namespace phiq::detail::scene {

namespace {

// The inertia tensor stated as a matrix is symmetric to this relative tolerance (its entries are typed by hand).
constexpr double kSymmetryTolerance = 1e-9;

bool same_slots(const Attachment3& a, const Attachment3& b) {
  return a.r[0] == b.r[0] && a.r[1] == b.r[1] && a.r[2] == b.r[2];
}

bool zero_vector(const Attachment3& a) {
  for (const Slot& s : a.r)
    if (s.is_coordinate() || s.value() != 0.0) return false;
  return true;
}

// A frame of points whose x (or y) can never give a direction: x's point the origin itself, a zero vector, or y's
// point x's. (Points that only meet at some row are named at that row, phiq/inverse_dynamics.hpp.)
template <class C>
void refuse_frame_without_direction(const C& f, const PartFrame& pf) {
  auto none = [](const Attachment3& to, bool is_point, const Attachment3& origin) {
    return is_point ? same_slots(to, origin) : zero_vector(to);
  };
  if (none(pf.x_toward, pf.x_is_point, pf.origin))
    f.field("x").fail(pf.x_is_point ? "x is the origin's point: the frame has no direction"
                                    : "x is a zero vector: the frame has no direction");
  if (!pf.spatial_frame) return;
  if (none(pf.y_toward, pf.y_is_point, pf.origin) ||
      (pf.x_is_point && pf.y_is_point && same_slots(pf.y_toward, pf.x_toward)))
    f.field("y").fail("y is the origin's point, x's point or a zero vector: the frame has no plane");
}

}  // namespace

void PartReader::read_parts(const Cursor& c, Scene& scene) {
  if (!c.is_map()) c.fail("parts is a map NAME: {body: B, shapes: [...], mass: ...}");
  std::unordered_set<std::string> names;
  for (const Part& p : scene.parts) names.insert(p.name);
  r_.reserve_ = [&](std::size_t more) { scene.parts.reserve(scene.parts.size() + more); };
  r_.read_map(c.entries(), [&](const std::string& name, const auto& v) {
    if (!names.insert(name).second) v.fail("part '" + name + "' is defined twice");
    read_part(name, v, scene);
  });
  r_.reserve_ = nullptr;
}

template <class C>
void PartReader::read_part(const std::string& name, const C& v, Scene& scene) const {
  if (!v.is_map()) v.fail("a part is a map {body: B | frame: {...}, shapes: [...], mass: ...}");
  v.expect_map({"body", "frame", "colour", "shapes", "mass", "center_of_mass", "inertia", "density"});
  Part part;
  part.name = name;
  part_frame(v, name, part);
  if (auto k = v.field("colour"); k.present()) part.colour = colour(k);
  if (auto s = v.field("shapes"); s.present()) {
    if (!s.is_sequence()) s.fail("shapes is a list of maps {type: box|cylinder|..., ...}");
    for (const C& item : s.items()) part.shapes.push_back(read_shape(item));
  }
  part_mass(v, part);
  part.fixed = max_coordinate(part.frame) < 0 &&
               (part.frame.kind != PartFrameKind::kExpressions || !frame_depends_on_time(part.frame));
  scene.parts.push_back(std::move(part));
}

bool PartReader::frame_depends_on_time(const PartFrame& f) {
  bool t = f.angle && f.angle->depends_on_time();
  for (const auto& e : f.at) t = t || e->depends_on_time();
  return t;
}

// The part's frame: `body: B` (default: the body named as the part), `frame: {origin: P, x: Q|u, y: R|v}` (natural
// coordinates), or `frame: {at: P | [x, y(, z)], angle: A, axis: [..]}` (expressions of the coordinates).
template <class C>
void PartReader::part_frame(const C& v, const std::string& name, Part& part) const {
  const auto body = v.field("body");
  const auto frame = v.field("frame");
  if (body.present() && frame.present()) frame.fail("a part is on a body or has a frame of its own, not both");
  if (frame.present()) return points_or_expression_frame(frame, part);
  const std::string b = body.present() ? body.name() : name;
  const bool known = b == kGround || (r_.spatial_ ? r_.entry_at(v, b, r_.names_.bodies3) >= 0
                                                  : r_.entry_at(v, b, r_.names_.bodies) >= 0);
  if (!known) {
    if (body.present()) body.fail("unknown body '" + b + "'");
    v.fail("'" + name + "' is no body: give the part `body: B`, or its own `frame: {...}`");
  }
  part.body = b;
  const C where = body.present() ? body : v;
  if (r_.spatial_) {
    part.frame.kind = PartFrameKind::kSpatialBody;
    part.frame.spatial = b == kGround ? Frame3::ground() : r_.names_.bodies3[r_.entry_at(where, b, r_.names_.bodies3)];
  } else {
    part.frame.kind = PartFrameKind::kPlanarBody;
    part.frame.planar = b == kGround ? Frame2{} : r_.names_.bodies[r_.entry_at(where, b, r_.names_.bodies)];
  }
}

// An attachment a frame's axis points along: a point (a name or inline), or in space a natural unit vector's name.
template <class C>
Attachment3 PartReader::frame_toward(const C& c, bool& is_point) const {
  is_point = true;
  if (r_.spatial_) {
    if (c.is_scalar() && r_.entry_at(c, c.text(), r_.names_.vectors) >= 0) {
      is_point = false;
      return Attachment3::natural(r_.vector3(c));
    }
    return Attachment3::natural(r_.point3(c));
  }
  const Point2 p = r_.point(c);
  return Attachment3::natural(Point3{p.x, p.y, Slot::constant(0.0)});
}

template <class C>
void PartReader::points_or_expression_frame(const C& f, Part& part) const {
  if (!f.is_map()) f.fail("a frame is {origin: P, x: Q, y: R} (points, vectors) or {at: P, angle: A} (expressions)");
  PartFrame& pf = part.frame;
  if (f.field("origin").present()) {
    if (r_.spatial_)
      f.expect_map({"origin", "x", "y"});
    else
      f.expect_map({"origin", "x"});
    pf.kind = PartFrameKind::kPoints;
    pf.spatial_frame = r_.spatial_;
    bool origin_point = true;
    pf.origin = frame_toward(f.require("origin"), origin_point);
    if (!origin_point) f.field("origin").fail("the origin is a point, not a vector");
    pf.x_toward = frame_toward(f.require("x"), pf.x_is_point);
    if (r_.spatial_) pf.y_toward = frame_toward(f.require("y"), pf.y_is_point);
    refuse_frame_without_direction(f, pf);
    part.body = "frame of points";
    return;
  }
  if (r_.spatial_)
    f.expect_map({"at", "angle", "axis"});
  else
    f.expect_map({"at", "angle"});
  pf.kind = PartFrameKind::kExpressions;
  pf.spatial_frame = r_.spatial_;
  const auto at = f.require("at");
  const std::size_t n = r_.spatial_ ? 3 : 2;
  if (at.is_scalar()) {  // a point's name: its components as expressions of its slots
    bool is_point = true;
    const Attachment3 p = frame_toward(at, is_point);
    if (!is_point) at.fail("at is a point, not a vector");
    for (std::size_t k = 0; k < n; ++k) pf.at.push_back(slot_expression(at, p.r[k]));
  } else {
    if (!at.is_sequence() || at.size() != n)
      at.fail(r_.spatial_ ? "at is a point or [x, y, z] (expressions)" : "at is a point or [x, y] (expressions)");
    for (std::size_t k = 0; k < n; ++k) pf.at.push_back(r_.compile(at.at(k), true));
  }
  if (auto a = f.field("angle"); a.present()) pf.angle = r_.compile(a, true);
  if (auto ax = f.field("axis"); ax.present()) {
    kin3::V3 u = r_.direction3(ax);
    pf.axis = (1.0 / kin3::norm(u)) * u;
  }
  part.body = "frame of expressions";
}

// A slot as an expression: a coordinate's name, or its constant.
template <class C>
std::shared_ptr<const CompiledExpression> PartReader::slot_expression(const C& c, const Slot& s) const {
  const std::string text = s.is_coordinate() ? r_.builder_.coordinate_name(s.coord()) : shortest(s.value());
  try {
    return CompiledExpression::compile(text, r_.resolver(true, text), true);
  } catch (const Error& e) {
    c.fail(e.what());
  }
}

// `mass` with `center_of_mass` and `inertia` (planar: Izz about the centre; spatial: [Ixx, Iyy, Izz], six values
// [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3×3 matrix, about the centre in body axes), or `density` over the shapes.
template <class C>
void PartReader::part_mass(const C& v, Part& part) const {
  const auto mass = v.field("mass"), density = v.field("density");
  const auto com = v.field("center_of_mass"), inertia = v.field("inertia");
  if (mass.present() && density.present()) density.fail("give a part's mass or its density, not both");
  if (!mass.present()) {
    if (com.present()) com.fail("a centre of mass needs the part's `mass` (or give its `density`)");
    if (inertia.present()) inertia.fail("an inertia needs the part's `mass` (or give its `density`)");
  }
  if (density.present()) {
    part.density = r_.positive(density);
    part.mass = shapes_mass(density, part, part.density);
    part.mass_source = MassSource::kDensity;
    return;
  }
  if (!mass.present()) return;
  part.mass_source = MassSource::kStated;
  part.mass.mass = r_.positive(mass);
  if (inertia.present()) part.mass.inertia = inertia_tensor(inertia);
  if (com.present()) {
    const std::vector<double> c3 = r_.numbers(com, r_.spatial_ ? 3 : 2);
    part.mass.center = {c3[0], c3[1], r_.spatial_ ? c3[2] : 0.0};
  }
  if (com.present() && inertia.present()) return;
  // what the stated fields leave out comes from the shapes at uniform density: their centroid, their inertia scaled
  const MassProperties shapes = shapes_mass(com.present() ? inertia : com, part, 1.0);
  if (!com.present()) part.mass.center = shapes.center;
  if (!inertia.present())
    for (std::size_t k = 0; k < 9; ++k) part.mass.inertia[k] = shapes.inertia[k] * part.mass.mass / shapes.mass;
}

// The mass properties of the part's solid shapes at `density`, refused at `c` when it has none with a volume.
template <class C>
MassProperties PartReader::shapes_mass(const C& c, const Part& part, double density) const {
  std::vector<MassProperties> each;
  for (std::size_t k = 0; k < part.shapes.size(); ++k) {
    const Shape& s = part.shapes[k];
    if (s.kind == ShapeKind::kPlane || s.kind == ShapeKind::kCurve) continue;
    try {
      each.push_back(shape_mass_properties(s, density));
    } catch (const Error& e) {
      c.fail("shapes[" + std::to_string(k) + "]" + (s.name.empty() ? "" : " ('" + s.name + "')") + ": " + e.what());
    }
  }
  if (each.empty())
    c.fail("part '" + part.name + "' has no solid shape to take its mass properties from: give mass, " +
           "center_of_mass and inertia");
  return combine_mass_properties(each);
}

// A stated inertia tensor, checked symmetric and positive definite, with the triangle inequality of its principal
// moments (a physical body: each at most the sum of the other two).
template <class C>
std::array<double, 9> PartReader::inertia_tensor(const C& c) const {
  std::array<double, 9> I{};
  if (!r_.spatial_) {
    I[8] = r_.positive(c);  // Izz; a planar body turns about z only
    return I;
  }
  if (c.is_sequence() && c.size() == 3 && c.at(0).is_sequence()) {
    for (std::size_t i = 0; i < 3; ++i) {
      const std::vector<double> row = r_.numbers(c.at(i), 3);
      for (std::size_t j = 0; j < 3; ++j) I[3 * i + j] = row[j];
    }
  } else if (c.is_sequence() && (c.size() == 3 || c.size() == 6)) {
    const std::vector<double> v = r_.numbers(c, 0);
    I[0] = v[0], I[4] = v[1], I[8] = v[2];
    if (v.size() == 6) I[1] = I[3] = v[3], I[2] = I[6] = v[4], I[5] = I[7] = v[5];
  } else {
    c.fail("an inertia is [Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3×3 matrix (about the centre of mass)");
  }
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = I[static_cast<std::size_t>(3 * i + j)];
  if ((m - m.transpose()).norm() > kSymmetryTolerance * m.norm()) c.fail("the inertia matrix is not symmetric");
  const Eigen::Vector3d p = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m, Eigen::EigenvaluesOnly).eigenvalues();
  if (!(p(0) > 0.0))
    c.fail("the inertia is not positive definite (principal moments " + shortest(p(0)) + ", " + shortest(p(1)) + ", " +
           shortest(p(2)) + ")");
  if (p(2) > (p(0) + p(1)) * (1.0 + 1e-12))
    c.fail("no body has these principal moments (" + shortest(p(0)) + ", " + shortest(p(1)) + ", " + shortest(p(2)) +
           "): the largest exceeds the sum of the other two");
  return I;
}

}  // namespace phiq::detail::scene
