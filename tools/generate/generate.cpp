#include "generate.hpp"
#include "generate_common.hpp"
#include "generate_linkages.hpp"

#include <cmath>
#include <stdexcept>

#include "phiq/scene.hpp"
#include "phiq/text.hpp"

namespace phiq::tools {

namespace {

// The first lines, as every kind writes them (gen::header: what was generated, the drive, the counts, the names),
// then the format version and the name.
void header(std::string& s, const GenerateOptions& o, const std::string& what, const std::string& driven,
            std::int64_t coordinates, std::int64_t kinematic, const std::string& names) {
  emit::SceneText t(1024);
  gen::header(t, o, what,
              driven + " = crank 0's angle (rad), linear from " + shortest_unsigned_zero(o.from) + " at t = 0 to " +
                  shortest_unsigned_zero(o.to) + " at t = 1; every crank at that angle (the parallelogram solution)",
              coordinates, kinematic, 1, names);
  s += t.take();
}

void footer(std::string& s, const GenerateOptions& o, const std::string& driven) {
  s += "drivers:\n  - {name: motor, coordinate: " + driven +
       ", law: {type: linear, initial: " + shortest_unsigned_zero(o.from) +
       ", rate: " + shortest_unsigned_zero(o.to - o.from) + "}}\n";
  s += "time: {start: 0, end: 1, steps: " + std::to_string(o.steps) + "}\n";
  s += std::string("output: {velocities: ") + (o.v ? "true" : "false") +
       ", accelerations: " + (o.a ? "true" : "false") + "}\n";
}

// The scenes are written with indexed families (`for i in 0..N`, models/README.md), so their size does not depend
// on N; they describe exactly the model the explicit listing (x0: ..., x1: ..., ...) did: the same names, order and
// initial values. Every per-member number is written as the sum the explicit listing computed (i + c, with the
// constant c a parameter written in full), which the loader evaluates in double precision in the order written:
// the same bits.

// IFToMM N four-bar: N+1 unit cranks pinned at (i, 0), tips P_i joined by N unit couplers; crank 0 driven by its
// angle from `from` at t = 0 to `to` at t = 1. Placed on the parallelogram solution at t = 0 (all cranks parallel).
std::string nfourbar_natural(const GenerateOptions& o) {
  const double c = std::cos(o.from), sn = std::sin(o.from);
  std::string s;
  header(s, o, "IFToMM N four-bar, natural coordinates (crank tips P_i = (x_i, y_i)), 1 dof", "theta", 2 * o.n + 3,
         2 * o.n + 2,
         "point P<i> = (x<i>, y<i>) is the tip of crank i, pinned at (i, 0); constraints crank<i> (P<i> at distance 1 "
         "from (i, 0)), coupler<i> (P<i> to P<i+1>, distance 1), crank0_angle (the angle of O->P0 = theta)");
  s += "parameters:\n";
  s += "  N: " + std::to_string(o.n) + "\n";
  s += "  c: " + shortest_unsigned_zero(c) + "    # cos(from): crank tip i starts at (i + c, s)\n";
  s += "  s: " + shortest_unsigned_zero(sn) + "    # sin(from)\n";
  s += "coordinates:\n";
  s += "  for i in 0..N:\n    x{i}: i + c\n    y{i}: s\n";
  s += "  theta: " + shortest_unsigned_zero(o.from) + "\n";
  s += "points:\n  O: [0, 0]\n";
  s += "  for i in 0..N:\n    P{i}: [\"x{i}\", \"y{i}\"]\n";
  s += "constraints:\n";
  s += "  - for i in 0..N:\n";
  s += "      - {name: \"crank{i}\", type: distance, points: [[i, 0], \"P{i}\"], length: 1}\n";
  s += "  - for i in 0..N-1:\n";
  s += "      - {name: \"coupler{i}\", type: distance, points: [\"P{i}\", \"P{i+1}\"], length: 1}\n";
  s += "  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}\n";
  footer(s, o, "theta");
  return s;
}

// The same mechanism in reference-point coordinates: crank i is body (xc_i, yc_i, psi_i) at its centre with its
// axis along the crank, coupler i body (xk_i, yk_i, phi_i); revolute pairs at the ends.
std::string nfourbar_reference_point(const GenerateOptions& o) {
  const double c = std::cos(o.from), sn = std::sin(o.from);
  std::string s;
  header(s, o, "IFToMM N four-bar, reference-point coordinates, 1 dof", "psi0", 6 * o.n + 3, 6 * o.n + 2,
         "bodies crank<i> = (xc<i>, yc<i>, psi<i>) and coupler<i> = (xk<i>, yk<i>, phi<i>), reference points at the "
         "middles, x axes along the bars; pairs pivot<i> (crank i to ground at (i, 0)), left<i> (crank i's tip to "
         "coupler i), right<i> (crank i+1's tip to coupler i)");
  s += "parameters:\n";
  s += "  N: " + std::to_string(o.n) + "\n";
  s += "  c: " + shortest_unsigned_zero(c) + "    # cos(from): coupler i starts at (i + 0.5 + c, s)\n";
  s += "  s: " + shortest_unsigned_zero(sn) + "    # sin(from)\n";
  s += "  hc: " + shortest_unsigned_zero(0.5 * c) + "    # crank i starts at (i + hc, hs), angle from\n";
  s += "  hs: " + shortest_unsigned_zero(0.5 * sn) + "\n";
  s += "  from: " + shortest_unsigned_zero(o.from) + "\n";
  s += "coordinates:\n";
  s += "  for i in 0..N:\n    xc{i}: i + hc\n    yc{i}: hs\n    psi{i}: from\n";
  s += "  for i in 0..N-1:\n    xk{i}: i + 0.5 + c\n    yk{i}: s\n    phi{i}: 0\n";
  s += "bodies:\n";
  s += "  for i in 0..N:\n    crank{i}: [\"xc{i}\", \"yc{i}\", \"psi{i}\"]\n";
  s += "  for i in 0..N-1:\n    coupler{i}: [\"xk{i}\", \"yk{i}\", \"phi{i}\"]\n";
  s += "constraints:\n";
  s += "  - for i in 0..N:\n";
  s += "      - {name: \"pivot{i}\", type: revolute, between: [{body: \"crank{i}\", at: [-0.5, 0]}, {body: ground, "
       "at: [i, 0]}]}\n";
  s += "  - for i in 0..N-1:\n";
  s += "      - {name: \"left{i}\", type: revolute, between: [{body: \"crank{i}\", at: [0.5, 0]}, {body: "
       "\"coupler{i}\", at: [-0.5, 0]}]}\n";
  s += "      - {name: \"right{i}\", type: revolute, between: [{body: \"crank{i+1}\", at: [0.5, 0]}, {body: "
       "\"coupler{i}\", at: [0.5, 0]}]}\n";
  footer(s, o, "psi0");
  return s;
}

// The entries of nfourbar's families (family_entries()): natural, the tips' coordinates (2 per crank), the points,
// the cranks and the couplers; reference-point, the cranks' and couplers' coordinates (3 each), their bodies, the
// pivots and the couplers' two pairs.
std::uint64_t nfourbar_family_entries(const GenerateOptions& o) {
  const auto cranks = static_cast<std::uint64_t>(o.n) + 1, couplers = static_cast<std::uint64_t>(o.n);
  if (o.coords == "natural") return 2 * cranks + cranks + cranks + couplers;
  return 3 * cranks + 3 * couplers + cranks + couplers + cranks + 2 * couplers;
}

}  // namespace

std::uint64_t family_entries(const GenerateOptions& o) {
  if (o.kind == "nfourbar") return nfourbar_family_entries(o);
  if (o.kind == "scissor") return scissor_family_entries(o);
  if (o.kind == "grid") return grid_family_entries(o);
  if (o.kind == "chain3d") return chain3d_family_entries(o);
  throw std::invalid_argument("unknown kind '" + o.kind + "' (available: nfourbar, scissor, grid, chain3d)");
}

std::int64_t max_n(const GenerateOptions& o) {
  // The counts grow with N (each family's members do, and the grid's shape only adds rows or columns), so the
  // largest N within the limit is found by bisection, in about 24 counts.
  const std::uint64_t limit = SceneLimits{}.max_family_instances;
  GenerateOptions at = o;
  auto fits = [&](std::int64_t n) {
    at.n = n;
    return family_entries(at) <= limit;
  };
  std::int64_t lo = 1, hi = gen::kMaxN;  // fits(lo); the answer is in [lo, hi]
  if (fits(hi)) return hi;
  while (lo < hi) {
    const std::int64_t mid = lo + (hi - lo + 1) / 2;
    if (fits(mid))
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

std::string generate_scene(const GenerateOptions& o) {
  if (o.n < 1) throw std::invalid_argument("N must be at least 1");
  if (o.steps < 0) throw std::invalid_argument("--steps must be >= 0");
  if (!std::isfinite(o.from) || !std::isfinite(o.to)) throw std::invalid_argument("--from and --to must be finite");
  if (!o.q) throw std::invalid_argument("--outputs must include q (positions are always written)");
  if (!std::isfinite(o.twist)) throw std::invalid_argument("--twist must be finite");
  // Finite options can still make numbers of the scene that are not: the driver's rate, and chain3d's phases
  // from + i·twist up to i = N; the loader would refuse the scene ('-inf' is not a finite number).
  if (!std::isfinite(o.to - o.from))
    throw std::invalid_argument(
        "--from and --to: the driven range to - from = " + shortest_unsigned_zero(o.to - o.from) + " is not finite");
  if (!std::isfinite(std::fabs(o.from) + static_cast<double>(o.n) * std::fabs(o.twist)))
    throw std::invalid_argument("--twist: crank N's phase from + N*twist is not finite");
  if (o.twist != 0.0 && o.kind != "chain3d") throw std::invalid_argument("--twist applies to chain3d only");
  if (o.kind == "nfourbar") {
    gen::check_size_and_coords(o);
    return o.coords == "natural" ? nfourbar_natural(o) : nfourbar_reference_point(o);
  }
  if (o.kind == "scissor") return scissor_scene(o);
  if (o.kind == "grid") return grid_scene(o);
  if (o.kind == "chain3d") return chain3d_scene(o);
  throw std::invalid_argument("unknown kind '" + o.kind + "' (available: nfourbar, scissor, grid, chain3d)");
}

}  // namespace phiq::tools
