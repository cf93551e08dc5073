// `phiq generate chain3d N`: a row of N spatial loops, the 3D analogue of nfourbar, with an exact solution.
// Geometry (chain3d_geometry.hpp), names and closed form: tools/README.md. N + 1 unit cranks turn on hinges of the
// same axis u (not a coordinate axis); crank i is pinned at O_i = i·o, and the tips P_i are joined by N couplers with
// ball joints at both ends. Crank 0 is driven by its angle θ about u; every crank i stays at θ + i·twist:
//   P_i = O_i + cos(θ + i·twist) e1 + sin(θ + i·twist) e2.
// Parallelogram row (twist 0, the default): o = e1 = d, couplers of length 1 parallel to d; the loops all lie in the
// plane through the pivots normal to u, tilted in space, and are singular where the cranks lie along the row
// (θ a multiple of π). Twisted row (--twist A, |sin A| ≥ 0.01): o = u (all hinges on one line), couplers of length
// √(3 − 2 cos A) between skew cranks; nonsingular at every θ, so it runs through any number of turns.
// Indexed families (`for i in 0..N`) keep the file's size independent of N.
#include <numbers>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

#include "chain3d_geometry.hpp"
#include "generate_common.hpp"
#include "generate_linkages.hpp"
#include "scene_writer.hpp"

namespace phiq::tools {

namespace {

using emit::Name;
using emit::SceneText;

// The rough placement (so that the first solve is an assembly): the exact solution at t = 0 with every point shifted
// by kShift along u, off its hinge's plane; the assembly moves each crank back on its own. A placement off the
// solution along the chain's motion (every crank turned a little), or one that lengthened every coupler a little
// (adding up to a large turn along a long chain), takes a correction through the whole chain: Newton failed on the
// second at N = 10^5, and the minimum-norm assembly of `phiq check`, which solves with Φq Φqᵀ, did not converge on
// the first at N = 10^6 (100 iterations, residual 8e-9); the shift takes 3-4 iterations at any N.
constexpr double kShift = 0.01;
// The twisted row's conditioning grows like 1/|sin twist|.
constexpr double kMinSinTwist = 0.01;

void check(const GenerateOptions& o) {
  gen::check_size_and_coords(o);
  if (o.twist == 0.0) {
    const double lo = std::min(o.from, o.to) / std::numbers::pi, hi = std::max(o.from, o.to) / std::numbers::pi;
    if (std::floor(hi) >= std::ceil(lo))
      throw std::invalid_argument(
          "--from and --to: the parallelogram row of chain3d is singular where the cranks lie along the row of "
          "pivots (the angle a multiple of pi); the driven range must not reach one (--twist runs through full "
          "turns)");
  } else if (!(std::fabs(std::sin(o.twist)) >= kMinSinTwist)) {
    throw std::invalid_argument(
        "--twist: |sin(twist)| must be at least 0.01 (at a multiple of pi neighbouring "
        "cranks are parallel or opposite on their common axis: singular)");
  }
}

// `name`x, `name`y, `name`z: the components of a vector as parameters.
std::string vector_parameters(const std::string& name, const chain3d::Vec& v, const std::string& comment) {
  return "  " + name + "x: " + shortest(v[0]) + "    # " + comment + "\n  " + name + "y: " + shortest(v[1]) + "\n  " +
         name + "z: " + shortest(v[2]) + "\n";
}

// The parameters both styles read: the size, the drive's start, the twist, the coupler length, the pivot step, the
// axes, and the rough placement's shift.
std::string parameters(const GenerateOptions& o, const chain3d::Geometry& g) {
  const bool twisted = o.twist != 0.0;
  return "parameters:\n  N: " + gen::str(o.n) + "\n  from: " + shortest(o.from) +
         "    # crank 0's angle at t = 0\n  tw: " + shortest(o.twist) +
         "    # crank i+1's phase ahead of crank i\n  L: " + shortest(chain3d::coupler_length(o.twist)) +
         "    # coupler length\n" + vector_parameters("o", twisted ? g.u : g.e1, "pivot step: O_i = i (ox, oy, oz)") +
         vector_parameters("u", g.u, "hinge axis") + vector_parameters("e1", g.e1, "crank direction at angle 0") +
         vector_parameters("e2", g.e2, "u x e1: crank direction at angle pi/2") + "  shift: " + shortest(kShift) +
         "    # rough placement: the solution at t = 0 shifted along u, off the hinges' planes\n";
}

// The drive's description.
std::string drive(const GenerateOptions& o, const std::string& what) {
  return what + " = crank 0's angle about u from e1 towards e2 (rad), linear from " + shortest(o.from) +
         " at t = 0 to " + shortest(o.to) + " at t = 1; crank i at that angle + i*tw";
}

std::string what(const GenerateOptions& o) {
  if (o.twist == 0.0)
    return "row of N spatial loops: N + 1 unit cranks on parallel hinges (axis u = (1, 2, 2)/3) pinned along "
           "d = (2, 1, -2)/3, their tips joined by N unit couplers with ball joints (the parallelogram row), 1 dof";
  return "twisted row of N spatial loops: N + 1 unit cranks on one hinge axis u = (1, 2, 2)/3, pinned one unit "
         "apart along it, neighbours " +
         shortest(o.twist) +
         " rad apart in phase, tips joined by couplers of length "
         "sqrt(3 - 2 cos twist) with ball joints, 1 dof";
}

// What the two coordinate styles write differently before their own sections.
struct Style {
  std::string driven;                   // what the driver drives (the Drive line)
  std::int64_t coordinates, kinematic;  // the counts
  std::string names;                    // the Names line
  std::string parameters;               // parameters of this style only
  std::string suffix;                   // crank i's point has the coordinates x<suffix>{i}, y<suffix>{i}, z<suffix>{i}
  const char* radius;                   // at this distance from the pivot
};

// The scene up to the body of the coordinates' family: the header, dimension 3, the parameters, and `for i in
// 0..N:` with the three coordinates of crank i's point, placed roughly: the exact position at t = 0 shifted along
// u. The caller continues the family's body.
SceneText begin(const GenerateOptions& o, const chain3d::Geometry& g, const Style& s) {
  SceneText t(4096);
  gen::header(t, o, what(o), drive(o, s.driven), s.coordinates, s.kinematic, 1, s.names);
  t.field("dimension", "3");
  t.raw(parameters(o, g) + s.parameters);
  t.section("coordinates");
  std::string c = "  for i in 0..N:\n";
  for (const char* k : {"x", "y", "z"})
    c += std::string("    ") + k + s.suffix + "{i}: i*o" + k + " + " + s.radius + "*(cos(from + i*tw)*e1" + k +
         " + sin(from + i*tw)*e2" + k + ") + shift*u" + k + "\n";
  t.raw(c);
  return t;
}

// The drivers, motor: crank 0's angle (the coordinate theta, or the angle of the joint pivot0) linear from `from`
// at t = 0 to `to` at t = 1, and the footer; returns the scene.
std::string finish(SceneText& t, const GenerateOptions& o, Name driven) {
  t.section("drivers");
  if (driven.family == "theta")
    t.linear_driver(Name{"motor"}, driven, o.from, o.to - o.from);
  else
    t.joint_driver(Name{"motor"}, driven, o.from, o.to - o.from);
  gen::footer(t, o);
  return t.take();
}

// Natural coordinates: the crank tips P_i and the driven angle theta. Per crank its hinge is two rows, the distance
// to O_i and the plane through O_i normal to u; the couplers are distances; crank0_angle ties P_0 to theta:
// (P_0 − O_0) · (−sin θ e1 + cos θ e2) = 0, smooth for every θ. n = 3N + 4, 3N + 3 kinematic equations + 1
// driver.
std::string chain3d_natural(const GenerateOptions& o) {
  const std::int64_t n = o.n;
  SceneText t = begin(o, chain3d::geometry(),
                      {"theta", 3 * n + 4, 3 * n + 3,
                       "point P<i> = (x<i>, y<i>, z<i>) is the tip of crank i; its hinge about u at O_i: crank<i> "
                       "(distance 1 from O_i) and plane<i> (P_i in the plane through O_i normal to u); coupler<i> "
                       "joins P_i and P_<i+1>; crank0_angle: (P_0 - O_0) . (-sin(theta) e1 + cos(theta) e2) = 0",
                       "", "", "1"});
  t.raw("  theta: from\n");
  t.section("points");
  t.raw("  for i in 0..N:\n    P{i}: [\"x{i}\", \"y{i}\", \"z{i}\"]\n");
  t.section("constraints");
  t.raw(
      "  - for i in 0..N:\n"
      "      - {name: \"crank{i}\", type: distance, points: [[i*ox, i*oy, i*oz], \"P{i}\"], length: 1}\n"
      "      - {name: \"plane{i}\", type: point_on_plane, between: [{body: ground, at: [i*ox, i*oy, i*oz], axis: "
      "[ux, uy, uz]}, {point: \"P{i}\"}]}\n"
      "  - for i in 0..N-1:\n"
      "      - {name: \"coupler{i}\", type: distance, points: [\"P{i}\", \"P{i+1}\"], length: L}\n"
      "  - {name: crank0_angle, type: equation, unit: length, expr: \"cos(theta)*(e2x*x0 + e2y*y0 + e2z*z0) - "
      "sin(theta)*(e1x*x0 + e1y*y0 + e1z*z0)\"}\n");
  return finish(t, o, Name{"theta"});
}

// Reference-point coordinates: crank i a body (position and Euler parameters) with its reference point at its middle,
// its x axis from its pivot to its tip and its z axis u; a revolute pair to ground at O_i about u (ground's joint
// frame x = e1, so the joint's angle is the crank's θ), and a distance between neighbouring tips (a coupler with a
// ball joint at each end). n = 7N + 7, 7N + 6 kinematic equations (N + 1 of them the Euler normalisations) + 1
// driver, on the angle of joint pivot0.
std::string chain3d_reference_point(const GenerateOptions& o) {
  const std::int64_t n = o.n;
  const chain3d::Geometry g = chain3d::geometry();
  std::string euler;
  for (const auto& [name, q] : {std::pair{"qa", g.qa}, std::pair{"qb", g.qb}})
    for (std::size_t k = 0; k < 4; ++k)
      euler += "  " + std::string(name) + std::to_string(k) + ": " + shortest(q[k]) +
               (k == 0 && name[1] == 'a' ? "    # a crank's Euler parameters at angle a: cos(a/2) qa + sin(a/2) qb\n"
                                         : "\n");
  SceneText t = begin(o, g,
                      {"the angle of joint pivot0", 7 * n + 7, 7 * n + 6,
                       "body crank<i> = (xc<i>, yc<i>, zc<i>, e0c<i>, e1c<i>, e2c<i>, e3c<i>) is crank i: reference "
                       "point at its middle, x axis from its pivot to its tip, z axis u; pivot<i> (revolute to ground "
                       "at O_i about u), coupler<i> (distance between the tips of cranks i and i+1)",
                       euler, "c", "0.5"});
  std::string c;
  for (char k : {'0', '1', '2', '3'})
    c += std::string("    e") + k + "c{i}: qa" + k + "*cos((from + i*tw)/2) + qb" + k + "*sin((from + i*tw)/2)\n";
  t.raw(c);
  t.section("bodies");
  t.raw(
      "  for i in 0..N:\n    crank{i}: [\"xc{i}\", \"yc{i}\", \"zc{i}\", \"e0c{i}\", \"e1c{i}\", \"e2c{i}\", "
      "\"e3c{i}\"]\n");
  t.section("constraints");
  t.raw(
      "  - for i in 0..N:\n"
      "      - {name: \"pivot{i}\", type: revolute, between: [{body: ground, at: [i*ox, i*oy, i*oz], axis: [ux, uy, "
      "uz], ref: [e1x, e1y, e1z]}, {body: \"crank{i}\", at: [-0.5, 0, 0]}]}\n"
      "  - for i in 0..N-1:\n"
      "      - {name: \"coupler{i}\", type: distance, between: [{body: \"crank{i}\", at: [0.5, 0, 0]}, {body: "
      "\"crank{i+1}\", at: [0.5, 0, 0]}], length: L}\n");
  return finish(t, o, Name{"pivot0"});
}

}  // namespace

// The entries of chain3d's families, as the loader counts them (family_entries(), generate.hpp): the points' or
// crank bodies' coordinates (3 or 7 per crank), the points or bodies, the hinges (crank and plane per crank, or
// pivot) and the couplers.
std::uint64_t chain3d_family_entries(const GenerateOptions& o) {
  const auto cranks = static_cast<std::uint64_t>(o.n) + 1, couplers = static_cast<std::uint64_t>(o.n);
  if (o.coords == "natural") return 3 * cranks + cranks + 2 * cranks + couplers;
  return 7 * cranks + cranks + cranks + couplers;
}

std::string chain3d_scene(const GenerateOptions& o) {
  check(o);
  return o.coords == "natural" ? chain3d_natural(o) : chain3d_reference_point(o);
}

}  // namespace phiq::tools
