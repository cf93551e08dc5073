// `phiq generate`: the generated nfourbar, scissor, grid and chain3d scenes run and stay on their closed forms,
// nfourbar's families are the model listed one by one (the generator's former output, rebuilt here), the file's
// size does not grow with N, and bad options are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "phiq/text.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

// Reads a CSV written by phiq into columns by name.
std::map<std::string, std::vector<double>> columns_of(const std::string& text) {
  std::stringstream in(text);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) names.push_back(c);
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::size_t k = 0;
    for (std::string c; std::getline(ls, c, ','); ++k) cols[names.at(k)].push_back(std::stod(c));
  }
  return cols;
}

TEST_F(Cli, GeneratedNFourBarStaysOnTheParallelogramBranch) {
  // N = 6 four-bars over the default quarter turn: every crank stays parallel to crank 0 at θ(t) = π/4 + π/2 t
  for (const char* coords : {"natural", "reference-point"}) {
    const fs::path scene = dir_ / (std::string(coords) + ".yaml"), out = dir_ / (std::string(coords) + ".csv");
    ASSERT_EQ(run(std::string("generate nfourbar 6 --steps 40 --coords ") + coords + " -o " + scene.string()).code, 0);
    Result r = run("run -q " + scene.string() + " -o " + out.string());
    ASSERT_EQ(r.code, 0) << r.err;
    auto c = columns_of(slurp(out));
    ASSERT_EQ(c["t"].size(), 41u) << coords;
    double worst = 0.0;
    for (std::size_t k = 0; k < c["t"].size(); ++k) {
      const double th = M_PI / 4 + M_PI / 2 * c["t"][k];
      for (int i = 0; i <= 6; ++i) {
        const std::string n = std::to_string(i);
        if (std::string(coords) == "natural") {
          worst = std::max(worst, std::fabs(c["x" + n][k] - (i + std::cos(th))));
          worst = std::max(worst, std::fabs(c["y" + n][k] - std::sin(th)));
        } else {
          worst = std::max(worst, std::fabs(c["psi" + n][k] - th));
          worst = std::max(worst, std::fabs(c["xc" + n][k] - (i + 0.5 * std::cos(th))));
        }
      }
    }
    EXPECT_LT(worst, 1e-9) << coords;
  }
}

// The nfourbar scenes as `phiq generate` wrote them before families: every coordinate, point, body and
// constraint listed one by one (the generator's former code, kept here as the reference of the compact form).
// Numbers as the generator writes them: shortest round trip, −0 as 0.
constexpr auto shortest = &phiq::shortest_unsigned_zero;
std::string explicit_nfourbar(std::int64_t n, const std::string& coords, double from, double to) {
  const double c = std::cos(from), sn = std::sin(from);
  std::string s = "phiq: 1\n";
  if (coords == "natural") {
    s += "coordinates:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      s += "  x" + std::to_string(i) + ": " + shortest(static_cast<double>(i) + c) + "\n";
      s += "  y" + std::to_string(i) + ": " + shortest(sn) + "\n";
    }
    s += "  theta: " + shortest(from) + "\n";
    s += "points:\n  O: [0, 0]\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  P" + k + ": [x" + k + ", y" + k + "]\n";
    }
    s += "constraints:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  - {name: crank" + k + ", type: distance, points: [[" + k + ", 0], P" + k + "], length: 1}\n";
    }
    for (std::int64_t i = 0; i < n; ++i) {
      const std::string k = std::to_string(i), k1 = std::to_string(i + 1);
      s += "  - {name: coupler" + k + ", type: distance, points: [P" + k + ", P" + k1 + "], length: 1}\n";
    }
    s += "  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}\n";
  } else {
    s += "coordinates:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  xc" + k + ": " + shortest(static_cast<double>(i) + 0.5 * c) + "\n  yc" + k + ": " + shortest(0.5 * sn) +
           "\n  psi" + k + ": " + shortest(from) + "\n";
    }
    for (std::int64_t i = 0; i < n; ++i) {
      const std::string k = std::to_string(i);
      s += "  xk" + k + ": " + shortest(static_cast<double>(i) + 0.5 + c) + "\n  yk" + k + ": " + shortest(sn) +
           "\n  phi" + k + ": 0\n";
    }
    s += "bodies:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  crank" + k + ": [xc" + k + ", yc" + k + ", psi" + k + "]\n";
    }
    for (std::int64_t i = 0; i < n; ++i) {
      const std::string k = std::to_string(i);
      s += "  coupler" + k + ": [xk" + k + ", yk" + k + ", phi" + k + "]\n";
    }
    s += "constraints:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  - {name: pivot" + k + ", type: revolute, between: [{body: crank" + k +
           ", at: [-0.5, 0]}, {body: ground, at: [" + k + ", 0]}]}\n";
    }
    for (std::int64_t i = 0; i < n; ++i) {
      const std::string k = std::to_string(i), k1 = std::to_string(i + 1);
      s += "  - {name: left" + k + ", type: revolute, between: [{body: crank" + k + ", at: [0.5, 0]}, {body: coupler" +
           k + ", at: [-0.5, 0]}]}\n";
      s += "  - {name: right" + k + ", type: revolute, between: [{body: crank" + k1 +
           ", at: [0.5, 0]}, {body: coupler" + k + ", at: [0.5, 0]}]}\n";
    }
  }
  const std::string driven = coords == "natural" ? "theta" : "psi0";
  s += "drivers:\n  - {name: motor, coordinate: " + driven + ", law: {type: linear, initial: " + shortest(from) +
       ", rate: " + shortest(to - from) + "}}\n";
  s += "time: {start: 0, end: 1, steps: 10}\n";
  return s;
}

TEST_F(Cli, GeneratedFamiliesAreTheModelListedOneByOne) {
  // the same coordinates (names, order, initial values bit for bit), constraints, pattern, Φ, Φq, Φt and γ
  for (const char* coords : {"natural", "reference-point"}) {
    for (const auto& [n, from, to] : {std::tuple<int, double, double>{3, 0.7853981633974483, 2.356194490192345},
                                      std::tuple<int, double, double>{37, 0.3, 1.1}}) {
      const fs::path p = dir_ / "compact.yaml";
      std::ostringstream args;
      args.precision(17);
      args << "generate nfourbar " << n << " --steps 10 --coords " << coords << " --from " << from << " --to " << to
           << " -o " << p.string();
      ASSERT_EQ(run(args.str()).code, 0) << args.str();
      phiq::Scene compact = phiq::load_scene(p.string());
      phiq::Scene listed = phiq::parse_scene(explicit_nfourbar(n, coords, from, to), "listed.yaml");
      SCOPED_TRACE(std::string(coords) + " N = " + std::to_string(n));
      phiq::test::expect_same_model(*compact.model, *listed.model);
      EXPECT_EQ(compact.model->time_domain_end(), listed.model->time_domain_end());
    }
  }
}

TEST_F(Cli, GeneratedSceneSizeDoesNotDependOnN) {
  for (const char* coords : {"natural", "reference-point"}) {
    const fs::path small = dir_ / "small.yaml", large = dir_ / "large.yaml";
    ASSERT_EQ(run(std::string("generate nfourbar 10 --coords ") + coords + " -o " + small.string()).code, 0);
    ASSERT_EQ(run(std::string("generate nfourbar 1000000 --coords ") + coords + " -o " + large.string()).code, 0);
    // N is written three times (comment, name, parameter), and the counts of coordinates, kinematic equations and
    // equations once each: 5 more digits each
    EXPECT_EQ(fs::file_size(large), fs::file_size(small) + 30) << coords;
    EXPECT_LT(fs::file_size(large), 4096u) << coords;
  }
}

TEST_F(Cli, GenerateRefusesBadOptions) {
  EXPECT_EQ(run("generate gears 5 -o " + (dir_ / "x.yaml").string()).code, 2);
  EXPECT_EQ(run("generate nfourbar 0 -o " + (dir_ / "x.yaml").string()).code, 2);
  EXPECT_EQ(run("generate nfourbar 5 --coords polar -o " + (dir_ / "x.yaml").string()).code, 2);
  EXPECT_EQ(run("generate nfourbar 5 --outputs q,w -o " + (dir_ / "x.yaml").string()).code, 2);
  // a scene the loader would refuse: more family entries than SceneLimits::max_family_instances, or more steps
  // than time.steps takes (it was written, a kilobyte, and refused by `phiq check` only after minutes)
  Result r = run("generate nfourbar 1000000000000 -o " + (dir_ / "x.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "phiq: generate: N = 1000000000000: nfourbar in natural coordinates is at most N = 9999999 (its "
            "families would make more entries than a scene may, SceneLimits::max_family_instances)\n");
  EXPECT_EQ(run("generate scissor 3333334 -o " + (dir_ / "x.yaml").string()).code, 2);
  // an item twice is most likely another one mistyped
  r = run("generate nfourbar 3 --outputs q,v,v -o " + (dir_ / "x.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "phiq: generate: --outputs: 'v' given twice in 'q,v,v'\n");
  r = run("generate grid 3 --steps 1000000001 -o " + (dir_ / "x.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "phiq: generate: --steps must be at most 1000000000 (a scene's time.steps), got 1000000001\n");
  EXPECT_FALSE(fs::exists(dir_ / "x.yaml"));
}

TEST_F(Cli, GeneratedScissorAndGridRunOverTheirDefaultRanges) {
  // without --from/--to: the scissor's bars from 0.3 to 1.2 rad, the grid's rows between π/4 and 3π/4
  for (const char* kind : {"scissor", "grid"})
    for (const char* coords : {"natural", "reference-point"}) {
      const fs::path scene = dir_ / "s.yaml", out = dir_ / "s.csv";
      const std::string args = std::string(kind) + " 5 --steps 30 --coords " + coords;
      ASSERT_EQ(run("generate " + args + " -o " + scene.string()).code, 0);
      const std::string text = slurp(scene);
      const std::string law = std::string(kind) == "scissor" ? "initial: 0.3, rate: 0.8999999999999999"
                                                             : "initial: 0.7853981633974483, rate: 1.5707963267948966";
      EXPECT_NE(text.find(law), std::string::npos) << kind << "\n" << text;
      Result r = run("run -q " + scene.string() + " -o " + out.string());
      ASSERT_EQ(r.code, 0) << kind << " " << coords << ": " << r.err;
      EXPECT_EQ(columns_of(slurp(out))["t"].size(), 31u);
    }
  // an explicit range replaces the default
  const fs::path scene = dir_ / "s.yaml";
  ASSERT_EQ(run("generate scissor 2 --from 0.5 --to 1 -o " + scene.string()).code, 0);
  EXPECT_NE(slurp(scene).find("initial: 0.5, rate: 0.5"), std::string::npos);
}

TEST_F(Cli, GenerateScissorAndGridRefuseBadOptions) {
  const std::string x = " -o " + (dir_ / "x.yaml").string();
  for (const char* kind : {"scissor", "grid"}) {
    EXPECT_EQ(run(std::string("generate ") + kind + " 0" + x).code, 2);
    EXPECT_EQ(run(std::string("generate ") + kind + " 5 --coords polar" + x).code, 2);
    EXPECT_EQ(run(std::string("generate ") + kind + " 5 --outputs q,w" + x).code, 2);
    EXPECT_EQ(run(std::string("generate ") + kind + " 5 --steps -1" + x).code, 2);
    Result r = run(std::string("generate ") + kind + " 5 --from 0" + x);  // flat: singular
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("generate: --from and --to: "), std::string::npos) << r.err;
  }
  EXPECT_EQ(run("generate scissor 5 --to 1.6" + x).code, 2);  // beyond vertical
  EXPECT_NE(run("generate gears 5" + x).err.find("available: nfourbar, scissor, grid, chain3d"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "x.yaml"));
}

TEST_F(Cli, GeneratedChain3dRuns) {
  // the command as written: N = 10 spatial loops, the default quarter turn in 1000 steps
  const fs::path scene = dir_ / "c.yaml", out = dir_ / "c.csv";
  ASSERT_EQ(run("generate chain3d 10 -o " + scene.string()).code, 0);
  Result r = run("run -q " + scene.string() + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  auto c = columns_of(slurp(out));
  ASSERT_EQ(c["t"].size(), 1001u);
  ASSERT_EQ(c.size(), 1u + 3 * 34);  // t and x0, y0, z0, ..., z10, theta with their .v and .a
  // the last row: every crank at 3π/4 about u = (1, 2, 2)/3 from e1 = d = (2, 1, -2)/3, P_10 = 10 d + c(3π/4)
  const double th = 3 * M_PI / 4, e1[3] = {2. / 3, 1. / 3, -2. / 3}, e2[3] = {-2. / 3, 2. / 3, -1. / 3};
  const char* axes[3] = {"x10", "y10", "z10"};
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(c[axes[k]].back(), 10 * e1[k] + std::cos(th) * e1[k] + std::sin(th) * e2[k], 1e-9) << axes[k];
  // the twisted row in reference-point coordinates through a full turn, and the options it refuses
  ASSERT_EQ(
      run("generate chain3d 4 --coords reference-point --twist 2 --from 0 --to 6.3 --steps 100 -o " + scene.string())
          .code,
      0);
  EXPECT_NE(slurp(scene).find("--coords reference-point --twist 2:"), std::string::npos);
  r = run("run -q " + scene.string() + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(columns_of(slurp(out))["t"].size(), 101u);
  const std::string x = " -o " + (dir_ / "x.yaml").string();
  EXPECT_EQ(run("generate chain3d 5 --from 0" + x).code, 2);           // the parallelogram row lies flat
  EXPECT_EQ(run("generate chain3d 5 --twist 3.1415926" + x).code, 2);  // neighbours opposite: singular
  EXPECT_EQ(run("generate nfourbar 5 --twist 1" + x).code, 2);         // chain3d only
  EXPECT_FALSE(fs::exists(dir_ / "x.yaml"));
}

}  // namespace
