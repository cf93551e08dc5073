// `phiq generate scissor N` and `phiq generate grid N`: linkages of any size with a closed-form solution, for tests
// and benchmarks. Geometry, names and closed forms: tools/README.md. Single entries go through the emitters of
// scene_writer.hpp; the indexed families (`for k in ...`) are built here and written with SceneText::raw.
#include "generate_linkages.hpp"

#include <numbers>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "generate_common.hpp"
#include "scene_writer.hpp"

namespace phiq::tools {

namespace {

using emit::Attach;
using emit::Component;
using emit::Name;
using emit::PointRef;
using emit::SceneText;

using gen::footer;
using gen::header;
using gen::str;

void check(const GenerateOptions& o, double singular_at, const std::string& what) {
  gen::check_size_and_coords(o);
  for (double v : {o.from, o.to})
    if (!(v > 0.0 && v < singular_at)) throw std::invalid_argument("--from and --to: " + what);
}

// ---------------------------------------------------------------------------------------------------------------
// Scissor lift: stage k (0 ≤ k < N) has bar a_k from L_k up to R_{k+1} and bar b_k from R_k up to L_{k+1}, both of
// length 1, pinned together at their midpoints M_k. L_0 is pinned to ground at the origin, R_0 slides along the
// x axis. Driven: θ, the angle of the bars to the horizontal. Closed form: L_k = (0, k sin θ), R_k = (cos θ,
// k sin θ), M_k = (cos θ / 2, (k + 1/2) sin θ); a_k is at angle θ, b_k at π − θ.

const char* const kScissorWhat = "scissor lift of N stages (unit bars crossing at their midpoints), 1 dof";

std::string scissor_drive(const GenerateOptions& o, const std::string& coordinate) {
  return coordinate + " = the bars' angle to the horizontal (rad), linear from " + shortest(o.from) + " at t = 0 to " +
         shortest(o.to) + " at t = 1";
}

// The scenes are written with indexed families (`for k in 0..N-1`, models/README.md), so that their size does not
// depend on N, and describe exactly the model listing every entry would: the same names and order, and initial
// values written as expressions of the index and of parameters holding the doubles used here, which the loader
// evaluates in double precision in the order written ((k + 0.5)*s is the double (k + 0.5) * s computed here).

// Natural coordinates: the joints L_k, R_k (k ≥ 1) and the crossing pins M_k; R_0 = (xr0, 0) on the ground.
// Per stage 6 coordinates and 6 equations: the two bars (distance), the pin half a bar from each lower end
// (distance), and on each bar's line (point_on_line). With θ and xr0: n = 6N + 2, m = 6N + 1 + 1 driver.
std::string scissor_natural(const GenerateOptions& o) {
  const std::int64_t n = o.n;
  const double c = std::cos(o.from), s = std::sin(o.from);
  SceneText t(4096);
  header(t, o, kScissorWhat, scissor_drive(o, "theta"), 6 * n + 2, 6 * n + 1, 1,
         "points L<k> = (xl<k>, yl<k>) and R<k> = (xr<k>, yr<k>) are the left and right joints at level k "
         "(L0 = origin, R0 = (xr0, 0) the slider), M<k> = (xm<k>, ym<k>) the crossing pin of stage k; "
         "bar a<k> joins L<k> to R<k+1>, bar b<k> joins R<k> to L<k+1>");
  t.raw("parameters:\n  N: " + str(n) + "\n  c: " + shortest(c) + "    # cos(from)\n  s: " + shortest(s) +
        "    # sin(from)\n  hc: " + shortest(0.5 * c) + "    # c/2\n");
  t.section("coordinates");
  t.coordinate(Name{"xr", 0}, c);
  t.raw(
      "  for k in 0..N-1:\n"
      "    xm{k}: hc\n    ym{k}: (k + 0.5)*s\n"
      "    xl{k+1}: 0\n    yl{k+1}: (k+1)*s\n"
      "    xr{k+1}: c\n    yr{k+1}: (k+1)*s\n");
  t.coordinate(Name{"theta"}, o.from);
  t.section("points");
  t.point(Name{"L", 0}, Component::of(0.0), Component::of(0.0));
  t.point(Name{"R", 0}, Name{"xr", 0}, Component::of(0.0));
  t.raw(
      "  for k in 0..N-1:\n"
      "    M{k}: [\"xm{k}\", \"ym{k}\"]\n"
      "    L{k+1}: [\"xl{k+1}\", \"yl{k+1}\"]\n"
      "    R{k+1}: [\"xr{k+1}\", \"yr{k+1}\"]\n");
  t.section("constraints");
  t.raw(
      "  - for k in 0..N-1:\n"
      "      - {name: \"a{k}\", type: distance, points: [\"L{k}\", \"R{k+1}\"], length: 1}\n"
      "      - {name: \"b{k}\", type: distance, points: [\"R{k}\", \"L{k+1}\"], length: 1}\n"
      "      - {name: \"mida{k}\", type: distance, points: [\"L{k}\", \"M{k}\"], length: 0.5}\n"
      "      - {name: \"midb{k}\", type: distance, points: [\"R{k}\", \"M{k}\"], length: 0.5}\n"
      "      - {name: \"ona{k}\", type: point_on_line, point: \"M{k}\", line: [\"L{k}\", \"R{k+1}\"]}\n"
      "      - {name: \"onb{k}\", type: point_on_line, point: \"M{k}\", line: [\"R{k}\", \"L{k+1}\"]}\n");
  t.segment_angle(Name{"angle"}, Name{"L", 0}, Name{"R", 1}, Name{"theta"});
  t.section("drivers");
  t.linear_driver(Name{"motor"}, Name{"theta"}, o.from, o.to - o.from);
  footer(t, o);
  return t.take();
}

// Reference-point coordinates: each bar a body with its reference point at its middle and its x axis from its lower
// to its upper end (ends at x = ∓1/2), and a slider body s on a prismatic pair along ground's x axis. Pairs: a_0's
// lower end to ground at the origin, b_0's lower end to the slider, a_k to b_k at the middles, and each upper end to
// the next stage's lower end. n = 6N + 3, m = 6N + 2 + 1 driver (psia0).
std::string scissor_reference_point(const GenerateOptions& o) {
  const std::int64_t n = o.n;
  const double c = std::cos(o.from), s = std::sin(o.from);
  SceneText t(4096);
  header(t, o, kScissorWhat, scissor_drive(o, "psia0"), 6 * n + 3, 6 * n + 2, 1,
         "bodies a<k> = (xa<k>, ya<k>, psia<k>) and b<k> = (xb<k>, yb<k>, psib<k>) are the bars of stage k "
         "(a rises to the right from the left joint, b to the left from the right joint; reference point at the "
         "middle = the crossing pin), s = (xs, ys, psis) the slider");
  t.raw("parameters:\n  N: " + str(n) + "\n  s: " + shortest(s) + "    # sin(from)\n  hc: " + shortest(0.5 * c) +
        "    # cos(from)/2\n  from: " + shortest(o.from) + "\n  pmf: " + shortest(std::numbers::pi - o.from) +
        "    # pi - from\n");
  t.section("coordinates");
  t.coordinate(Name{"xs"}, c);
  t.coordinate(Name{"ys"}, 0.0);
  t.coordinate(Name{"psis"}, 0.0);
  t.raw(
      "  for k in 0..N-1:\n"
      "    xa{k}: hc\n    ya{k}: (k + 0.5)*s\n    psia{k}: from\n"
      "    xb{k}: hc\n    yb{k}: (k + 0.5)*s\n    psib{k}: pmf\n");
  t.section("bodies");
  t.body(Name{"s"}, Name{"xs"}, Name{"ys"}, Name{"psis"});
  t.raw(
      "  for k in 0..N-1:\n"
      "    a{k}: [\"xa{k}\", \"ya{k}\", \"psia{k}\"]\n"
      "    b{k}: [\"xb{k}\", \"yb{k}\", \"psib{k}\"]\n");
  t.section("constraints");
  const Name ground{"ground"};
  t.revolute(Name{"pivot"}, Attach{Name{"a", 0}, -0.5, 0.0}, Attach{ground, 0.0, 0.0});
  t.prismatic(Name{"guide"}, Attach{ground, 0.0, 0.0}, Attach{Name{"s"}, 0.0, 0.0});
  t.revolute(Name{"slide"}, Attach{Name{"b", 0}, -0.5, 0.0}, Attach{Name{"s"}, 0.0, 0.0});
  t.raw(
      "  - for k in 0..N-2:\n"
      "      - {name: \"cross{k}\", type: revolute, between: [{body: \"a{k}\", at: [0, 0]}, {body: \"b{k}\", "
      "at: [0, 0]}]}\n"
      "      - {name: \"right{k+1}\", type: revolute, between: [{body: \"a{k}\", at: [0.5, 0]}, {body: "
      "\"b{k+1}\", at: [-0.5, 0]}]}\n"
      "      - {name: \"left{k+1}\", type: revolute, between: [{body: \"b{k}\", at: [0.5, 0]}, {body: "
      "\"a{k+1}\", at: [-0.5, 0]}]}\n");
  t.revolute(Name{"cross", n - 1}, Attach{Name{"a", n - 1}, 0.0, 0.0}, Attach{Name{"b", n - 1}, 0.0, 0.0});
  t.section("drivers");
  t.linear_driver(Name{"motor"}, Name{"psia", 0}, o.from, o.to - o.from);
  footer(t, o);
  return t.take();
}

// ---------------------------------------------------------------------------------------------------------------
// Grid: exactly N parallelogram cells of unit bars in R rows of C = ⌈√N⌉ cells (the top row holds the remaining
// N − (R − 1) C ≥ 1). Node (i, j) is column i of node row j; node row 0 is pinned to ground at (i, 0). Cell row j
// has w_j + 1 "vertical" bars from node (i, j) to (i, j + 1) and the w_j horizontal bars of node row j + 1. Each
// cell row is a chain of parallelograms with one shear dof: its vertical bars all turn by θ_j, driven linearly from
// --from to --to in even rows and from --to to --from in odd rows. Closed form: node (i, j) =
// (i + Σ_{k<j} cos θ_k, Σ_{k<j} sin θ_k), horizontal bars stay horizontal.

struct GridShape {
  std::int64_t cols = 1, rows = 1, last = 1;                                       // C, R, cells of the top row
  std::int64_t width(std::int64_t j) const { return j + 1 < rows ? cols : last; }  // w_j: cells of row j
};

GridShape grid_shape(std::int64_t n) {
  GridShape g;
  g.cols = static_cast<std::int64_t>(std::sqrt(static_cast<double>(n)));
  while (g.cols * g.cols < n) ++g.cols;
  while (g.cols > 1 && (g.cols - 1) * (g.cols - 1) >= n) --g.cols;
  g.rows = (n + g.cols - 1) / g.cols;
  g.last = n - (g.rows - 1) * g.cols;
  return g;
}

// θ_j at t = 0 and its rate.
double row_initial(const GenerateOptions& o, std::int64_t j) { return j % 2 == 0 ? o.from : o.to; }
double row_rate(const GenerateOptions& o, std::int64_t j) { return j % 2 == 0 ? o.to - o.from : o.from - o.to; }

const char* const kGridWhat = "lattice of N parallelogram cells of unit bars, one shear dof per cell row";

std::string grid_drive(const GenerateOptions& o, const std::string& coordinate) {
  return coordinate + " = the angle of row j's vertical bars to the horizontal (rad), linear from " + shortest(o.from) +
         " to " + shortest(o.to) + " in even rows j and from " + shortest(o.to) + " to " + shortest(o.from) +
         " in odd rows";
}

std::string grid_shape_text(const GridShape& g) {
  auto count = [](std::int64_t n, const char* one, const char* many) { return str(n) + " " + (n == 1 ? one : many); };
  return count(g.rows, "row", "rows") + " of " + count(g.cols, "cell", "cells") +
         (g.last == g.cols ? std::string() : " (the top row " + str(g.last) + ")");
}

// Families of the grid. Even rows j = 2k start at `from`, odd rows 2k + 1 at `to`, so the coordinates are written
// by pairs of rows (`for k in ...`, rows 2k and 2k + 1), the last (shorter) row in a family of one member k. The sum
// over rows below of the row angles' cosines (sines) is written in closed form, e·ca + o·cb with e even and o odd
// rows (sums()), the double the loader computes from the same expression.

// The text of a number of ne even and no odd rows, for the expression (ne)*a + (no)*b: "(k+1)*ca + k*cb".
std::string sums(const std::string& ne, const std::string& no, const char* a, const char* b) {
  return "(" + ne + ")*" + a + " + (" + no + ")*" + b;
}

// Rows 0 … R−2 are full (C cells), row R−1 holds `last`. Pairs of rows k = 0 … P−1 are full; the tail is the
// family k = P … P: row 2P alone (the last row, R odd), or rows 2P (full) and 2P + 1 (the last row, R even).
struct RowPairs {
  std::int64_t pairs;  // P
  bool odd_tail;       // R even: the tail has an odd row too
};
RowPairs row_pairs(const GridShape& g) { return {(g.rows - 1) / 2, g.rows % 2 == 0}; }

std::string range(std::int64_t a, std::int64_t b) { return str(a) + ".." + str(b); }

// Parameters of both grid styles: the shape and the row angles at t = 0.
void grid_parameters(SceneText& t, const GenerateOptions& o, const GridShape& g) {
  t.raw("parameters:\n  N: " + str(o.n) + "\n  C: " + str(g.cols) + "    # cells per row\n  L: " + str(g.last) +
        "    # cells of the last row\n  R: " + str(g.rows) + "    # rows\n  from: " + shortest(o.from) + "\n  to: " +
        shortest(o.to) + "\n  ca: " + shortest(std::cos(o.from)) + "\n  sa: " + shortest(std::sin(o.from)) +
        "\n  cb: " + shortest(std::cos(o.to)) + "\n  sb: " + shortest(std::sin(o.to)) +
        "\n  hca: " + shortest(0.5 * std::cos(o.from)) + "\n  hsa: " + shortest(0.5 * std::sin(o.from)) +
        "\n  hcb: " + shortest(0.5 * std::cos(o.to)) + "\n  hsb: " + shortest(0.5 * std::sin(o.to)) + "\n");
}

// The drivers: motor<j> drives row j's angle from `from` (even j) or `to` (odd j) at the rate of row_rate.
void grid_drivers(SceneText& t, const GenerateOptions& o, const GridShape& g, const std::string& coordinate) {
  const RowPairs p = row_pairs(g);
  auto law = [&](const std::string& jt, std::int64_t parity) {
    return "      - {name: \"motor" + jt + "\", coordinate: \"" + coordinate + jt +
           "\", law: {type: linear, "
           "initial: " +
           shortest(row_initial(o, parity)) + ", rate: " + shortest(row_rate(o, parity)) + "}}\n";
  };
  t.section("drivers");
  t.raw("  - for k in " + range(0, p.pairs - 1) + ":\n" + law("{2*k}", 0) + law("{2*k+1}", 1));
  t.raw("  - for k in " + range(p.pairs, p.pairs) + ":\n" + law("{2*k}", 0) + (p.odd_tail ? law("{2*k+1}", 1) : ""));
}

// Natural coordinates: the nodes above ground and the row angles. n = 2N + 3R, m = 2N + 2R + R drivers.
std::string grid_natural(const GenerateOptions& o) {
  const GridShape g = grid_shape(o.n);
  const std::int64_t n = o.n, r = g.rows;
  const RowPairs p = row_pairs(g);
  SceneText t(8192);
  header(t, o, std::string(kGridWhat) + ": " + grid_shape_text(g), grid_drive(o, "theta<j>"), 2 * n + 3 * r,
         2 * n + 2 * r, r,
         "point P<i>_<j> = (x<i>_<j>, y<i>_<j>) is node (i, j) for j >= 1 (node (i, 0) is ground at [i, 0]); "
         "constraints v<i>_<j> (bar from node (i, j) up to (i, j+1)), h<i>_<j> (bar from node (i, j) to (i+1, j)), "
         "row<j> (angle of v0_<j> = theta<j>)");
  grid_parameters(t, o, g);
  t.section("coordinates");
  // Row j = 2k (+1 if odd) of width w: theta<j>, then node row j + 1 at Σ_{rows ≤ j} (cos, sin) θ.
  auto row = [](bool odd, const std::string& w, const char* idx) {
    const std::string j = odd ? "{2*k+1}" : "{2*k}", j1 = odd ? "{2*k+2}" : "{2*k+1}";
    const std::string ne = "k+1", no = odd ? "k+1" : "k", i = idx;
    return "    theta" + j + ": " + (odd ? "to" : "from") + "\n    for " + i + " in 0.." + w + ":\n      x{" + i +
           "}_" + j1 + ": " + i + " + (" + sums(ne, no, "ca", "cb") + ")\n      y{" + i + "}_" + j1 + ": " +
           sums(ne, no, "sa", "sb") + "\n";
  };
  t.raw("  for k in " + range(0, p.pairs - 1) + ":    # rows 2k and 2k+1\n" + row(false, "C", "i") +
        row(true, "C", "m"));
  t.raw("  for k in " + range(p.pairs, p.pairs) + ":    # the last row" + (p.odd_tail ? "s" : "") + "\n" +
        (p.odd_tail ? row(false, "C", "i") + row(true, "L", "m") : row(false, "L", "i")));
  t.section("points");
  t.raw("  for j in " + range(0, r - 2) +
        ":\n    for i in 0..C:\n      P{i}_{j+1}: [\"x{i}_{j+1}\", \"y{i}_{j+1}\"]\n");
  t.raw("  for i in 0..L:\n    P{i}_" + str(r) + ": [\"x{i}_" + str(r) + "\", \"y{i}_" + str(r) + "\"]\n");
  t.section("constraints");
  // Row j (text jt, j + 1 text j1t) of width w; node row j is ground for j = 0.
  auto crow = [](const std::string& ind, const std::string& jt, const std::string& j1t, const std::string& w,
                 bool ground) {
    const std::string a0 = ground ? "[0, 0]" : "\"P0_" + jt + "\"", ai = ground ? "[i, 0]" : "\"P{i}_" + jt + "\"";
    return ind + "- {name: \"row" + jt + "\", type: segment_angle, segment: [" + a0 + ", \"P0_" + j1t +
           "\"], angle: \"theta" + jt + "\"}\n" + ind + "- for i in 0.." + w + ":\n" + ind + "    - {name: \"v{i}_" +
           jt + "\", type: distance, points: [" + ai + ", \"P{i}_" + j1t + "\"], length: 1}\n" + ind +
           "- for i in 0.." + w + "-1:\n" + ind + "    - {name: \"h{i}_" + j1t +
           "\", type: distance, points: [\"P{i}_" + j1t + "\", \"P{i+1}_" + j1t + "\"], length: 1}\n";
  };
  t.raw(crow("  ", "0", "1", r > 1 ? "C" : "L", true));
  t.raw("  - for j in " + range(1, r - 2) + ":\n" + crow("      ", "{j}", "{j+1}", "C", false));
  if (r > 1) t.raw("  - for j in " + range(r - 1, r - 1) + ":\n" + crow("      ", "{j}", "{j+1}", "L", false));
  grid_drivers(t, o, g, "theta");
  footer(t, o);
  return t.take();
}

// The pairs at node (i, j + 1) on top of the vertical bar of a row of width w below a node row whose vertical bars
// go up from i <= wn (wn < 0: none): u (up, i <= wn), l (left, i > 0), r (right, i < w), in this order.
std::string pairs_at(std::int64_t i, std::int64_t w, std::int64_t wn) {
  return std::string(i <= wn ? "u" : "") + (i > 0 ? "l" : "") + (i < w ? "r" : "");
}
// The last node of the run from a whose nodes have the same pairs: one family of the pairs.
std::int64_t pair_run_end(std::int64_t a, std::int64_t w, std::int64_t wn) {
  std::int64_t b = a;
  while (b < w && pairs_at(b + 1, w, wn) == pairs_at(a, w, wn)) ++b;
  return b;
}

// Reference-point coordinates: every bar a body with its reference point at its middle and its x axis from its first
// node to its second (ends at x = ∓1/2): vertical bars v<i>_<j> (node (i, j) to (i, j+1), angle θ_j), horizontal
// bars h<i>_<j> (node (i, j) to (i+1, j), angle 0). Each node above ground pins the top of the vertical bar below it
// to every other bar end there; each ground node pins its vertical bar to ground. n = 6N + 3R, m = 6N + 2R + R
// drivers (psiv0_<j>).
std::string grid_reference_point(const GenerateOptions& o) {
  const GridShape g = grid_shape(o.n);
  const std::int64_t n = o.n, r = g.rows;
  const RowPairs p = row_pairs(g);
  SceneText t(16384);
  header(t, o, std::string(kGridWhat) + ": " + grid_shape_text(g), grid_drive(o, "psiv0_<j>"), 6 * n + 3 * r,
         6 * n + 2 * r, r,
         "bodies v<i>_<j> = (xv<i>_<j>, yv<i>_<j>, psiv<i>_<j>): bar from node (i, j) up to (i, j+1); "
         "h<i>_<j> = (xh<i>_<j>, yh<i>_<j>, psih<i>_<j>): bar from node (i, j) to (i+1, j); reference points at "
         "the middles; pairs pin<i> (to ground), up<i>_<j>, left<i>_<j>, right<i>_<j> (at node (i, j))");
  grid_parameters(t, o, g);
  t.section("coordinates");
  // Row j = 2k (+1 if odd) of width w: its vertical bars from node row j (at the sums over rows < j), then the
  // horizontal bars of node row j + 1 (sums over rows ≤ j).
  auto row = [](bool odd, const std::string& w, const char* idx) {
    const std::string j = odd ? "{2*k+1}" : "{2*k}", j1 = odd ? "{2*k+2}" : "{2*k+1}", i = idx;
    const std::string bx = sums(odd ? "k+1" : "k", "k", "ca", "cb"), by = sums(odd ? "k+1" : "k", "k", "sa", "sb");
    const std::string ax = sums("k+1", odd ? "k+1" : "k", "ca", "cb"), ay = sums("k+1", odd ? "k+1" : "k", "sa", "sb");
    const std::string hc = odd ? "hcb" : "hca", hs = odd ? "hsb" : "hsa", th = odd ? "to" : "from";
    return "    for " + i + " in 0.." + w + ":\n      xv{" + i + "}_" + j + ": " + i + " + (" + bx + ") + " + hc +
           "\n      yv{" + i + "}_" + j + ": (" + by + ") + " + hs + "\n      psiv{" + i + "}_" + j + ": " + th +
           "\n    for " + i + " in 0.." + w + "-1:\n      xh{" + i + "}_" + j1 + ": " + i + " + (" + ax +
           ") + 0.5\n      yh{" + i + "}_" + j1 + ": " + ay + "\n      psih{" + i + "}_" + j1 + ": 0\n";
  };
  t.raw("  for k in " + range(0, p.pairs - 1) + ":    # rows 2k and 2k+1\n" + row(false, "C", "i") +
        row(true, "C", "m"));
  t.raw("  for k in " + range(p.pairs, p.pairs) + ":    # the last row" + (p.odd_tail ? "s" : "") + "\n" +
        (p.odd_tail ? row(false, "C", "i") + row(true, "L", "m") : row(false, "L", "i")));
  t.section("bodies");
  auto brow = [](const std::string& ind, const std::string& jt, const std::string& j1t, const std::string& w) {
    return ind + "for i in 0.." + w + ":\n" + ind + "  v{i}_" + jt + ": [\"xv{i}_" + jt + "\", \"yv{i}_" + jt +
           "\", \"psiv{i}_" + jt + "\"]\n" + ind + "for i in 0.." + w + "-1:\n" + ind + "  h{i}_" + j1t +
           ": [\"xh{i}_" + j1t + "\", \"yh{i}_" + j1t + "\", \"psih{i}_" + j1t + "\"]\n";
  };
  t.raw("  for j in " + range(0, r - 2) + ":\n" + brow("    ", "{j}", "{j+1}", "C"));
  t.raw("  for j in " + range(r - 1, r - 1) + ":\n" + brow("    ", "{j}", "{j+1}", "L"));
  t.section("constraints");
  t.raw(std::string("  - for i in 0..") + (r > 1 ? "C" : "L") +
        ":\n      - {name: \"pin{i}\", type: revolute, between: [{body: \"v{i}_0\", at: [-0.5, 0]}, {body: ground, "
        "at: [i, 0]}]}\n");
  // The pairs at node row j + 1, on top of the vertical bars of row j (width w): up (to the vertical bar above, if
  // node (i, j + 1) has one: i ≤ wn), left (i > 0), right (i < w), in this order for each i. Written as families
  // over the runs of i with the same pairs.
  auto crow = [](const std::string& ind, const std::string& jt, const std::string& j1t, std::int64_t w,
                 std::int64_t wn) {
    const std::string top = "{body: \"v{i}_" + jt + "\", at: [0.5, 0]}";
    std::string s;
    for (std::int64_t a = 0; a <= w;) {
      const std::int64_t b = pair_run_end(a, w, wn);
      s += ind + "- for i in " + range(a, b) + ":\n";
      for (char c : pairs_at(a, w, wn)) {
        if (c == 'u')
          s += ind + "    - {name: \"up{i}_" + j1t + "\", type: revolute, between: [" + top + ", {body: \"v{i}_" + j1t +
               "\", at: [-0.5, 0]}]}\n";
        if (c == 'l')
          s += ind + "    - {name: \"left{i}_" + j1t + "\", type: revolute, between: [" + top + ", {body: \"h{i-1}_" +
               j1t + "\", at: [0.5, 0]}]}\n";
        if (c == 'r')
          s += ind + "    - {name: \"right{i}_" + j1t + "\", type: revolute, between: [" + top + ", {body: \"h{i}_" +
               j1t + "\", at: [-0.5, 0]}]}\n";
      }
      a = b + 1;
    }
    return s;
  };
  t.raw("  - for j in " + range(0, r - 3) + ":\n" + crow("      ", "{j}", "{j+1}", g.cols, g.cols));
  // Rows R−2 and R−1 in families of one member each, so that their number is written once.
  if (r > 1) t.raw("  - for j in " + range(r - 2, r - 2) + ":\n" + crow("      ", "{j}", "{j+1}", g.cols, g.last));
  t.raw("  - for j in " + range(r - 1, r - 1) + ":\n" + crow("      ", "{j}", "{j+1}", g.last, -1));
  grid_drivers(t, o, g, "psiv0_");
  footer(t, o);
  return t.take();
}

}  // namespace

std::string scissor_scene(const GenerateOptions& o) {
  check(o, std::numbers::pi / 2,
        "the scissor's bar angle must lie strictly between 0 (flat) and pi/2 (vertical), "
        "where the linkage is singular");
  return o.coords == "natural" ? scissor_natural(o) : scissor_reference_point(o);
}

std::string grid_scene(const GenerateOptions& o) {
  check(o, std::numbers::pi,
        "the grid's row angles must lie strictly between 0 and pi, where the cells are flat (singular)");
  return o.coords == "natural" ? grid_natural(o) : grid_reference_point(o);
}

// The entries of the families written above, counted as the loader counts them: a family of M members whose body
// has E entries makes M·E (none when empty), a nested family being one entry of its parent's body per member plus
// what it makes. Each term follows the text written by scissor_natural() ... grid_reference_point(), in order;
// tests/test_generate.cpp checks the count against the loader's limit at many N.
namespace {
std::uint64_t fam(std::int64_t members, std::int64_t entries) {
  return members > 0 ? static_cast<std::uint64_t>(members) * static_cast<std::uint64_t>(entries) : 0;
}
// The constraints at node row j + 1 of reference-point grid (crow in grid_reference_point()): one family per run
// of nodes with the same pairs, each making (nodes) x (pairs) entries.
std::uint64_t grid_pair_entries(std::int64_t w, std::int64_t wn) {
  std::uint64_t e = 0;
  for (std::int64_t a = 0; a <= w;) {
    const std::int64_t b = pair_run_end(a, w, wn);
    e += 1 + fam(b - a + 1, static_cast<std::int64_t>(pairs_at(a, w, wn).size()));
    a = b + 1;
  }
  return e;
}
}  // namespace

std::uint64_t scissor_family_entries(const GenerateOptions& o) {
  const std::int64_t n = o.n;
  if (o.coords == "natural") return fam(n, 6) + fam(n, 3) + fam(n, 6);  // coordinates, points, constraints
  return fam(n, 6) + fam(n, 2) + fam(n - 1, 3);  // coordinates, bodies, the pairs of stages 0 ... N-2
}

std::uint64_t grid_family_entries(const GenerateOptions& o) {
  const GridShape g = grid_shape(o.n);
  const std::int64_t c = g.cols, r = g.rows, l = g.last, w0 = r > 1 ? c : l;
  const RowPairs p = row_pairs(g);
  const std::uint64_t drivers = fam(p.pairs, 2) + (p.odd_tail ? 2 : 1);
  if (o.coords == "natural") {
    // coordinates: per pair of rows 4 entries (theta, the nodes' family, twice), each node 2; then the tail
    const std::uint64_t coordinates = fam(p.pairs, 4) + 2 * fam(p.pairs, 2 * (c + 1)) +
                                      (p.odd_tail ? 4 + 2 * (c + 1) + 2 * (l + 1) : 2 + 2 * (l + 1));
    const std::uint64_t points = fam(r - 1, 1) + fam(r - 1, c + 1) + fam(l + 1, 1);
    // row 0 (its vertical and horizontal bars' families), rows 1 ... R-2 (3 items each), row R-1
    const std::uint64_t constraints = fam(w0 + 1, 1) + fam(w0, 1) + fam(r - 2, 3) + fam(r - 2, 2 * c + 1) +
                                      (r > 1 ? 3 + fam(l + 1, 1) + fam(l, 1) : 0);
    return coordinates + points + constraints + drivers;
  }
  // coordinates: per row 2 entries (the vertical and the horizontal bars' families), 3 per bar
  const std::uint64_t coordinates =
      fam(p.pairs, 4) + 2 * fam(p.pairs, 3 * (c + 1) + 3 * c) +
      (p.odd_tail ? 4 + 3 * (c + 1) + 3 * c + 3 * (l + 1) + 3 * l : 2 + 3 * (l + 1) + 3 * l);
  const std::uint64_t bodies = fam(r - 1, 2) + fam(r - 1, 2 * c + 1) + 2 + fam(l + 1, 1) + fam(l, 1);
  const std::uint64_t constraints = fam(w0 + 1, 1) + (r > 2 ? (r - 2) * grid_pair_entries(c, c) : 0) +
                                    (r > 1 ? grid_pair_entries(c, l) : 0) + grid_pair_entries(l, -1);
  return coordinates + bodies + constraints + drivers;
}

std::optional<DrivenRange> kind_default_range(const std::string& kind) {
  if (kind == "scissor") return DrivenRange{0.3, 1.2};
  return std::nullopt;
}

}  // namespace phiq::tools
