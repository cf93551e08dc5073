// A part's shapes (part_reader.hpp): `parts.NAME.shapes[k]`, one map per shape, its type deciding its fields
// (models/README.md, Parts). Sizes are positive numbers or constant expressions; a mesh file is read relative to the
// scene's folder.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "phiq/text.hpp"
#include "scene/part_reader.hpp"

namespace phiq::detail::scene {

namespace {

// The shape types, by the names to_string(ShapeKind) gives them.
constexpr ShapeKind kShapeKinds[] = {ShapeKind::kBox,     ShapeKind::kCylinder, ShapeKind::kSphere,
                                     ShapeKind::kCapsule, ShapeKind::kCone,     ShapeKind::kPlane,
                                     ShapeKind::kPolygon, ShapeKind::kMesh,     ShapeKind::kCurve};

std::string shape_type_list() {
  std::string s;
  for (ShapeKind k : kShapeKinds) s += (s.empty() ? "" : ", ") + std::string(to_string(k));
  return s;
}

RotationMatrix about_z(double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {c, -s, 0, s, c, 0, 0, 0, 1};
}

}  // namespace

// `colour: [r, g, b]` or `[r, g, b, a]`, each in [0, 1], or "#rrggbb".
template <class C>
std::array<double, 4> PartReader::colour(const C& c) const {
  std::array<double, 4> rgba{0, 0, 0, 1};
  if (c.is_scalar()) {
    const std::string s = c.text();
    unsigned v = 0;
    if (s.size() != 7 || s[0] != '#' || std::sscanf(s.c_str() + 1, "%6x", &v) != 1)
      c.fail("a colour is [r, g, b], [r, g, b, a] (each from 0 to 1) or \"#rrggbb\"");
    for (int k = 0; k < 3; ++k) rgba[static_cast<std::size_t>(k)] = ((v >> (16 - 8 * k)) & 0xff) / 255.0;
    return rgba;
  }
  if (!c.is_sequence() || (c.size() != 3 && c.size() != 4))
    c.fail("a colour is [r, g, b], [r, g, b, a] (each from 0 to 1) or \"#rrggbb\"");
  for (std::size_t k = 0; k < c.size(); ++k) {
    const double v = r_.number(c.at(k));
    if (!(v >= 0.0 && v <= 1.0)) c.at(k).fail("a colour component is from 0 to 1");
    rgba[k] = v;
  }
  return rgba;
}

// A list of `n`-component points ([x, y] or [x, y, z]) of at least `least` entries.
template <class C>
std::vector<kin3::V3> PartReader::shape_points(const C& c, std::size_t n, std::size_t least) const {
  if (!c.is_sequence() || c.size() < least) c.fail("expected a list of at least " + std::to_string(least) + " points");
  std::vector<kin3::V3> out;
  for (const C& p : c.items()) {
    const std::vector<double> v = r_.numbers(p, n);
    out.push_back({v[0], v[1], n == 3 ? v[2] : 0.0});
  }
  return out;
}

template <class C>
Shape PartReader::read_shape(const C& c) const {
  if (!c.is_map()) c.fail("a shape is a map {type: box|cylinder|..., ...}");
  const std::string type = c.require("type").text();
  const ShapeKind* kind = nullptr;
  for (const ShapeKind& k : kShapeKinds)
    if (type == to_string(k)) kind = &k;
  if (!kind) c.field("type").fail("unknown shape type '" + type + "' (the types: " + shape_type_list() + ")");
  Shape s;
  s.kind = *kind;
  const char* placement = r_.spatial_ ? "orientation" : "angle";
  switch (s.kind) {
    case ShapeKind::kBox:
      c.expect_map({"type", "name", "colour", "at", placement, "size"});
      break;
    case ShapeKind::kSphere:
      c.expect_map({"type", "name", "colour", "at", placement, "radius"});
      break;
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:
      c.expect_map({"type", "name", "colour", "at", placement, "radius", "length"});
      break;
    case ShapeKind::kCone:
      c.expect_map({"type", "name", "colour", "at", placement, "radius", "height"});
      break;
    case ShapeKind::kPlane:
      c.expect_map({"type", "name", "colour", "at", placement, "size"});
      break;
    case ShapeKind::kPolygon:
      c.expect_map({"type", "name", "colour", "at", placement, "points", "thickness"});
      break;
    case ShapeKind::kMesh:
      c.expect_map({"type", "name", "colour", "at", placement, "file", "scale"});
      break;
    case ShapeKind::kCurve:
      c.expect_map({"type", "name", "colour", "at", placement, "points", "closed", "width"});
      break;
  }
  if (auto n = c.field("name"); n.present()) s.name = n.name();
  if (auto k = c.field("colour"); k.present()) s.colour = colour(k);
  if (auto a = c.field("at"); a.present()) {
    const std::vector<double> v = r_.numbers(a, r_.spatial_ ? 3 : 2);
    s.at = {v[0], v[1], r_.spatial_ ? v[2] : 0.0};
  }
  if (auto o = c.field(placement); o.present()) {
    if (r_.spatial_) {
      const EulerParameters e = r_.orientation(o);
      s.rotation = rotation_matrix(e);
    } else {
      s.rotation = about_z(r_.number(o));
    }
  }
  read_shape_size(c, s);
  return s;
}

// The fields that size the shape `s` (its kind already set).
template <class C>
void PartReader::read_shape_size(const C& c, Shape& s) const {
  switch (s.kind) {
    case ShapeKind::kBox: {
      const auto size = c.require("size");
      if (!size.is_sequence() || size.size() != 3) size.fail("a box's size is [x, y, z] (edge lengths)");
      s.size = {r_.positive(size.at(0)), r_.positive(size.at(1)), r_.positive(size.at(2))};
      break;
    }
    case ShapeKind::kPlane: {
      const auto size = c.require("size");
      if (!size.is_sequence() || size.size() != 2) size.fail("a plane's size is [x, y] (the drawn extent)");
      s.size = {r_.positive(size.at(0)), r_.positive(size.at(1)), 0.0};
      break;
    }
    case ShapeKind::kSphere:
      s.radius = r_.positive(c.require("radius"));
      break;
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:
      s.radius = r_.positive(c.require("radius")), s.length = r_.positive(c.require("length"));
      break;
    case ShapeKind::kCone:
      s.radius = r_.positive(c.require("radius")), s.length = r_.positive(c.require("height"));
      break;
    case ShapeKind::kPolygon: {
      for (const kin3::V3& p : shape_points(c.require("points"), 2, 3)) s.outline.push_back({p.x, p.y});
      s.length = r_.positive(c.require("thickness"));
      break;
    }
    case ShapeKind::kCurve:
      s.points = shape_points(c.require("points"), r_.spatial_ ? 3 : 2, 2);
      s.closed = c.field("closed").present() && c.field("closed").boolean();
      s.radius = c.field("width").present() ? 0.5 * r_.positive(c.field("width")) : 0.0;
      break;
    case ShapeKind::kMesh: {
      const auto f = c.require("file");
      s.file = f.text();
      s.scale = c.field("scale").present() ? r_.positive(c.field("scale")) : 1.0;
      // relative to the scene's folder, as a user writes it beside the scene
      std::filesystem::path p(s.file);
      if (p.is_relative()) p = std::filesystem::path(r_.file_).parent_path() / p;
      // one read per file and scale: a family of parts on one mesh shares it (10⁴ links, one STL read)
      std::shared_ptr<const TriangleMesh>& mesh = meshes_[{p.lexically_normal().string(), s.scale}];
      try {
        if (!mesh) mesh = std::make_shared<const TriangleMesh>(load_mesh_file(p.string(), s.scale));
      } catch (const Error& e) {
        f.fail(e.what());
      }
      s.mesh = mesh;
      break;
    }
  }
}

template std::array<double, 4> PartReader::colour(const Cursor&) const;
template std::array<double, 4> PartReader::colour(const TCursor&) const;
template Shape PartReader::read_shape(const Cursor&) const;
template Shape PartReader::read_shape(const TCursor&) const;

}  // namespace phiq::detail::scene
