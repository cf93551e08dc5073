// `phiq generate scissor` and `phiq generate grid`: the scenes load, are square with the stated counts, and their
// sweeps follow the closed forms of tools/README.md (positions, velocities, accelerations) in both coordinate
// styles, which agree with each other; they are written with indexed families (size independent of N) and are
// the model of the explicit listing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "generate.hpp"
#include "test_support.hpp"

#include "explicit_linkages.inc"

namespace phiq {
namespace {

using tools::GenerateOptions;

using test::generate_options;

// A closed form: c + Σ (A cos θ_k + B sin θ_k + D θ_k) over driven angles θ_k(t) = θ_k(0) + r_k t.
struct Term {
  std::size_t angle;
  double cos_coef, sin_coef, lin_coef;
};
struct ClosedForm {
  double c = 0.0;
  std::vector<Term> terms;
};
struct Angles {
  std::vector<double> initial, rate;
};

struct Value {
  double q, v, a;
};
Value evaluate(const ClosedForm& f, const Angles& ang, double t) {
  Value r{f.c, 0.0, 0.0};
  for (const Term& k : f.terms) {
    const double w = ang.rate[k.angle], th = ang.initial[k.angle] + w * t, c = std::cos(th), s = std::sin(th);
    r.q += k.cos_coef * c + k.sin_coef * s + k.lin_coef * th;
    r.v += (-k.cos_coef * s + k.sin_coef * c + k.lin_coef) * w;
    r.a += (-k.cos_coef * c - k.sin_coef * s) * w * w;
  }
  return r;
}

// What a generated scene should be: its counts and the closed form of every coordinate.
struct Expected {
  Index coordinates = 0, kinematic = 0, drivers = 0;
  Angles angles;
  std::map<std::string, ClosedForm> q;
};

std::string nm(const std::string& f, std::int64_t i) { return f + std::to_string(i); }
std::string nm(const std::string& f, std::int64_t i, std::int64_t j) {
  return f + std::to_string(i) + "_" + std::to_string(j);
}

// Scissor: bars at θ; L_k = (0, k s), R_k = (c, k s), M_k = (c/2, (k + 1/2) s).
Expected scissor_expected(const GenerateOptions& o) {
  Expected e;
  const std::int64_t n = o.n;
  e.angles = {{o.from}, {o.to - o.from}};
  auto cs = [](double a, double b, double c = 0.0, double d = 0.0) { return ClosedForm{c, {{0, a, b, d}}}; };
  e.drivers = 1;
  if (o.coords == "natural") {
    e.coordinates = 6 * n + 2;
    e.kinematic = 6 * n + 1;
    e.q["theta"] = cs(0, 0, 0, 1);
    e.q["xr0"] = cs(1, 0);
    for (std::int64_t k = 0; k < n; ++k) {
      e.q[nm("xm", k)] = cs(0.5, 0);
      e.q[nm("ym", k)] = cs(0, k + 0.5);
      e.q[nm("xl", k + 1)] = cs(0, 0);
      e.q[nm("yl", k + 1)] = cs(0, k + 1.0);
      e.q[nm("xr", k + 1)] = cs(1, 0);
      e.q[nm("yr", k + 1)] = cs(0, k + 1.0);
    }
  } else {
    e.coordinates = 6 * n + 3;
    e.kinematic = 6 * n + 2;
    e.q["xs"] = cs(1, 0);
    e.q["ys"] = cs(0, 0);
    e.q["psis"] = cs(0, 0);
    for (std::int64_t k = 0; k < n; ++k) {
      for (const char* bar : {"a", "b"}) {
        e.q[nm(std::string("x") + bar, k)] = cs(0.5, 0);
        e.q[nm(std::string("y") + bar, k)] = cs(0, k + 0.5);
      }
      e.q[nm("psia", k)] = cs(0, 0, 0, 1);
      e.q[nm("psib", k)] = cs(0, 0, M_PI, -1);
    }
  }
  return e;
}

// Grid: N cells in rows of C = ceil(sqrt N), the top row holding the rest; row j's angle runs from → to in even
// rows, to → from in odd rows; node (i, j) = (i + Σ_{k<j} cos θ_k, Σ_{k<j} sin θ_k).
struct Shape {
  std::int64_t cols, rows, last;
  std::int64_t width(std::int64_t j) const { return j + 1 < rows ? cols : last; }
};
Shape shape_of(std::int64_t n) {
  std::int64_t c = 1;
  while (c * c < n) ++c;
  const std::int64_t r = (n + c - 1) / c;
  return {c, r, n - (r - 1) * c};
}

Expected grid_expected(const GenerateOptions& o) {
  Expected e;
  const Shape g = shape_of(o.n);
  const std::int64_t n = o.n, r = g.rows;
  for (std::int64_t j = 0; j < r; ++j) {
    e.angles.initial.push_back(j % 2 ? o.to : o.from);
    e.angles.rate.push_back(j % 2 ? o.from - o.to : o.to - o.from);
  }
  auto node_x = [&](std::int64_t i, std::int64_t j, double extra) {  // i + extra + Σ_{k<j} cos θ_k
    ClosedForm f{static_cast<double>(i) + extra, {}};
    for (std::int64_t k = 0; k < j; ++k) f.terms.push_back({static_cast<std::size_t>(k), 1, 0, 0});
    return f;
  };
  auto node_y = [&](std::int64_t j) {
    ClosedForm f;
    for (std::int64_t k = 0; k < j; ++k) f.terms.push_back({static_cast<std::size_t>(k), 0, 1, 0});
    return f;
  };
  e.drivers = r;
  if (o.coords == "natural") {
    e.coordinates = 2 * n + 3 * r;
    e.kinematic = 2 * n + 2 * r;
    for (std::int64_t j = 0; j < r; ++j) {
      e.q[nm("theta", j)] = ClosedForm{0, {{static_cast<std::size_t>(j), 0, 0, 1}}};
      for (std::int64_t i = 0; i <= g.width(j); ++i) {
        e.q[nm("x", i, j + 1)] = node_x(i, j + 1, 0);
        e.q[nm("y", i, j + 1)] = node_y(j + 1);
      }
    }
  } else {
    e.coordinates = 6 * n + 3 * r;
    e.kinematic = 6 * n + 2 * r;
    for (std::int64_t j = 0; j < r; ++j) {
      const auto a = static_cast<std::size_t>(j);
      for (std::int64_t i = 0; i <= g.width(j); ++i) {
        ClosedForm x = node_x(i, j, 0), y = node_y(j);
        x.terms.push_back({a, 0.5, 0, 0});
        y.terms.push_back({a, 0, 0.5, 0});
        e.q[nm("xv", i, j)] = x;
        e.q[nm("yv", i, j)] = y;
        e.q[nm("psiv", i, j)] = ClosedForm{0, {{a, 0, 0, 1}}};
      }
      for (std::int64_t i = 0; i < g.width(j); ++i) {
        e.q[nm("xh", i, j + 1)] = node_x(i, j + 1, 0.5);
        e.q[nm("yh", i, j + 1)] = node_y(j + 1);
        e.q[nm("psih", i, j + 1)] = ClosedForm{};
      }
    }
  }
  return e;
}

Expected expected_for(const GenerateOptions& o) { return o.kind == "scissor" ? scissor_expected(o) : grid_expected(o); }

struct SweptScene {
  Scene scene;
  test::Trace trace;
  std::map<std::string, Index> column;
  double at(const std::vector<Eigen::VectorXd>& rows, std::size_t k, const std::string& name) const {
    return rows[k](column.at(name));
  }
};

// Generates, loads, checks the counts, sweeps and compares every coordinate with the closed form at every step.
SweptScene check_against_closed_form(const GenerateOptions& o) {
  SCOPED_TRACE(o.kind + " " + std::to_string(o.n) + " " + o.coords);
  SweptScene run{parse_scene(tools::generate_scene(o), o.kind + ".yaml"), {}, {}};
  const Model& m = *run.scene.model;
  const Expected e = expected_for(o);
  EXPECT_EQ(m.num_coordinates(), e.coordinates);
  EXPECT_EQ(m.num_equations(), e.coordinates);  // square
  Index kinematic = 0, drivers = 0;
  for (const ConstraintInfo& c : m.constraints()) (c.depends_on_time ? drivers : kinematic) += c.rows;
  EXPECT_EQ(kinematic, e.kinematic);
  EXPECT_EQ(drivers, e.drivers);
  EXPECT_EQ(run.scene.sweep.steps, o.steps);
  EXPECT_TRUE(run.scene.sweep.velocities);
  EXPECT_TRUE(run.scene.sweep.accelerations);
  EXPECT_EQ(e.q.size(), static_cast<std::size_t>(e.coordinates));  // the closed form covers every coordinate
  for (Index j = 0; j < m.num_coordinates(); ++j) run.column[m.coordinate_names()[static_cast<std::size_t>(j)]] = j;

  SweepSummary summary;
  EXPECT_EQ(test::sweep(m, run.scene.sweep, &run.trace, &summary), SolveStatus::kSuccess) << summary.message;
  EXPECT_TRUE(summary.warnings.empty());
  EXPECT_EQ(run.trace.t.size(), static_cast<std::size_t>(o.steps + 1));
  EXPECT_EQ(run.trace.qd.size(), run.trace.t.size());
  EXPECT_EQ(run.trace.qdd.size(), run.trace.t.size());
  double worst[3] = {0, 0, 0};
  std::string where[3];
  for (std::size_t k = 0; k < run.trace.t.size() && k < run.trace.qdd.size(); ++k) {
    for (const auto& [name, form] : e.q) {
      const Index j = m.coordinate_index(name);
      const Value want = evaluate(form, e.angles, run.trace.t[k]);
      const double got[3] = {run.trace.q[k](j), run.trace.qd[k](j), run.trace.qdd[k](j)};
      const double ref[3] = {want.q, want.v, want.a};
      for (int d = 0; d < 3; ++d) {
        const double err = std::fabs(got[d] - ref[d]);
        if (err > worst[d]) worst[d] = err, where[d] = name + " at t = " + std::to_string(run.trace.t[k]);
      }
    }
  }
  EXPECT_LT(worst[0], 1e-9) << "position " << where[0];
  EXPECT_LT(worst[1], 1e-9) << "velocity " << where[1];
  EXPECT_LT(worst[2], 1e-9) << "acceleration " << where[2];
  return run;
}

constexpr std::int64_t kSizes[] = {1, 2, 5, 7};

TEST(GenerateScissor, BothCoordinateStylesFollowTheClosedFormAndAgree) {
  for (std::int64_t n : kSizes) {
    const SweptScene nat = check_against_closed_form(generate_options("scissor", n, "natural", 0.3, 1.2));
    const SweptScene ref = check_against_closed_form(generate_options("scissor", n, "reference-point", 0.3, 1.2));
    // shared quantities: the lift's height (top joint) and the crossing pins, with their velocities
    ASSERT_EQ(nat.trace.t.size(), ref.trace.t.size());
    double worst = 0.0;
    for (std::size_t k = 0; k < nat.trace.t.size() && k < nat.trace.qd.size() && k < ref.trace.qd.size(); ++k) {
      const std::string top = nm("psia", n - 1);
      const double psi = ref.at(ref.trace.q, k, top), psid = ref.at(ref.trace.qd, k, top);
      const double h_ref = ref.at(ref.trace.q, k, nm("ya", n - 1)) + 0.5 * std::sin(psi);
      const double hd_ref = ref.at(ref.trace.qd, k, nm("ya", n - 1)) + 0.5 * std::cos(psi) * psid;
      worst = std::max(worst, std::fabs(nat.at(nat.trace.q, k, nm("yl", n)) - h_ref));
      worst = std::max(worst, std::fabs(nat.at(nat.trace.q, k, nm("yr", n)) - h_ref));
      worst = std::max(worst, std::fabs(nat.at(nat.trace.qd, k, nm("yl", n)) - hd_ref));
      for (std::int64_t s = 0; s < n; ++s)
        for (const char* c : {"x", "y"}) {
          for (const char* bar : {"a", "b"}) {
            const std::string r = nm(std::string(c) + bar, s), p = nm(std::string(c) + "m", s);
            worst = std::max(worst, std::fabs(nat.at(nat.trace.q, k, p) - ref.at(ref.trace.q, k, r)));
            worst = std::max(worst, std::fabs(nat.at(nat.trace.qd, k, p) - ref.at(ref.trace.qd, k, r)));
          }
        }
      // and the closed form of the height: N sin θ
      const double th = 0.3 + 0.9 * nat.trace.t[k];
      worst = std::max(worst, std::fabs(h_ref - static_cast<double>(n) * std::sin(th)));
    }
    EXPECT_LT(worst, 1e-9) << "N = " << n;
  }
}

TEST(GenerateGrid, BothCoordinateStylesFollowTheClosedFormAndAgree) {
  for (std::int64_t n : kSizes) {
    const SweptScene nat = check_against_closed_form(generate_options("grid", n, "natural", M_PI / 4, 3 * M_PI / 4));
    const SweptScene ref =
        check_against_closed_form(generate_options("grid", n, "reference-point", M_PI / 4, 3 * M_PI / 4));
    // shared quantities: every node above ground, natural (x, y) against the top of the vertical bar below it
    const Shape g = shape_of(n);
    ASSERT_EQ(nat.trace.t.size(), ref.trace.t.size());
    double worst = 0.0;
    for (std::size_t k = 0; k < nat.trace.t.size() && k < nat.trace.qd.size() && k < ref.trace.qd.size(); ++k)
      for (std::int64_t j = 0; j < g.rows; ++j)
        for (std::int64_t i = 0; i <= g.width(j); ++i) {
          const double psi = ref.at(ref.trace.q, k, nm("psiv", i, j)), psid = ref.at(ref.trace.qd, k, nm("psiv", i, j));
          const double x = ref.at(ref.trace.q, k, nm("xv", i, j)) + 0.5 * std::cos(psi);
          const double y = ref.at(ref.trace.q, k, nm("yv", i, j)) + 0.5 * std::sin(psi);
          const double yd = ref.at(ref.trace.qd, k, nm("yv", i, j)) + 0.5 * std::cos(psi) * psid;
          worst = std::max(worst, std::fabs(nat.at(nat.trace.q, k, nm("x", i, j + 1)) - x));
          worst = std::max(worst, std::fabs(nat.at(nat.trace.q, k, nm("y", i, j + 1)) - y));
          worst = std::max(worst, std::fabs(nat.at(nat.trace.qd, k, nm("y", i, j + 1)) - yd));
        }
    EXPECT_LT(worst, 1e-9) << "N = " << n;
  }
}

TEST(GenerateGrid, ShapeHasExactlyNCells) {
  // C = ceil(sqrt N) cells per row, R rows, the top row the rest (at least one)
  struct Case {
    std::int64_t n, cols, rows, last;
  };
  for (Case c : {Case{1, 1, 1, 1}, Case{2, 2, 1, 2}, Case{3, 2, 2, 1}, Case{5, 3, 2, 2}, Case{7, 3, 3, 1},
                 Case{9, 3, 3, 3}, Case{100000, 317, 316, 145}}) {
    const Shape s = shape_of(c.n);
    EXPECT_EQ(s.cols, c.cols) << c.n;
    EXPECT_EQ(s.rows, c.rows) << c.n;
    EXPECT_EQ(s.last, c.last) << c.n;
    const std::string text = tools::generate_scene(generate_options("grid", c.n, "natural", 1.0, 2.0, 1));
    const std::string shape = std::to_string(c.rows) + (c.rows == 1 ? " row of " : " rows of ") +
                              std::to_string(c.cols) + (c.cols == 1 ? " cell" : " cells");
    EXPECT_NE(text.find(shape), std::string::npos) << text.substr(0, 400);
  }
}

TEST(Generate, HeaderStatesTheCounts) {
  const std::string s = tools::generate_scene(generate_options("scissor", 5, "natural", 0.3, 1.2));
  EXPECT_NE(s.find("# Counts: 32 coordinates, 31 kinematic equations + 1 driver = 32 equations; 1 dof\n"),
            std::string::npos)
      << s.substr(0, 800);
  const std::string g = tools::generate_scene(generate_options("grid", 5, "reference-point", 0.5, 2.5));
  EXPECT_NE(g.find("# Counts: 36 coordinates, 34 kinematic equations + 2 drivers = 36 equations; 2 dof\n"),
            std::string::npos)
      << g.substr(0, 800);
}

// Every kind opens with the same comment lines (tools/README.md): what, Drive, Counts, Names; nfourbar wrote only
// the first. The counts are the loaded model's.
TEST(Generate, EveryKindStatesItsDriveCountsAndNames) {
  for (const char* kind : {"nfourbar", "scissor", "grid", "chain3d"})
    for (const char* coords : {"natural", "reference-point"})
      for (std::int64_t n : {1, 4}) {
        const GenerateOptions o = generate_options(kind, n, coords, 0.5, 1.0);
        const std::string text = tools::generate_scene(o);
        SCOPED_TRACE(std::string(kind) + " " + coords + " N = " + std::to_string(n) + "\n" + text.substr(0, 900));
        std::vector<std::string> lines;
        for (std::size_t at = 0; lines.size() < 4;) {
          const std::size_t end = text.find('\n', at);
          lines.push_back(text.substr(at, end - at));
          at = end + 1;
        }
        EXPECT_EQ(lines[0].rfind("# Generated by phiq generate " + std::string(kind) + " " + std::to_string(n) +
                                     " --coords " + coords + ": ",
                                 0),
                  0u);
        EXPECT_EQ(lines[1].rfind("# Drive: ", 0), 0u);
        EXPECT_NE(lines[1].find(" linear from 0.5 "), std::string::npos);
        EXPECT_EQ(lines[3].rfind("# Names: ", 0), 0u);
        const Scene scene = parse_scene(text, "s.yaml");
        const Index nq = scene.model->num_coordinates(), m = scene.model->num_equations();
        Index drivers = 0;
        for (const auto& c : scene.model->constraints()) drivers += c.depends_on_time ? c.rows : 0;
        EXPECT_EQ(lines[2], "# Counts: " + std::to_string(nq) + " coordinates, " + std::to_string(m - drivers) +
                                " kinematic equations + " + std::to_string(drivers) +
                                (drivers == 1 ? " driver = " : " drivers = ") + std::to_string(m) + " equations; " +
                                std::to_string(nq - (m - drivers)) + " dof");
      }
}

TEST(Generate, OutputsAndStepsReachTheScene) {
  for (const char* kind : {"scissor", "grid", "chain3d"}) {
    GenerateOptions o = generate_options(kind, 3, "reference-point", 0.4, 1.0, 7);
    o.v = false;
    o.a = false;
    Scene s = parse_scene(tools::generate_scene(o), "s.yaml");
    EXPECT_EQ(s.sweep.steps, 7);
    EXPECT_FALSE(s.sweep.velocities) << kind;
    EXPECT_FALSE(s.sweep.accelerations) << kind;
    o.v = true;
    Scene s2 = parse_scene(tools::generate_scene(o), "s.yaml");
    EXPECT_TRUE(s2.sweep.velocities) << kind;
    EXPECT_FALSE(s2.sweep.accelerations) << kind;
  }
}

TEST(Generate, SceneSizeDoesNotGrowWithN) {
  // Written with indexed families: sizes differ only in a few digits (counts, ranges, parameters). The grid's text
  // has one shape per parity of its row count and whether the last row is short: N = 14 (4 rows of 4, the last 2)
  // has the shape of N = 10^5 (316 rows of 317, the last 145); any N stays under 8 KB.
  for (const char* kind : {"scissor", "grid"})
    for (const char* coords : {"natural", "reference-point"}) {
      auto size = [&](std::int64_t n) {
        return tools::generate_scene(generate_options(kind, n, coords, 0.5, 1.0, 10)).size();
      };
      const std::size_t small = size(std::string(kind) == "grid" ? 14 : 10), large = size(100000);
      EXPECT_LT(std::max(small, large) - std::min(small, large), 100u) << kind << " " << coords;
      const std::int64_t most = tools::max_n(generate_options(kind, 1, coords, 0.5, 1.0));
      for (std::int64_t n : {std::int64_t{1}, std::int64_t{2}, std::int64_t{3}, std::int64_t{7}, std::int64_t{10},
                             std::int64_t{1000000}, most})
        EXPECT_LT(size(n), 8192u) << kind << " " << coords;
    }
}

// The family form is the model the explicit listing (explicit_linkages.inc) describes: names, order, initial values,
// constraints and drivers bit for bit, with the grid's last row short or full and odd and even rows.
TEST(Generate, FamilyFormIsTheExplicitModel) {
  struct Case {
    const char* kind;
    std::int64_t n;
  };
  for (Case c : {Case{"scissor", 1}, Case{"scissor", 2}, Case{"scissor", 7}, Case{"grid", 1}, Case{"grid", 2},
                 Case{"grid", 3}, Case{"grid", 5}, Case{"grid", 7}, Case{"grid", 9}, Case{"grid", 10}, Case{"grid", 13},
                 Case{"grid", 20}, Case{"grid", 30}})
    for (const char* coords : {"natural", "reference-point"})
      for (auto [from, to] : {std::pair{0.3, 1.2}, std::pair{1.1, 0.4}}) {
        SCOPED_TRACE(std::string(c.kind) + " " + std::to_string(c.n) + " " + coords + " " + std::to_string(from));
        const GenerateOptions o = generate_options(c.kind, c.n, coords, from, to, 5);
        const std::string families = tools::generate_scene(o), listed = test::explicit_linkages::scene(o);
        EXPECT_NE(families.find("for k in"), std::string::npos);
        EXPECT_EQ(listed.find(" in 0.."), std::string::npos);
        Scene a = parse_scene(families, "families.yaml"), b = parse_scene(listed, "listed.yaml");
        test::expect_same_model(*a.model, *b.model);
        EXPECT_EQ(a.sweep.steps, b.sweep.steps);
      }
}

TEST(Generate, RefusesBadOptionsLikeNFourBar) {
  const auto message = test::generate_error;
  for (const char* kind : {"nfourbar", "scissor", "grid", "chain3d"}) {
    GenerateOptions o = generate_options(kind, 3, "natural", 0.5, 1.0);
    o.n = 0;
    EXPECT_EQ(message(o), "N must be at least 1") << kind;
    o = generate_options(kind, 3, "polar", 0.5, 1.0);
    EXPECT_EQ(message(o), "--coords is natural or reference-point") << kind;
    o = generate_options(kind, 3, "natural", 0.5, 1.0, -1);
    EXPECT_EQ(message(o), "--steps must be >= 0") << kind;
    o = generate_options(kind, 3, "natural", 0.5, NAN);
    EXPECT_EQ(message(o), "--from and --to must be finite") << kind;
    o = generate_options(kind, 3, "natural", 0.5, 1.0);
    o.q = false;
    EXPECT_EQ(message(o), "--outputs must include q (positions are always written)") << kind;
  }
  // finite options whose scene would not be: the driver's rate overflows, or chain3d's phases (the loader refused
  // '-inf' and 'inf' where generate wrote them)
  for (const char* kind : {"nfourbar", "scissor", "grid", "chain3d"})
    EXPECT_EQ(message(generate_options(kind, 3, "natural", 1.7e308, -1.7e308)),
              "--from and --to: the driven range to - from = -inf is not finite")
        << kind;
  GenerateOptions twisted = generate_options("chain3d", 3, "reference-point", 0.5, 1.0);
  twisted.twist = 1e308;
  EXPECT_EQ(message(twisted), "--twist: crank N's phase from + N*twist is not finite");
  twisted.twist = 1e307;  // 3e307: every phase finite, the scene loads
  EXPECT_NO_THROW(parse_scene(tools::generate_scene(twisted), "t.yaml"));
  EXPECT_EQ(message(generate_options("gears", 3, "natural", 0.5, 1.0)),
            "unknown kind 'gears' (available: nfourbar, scissor, grid, chain3d)");
  // driven ranges that reach a singular position
  for (double bad : {0.0, -0.1, M_PI / 2, 2.0}) {
    EXPECT_NE(message(generate_options("scissor", 3, "natural", bad, 1.0)).find("strictly between 0 (flat) and pi/2"),
              std::string::npos);
    EXPECT_NE(message(generate_options("scissor", 3, "reference-point", 0.5, bad)).find("--from and --to"),
              std::string::npos);
  }
  for (double bad : {0.0, M_PI, 4.0}) {
    EXPECT_NE(message(generate_options("grid", 3, "natural", bad, 1.0)).find("strictly between 0 and pi"),
              std::string::npos);
    EXPECT_NE(message(generate_options("grid", 3, "natural", 1.0, bad)).find("--from and --to"), std::string::npos);
  }
  EXPECT_EQ(message(generate_options("grid", 3, "natural", 2.0, 3.0)), "(no error)");  // beyond π/2: fine for the grid
}

// The loader refuses a scene whose families make more than SceneLimits::max_family_instances entries (counted
// before any is expanded; once only after expanding those before the one that exceeds it: nfourbar N = 10^7 took
// 160 s and 4.7 GB to be refused). family_entries() counts them as the loader does: a scene loads with exactly
// that limit and not with one less.
TEST(Generate, FamilyEntriesAreWhatTheLoaderCounts) {
  std::vector<std::int64_t> sizes;
  for (std::int64_t n = 1; n <= 30; ++n) sizes.push_back(n);  // grids of 1, 2 and 3+ rows, short and full last rows
  for (std::int64_t n : {35, 36, 37, 42, 49, 56, 99, 100, 101, 111, 1000}) sizes.push_back(n);
  for (const char* kind : {"nfourbar", "scissor", "grid", "chain3d"})
    for (const char* coords : {"natural", "reference-point"})
      for (std::int64_t n : sizes) {
        const GenerateOptions o = generate_options(kind, n, coords, 0.5, 1.0, 4);
        const std::string text = tools::generate_scene(o);
        const std::uint64_t entries = tools::family_entries(o);
        SceneLimits exact, less;
        exact.max_family_instances = entries;
        less.max_family_instances = entries - 1;
        EXPECT_NO_THROW(parse_scene(text, "exact.yaml", exact)) << kind << " " << coords << " N = " << n;
        try {
          parse_scene(text, "less.yaml", less);
          ADD_FAILURE() << kind << " " << coords << " N = " << n << ": loads with " << entries - 1 << " entries";
        } catch (const SceneError& e) {
          EXPECT_NE(std::string(e.what()).find("max_family_instances"), std::string::npos) << e.what();
        }
      }
}

// An N or a step count the loader would refuse is refused by generate (it wrote such scenes, a kilobyte each, and
// `phiq check` said so only after expanding gigabytes). The largest N of each kind, counted by hand from the
// families each writes (per N: nfourbar 5 natural, 11 reference-point; scissor 15, 11; chain3d 7, 10; grid about
// 5 and 11, its rows adding a few), within 5·10^7.
TEST(Generate, RefusesWhatTheLoaderWouldRefuse) {
  const auto message = test::generate_error;
  struct Case {
    const char* kind;
    const char* coords;
    std::int64_t most;
  };
  for (const Case& c : {Case{"nfourbar", "natural", 9999999}, Case{"nfourbar", "reference-point", 4545454},
                        Case{"scissor", "natural", 3333333}, Case{"scissor", "reference-point", 4545454},
                        Case{"grid", "natural", 9993046}, Case{"grid", "reference-point", 4542936},
                        Case{"chain3d", "natural", 7142856}, Case{"chain3d", "reference-point", 4999999}}) {
    GenerateOptions o = generate_options(c.kind, c.most, c.coords, 0.5, 1.0);
    EXPECT_EQ(tools::max_n(o), c.most) << c.kind << " " << c.coords;
    EXPECT_LE(tools::family_entries(o), SceneLimits{}.max_family_instances) << c.kind << " " << c.coords;
    EXPECT_EQ(message(o), "(no error)") << c.kind << " " << c.coords;
    for (std::int64_t n : {c.most + 1, std::int64_t{10000000}, std::int64_t{1000000000000}}) {
      o.n = n;
      if (n <= 10000000) {
        EXPECT_GT(tools::family_entries(o), SceneLimits{}.max_family_instances);
      }
      EXPECT_EQ(message(o), "N = " + std::to_string(n) + ": " + c.kind + " in " + c.coords +
                                " coordinates is at most N = " + std::to_string(c.most) +
                                " (its families would make more entries than a scene may, "
                                "SceneLimits::max_family_instances)");
    }
  }
  // time.steps is at most 10^9
  for (const char* kind : {"nfourbar", "scissor", "grid", "chain3d"}) {
    GenerateOptions o = generate_options(kind, 2, "natural", 0.5, 1.0, tools::kMaxSteps);
    Scene s = parse_scene(tools::generate_scene(o), "s.yaml");
    EXPECT_EQ(s.sweep.steps, tools::kMaxSteps);
    o.steps = tools::kMaxSteps + 1;
    EXPECT_EQ(message(o), "--steps must be at most 1000000000 (a scene's time.steps), got 1000000001") << kind;
  }
}

}  // namespace
}  // namespace phiq
