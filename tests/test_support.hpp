// Helpers shared by the test files.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "phiq/phiq.hpp"
#include "../bench/nfourbar_model.hpp"
#include "closed_forms.hpp"
#include "generate.hpp"

namespace phiq::test {

// (appended, not `std::string(DIR) + "/" + rel`: GCC 12 warns of a memcpy out of bounds in that temporary's inlined
// operator+, a false positive, -Warray-bounds)
inline std::string model_path(const std::string& rel) {
  std::string path = PHIQ_MODELS_DIR;
  path += '/';
  path += rel;
  return path;
}

// The whole text of the file at `path`, read as bytes ("" if it cannot be opened).
inline std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The text of models/REL up to (without) its first `cut`, or whole (std::out_of_range if `cut` is not in it: a test
// whose marker is gone fails).
inline std::string model_file_text(const std::string& rel, const std::string& cut = "") {
  std::string text = file_text(model_path(rel));
  if (!cut.empty()) text.erase(text.find(cut));
  return text;
}

// `text` with its first occurrence of `from` replaced by `to` (a failure, and `text` unchanged, if it has none).
inline std::string replace_first(std::string text, const std::string& from, const std::string& to) {
  const auto p = text.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return p == std::string::npos ? text : text.replace(p, from.size(), to);
}

// The SceneError of a scene read as "bad.yaml": one line, starting with the file name (a failure if it loads).
inline std::string scene_error(const std::string& text, const std::string& file = "bad.yaml",
                               const SceneLimits& limits = {}) {
  try {
    parse_scene(text, file, limits);
  } catch (const SceneError& e) {
    std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << "one line: " << m;
    EXPECT_EQ(m.rfind(file + ":", 0), 0u) << m;
    return m;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return "";
}

#define EXPECT_HAS(msg, part) EXPECT_NE((msg).find(part), std::string::npos) << (msg)

// The phiq::Error a sweep of `model` under `opt` throws, from the model's initial positions (a failure, and "", if
// it throws none).
inline std::string sweep_error(const Model& model, const SweepOptions& opt) {
  Workspace ws(model);
  ws.q = model.initial_positions();
  try {
    (void)run_sweep(
        model, opt, ws, [](const StepView&) { return true; }, nullptr);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "the sweep threw no error";
  return "";
}

// The same doubles bit for bit (a NaN equal to itself: what "the same results" means across runs and threads).
inline bool same_bits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}
inline bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

// A scene of models/ prepared as `phiq run` prepares it (prepare_square with default assembly settings): the
// full scene model, the assembly, and the model its square solves use (null when the preparation failed).
struct Prepared {
  Scene scene;
  AssemblySummary assembly;
  std::unique_ptr<Model> solved;
  Eigen::VectorXd q;  // the assembled position
};

inline Prepared prepare(const std::string& rel) {
  Prepared p;
  p.scene = load_scene(model_path(rel));
  p.q = p.scene.model->initial_positions();
  // its status is p.assembly's; `solved` stays null on failure
  (void)prepare_square(*p.scene.model, p.scene.sweep.t_begin, {}, p.q, &p.solved, &p.assembly);
  return p;
}

// Sweeps a prepared scene; calls check(step) at every row and asserts that every row of the full model (left-out
// rows included) holds to 1e-9 (scaled) and that every time point is delivered.
template <class Check>
void sweep_prepared(Prepared& p, Check check) {
  ASSERT_NE(p.solved, nullptr) << p.assembly.BriefReport();
  const Model& full = *p.scene.model;
  Workspace ws(*p.solved);
  ws.q = p.q;
  SweepSummary sum;
  Eigen::VectorXd phi(full.num_equations());
  Index rows = 0;
  const SolveStatus st = run_sweep(
      *p.solved, p.scene.sweep, ws,
      [&](const StepView& s) {
        full.residual(s.q.data(), s.t, phi.data());
        EXPECT_LE(scaled_residual(full, phi), 1e-9) << "t = " << s.t;
        check(s);
        ++rows;
        return true;
      },
      &sum);
  ASSERT_EQ(st, SolveStatus::kSuccess) << sum.message;
  EXPECT_EQ(rows, p.scene.sweep.steps + 1);
}

// All rows of a sweep, kept in memory.
struct Trace {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q, qd, qdd;
};

inline SolveStatus sweep(const Model& model, const SweepOptions& opt, Trace* trace, SweepSummary* summary = nullptr,
                         Workspace* ws_in = nullptr) {
  Workspace local(model);
  Workspace& ws = ws_in ? *ws_in : local;
  return run_sweep(
      model, opt, ws,
      [&](const StepView& s) {
        trace->t.push_back(s.t);
        trace->q.push_back(s.q);
        if (s.qd) trace->qd.push_back(*s.qd);
        if (s.qdd) trace->qdd.push_back(*s.qdd);
        return true;
      },
      summary);
}

// A scene of models/ swept with every row kept: what the closed-form tests of a scene start from.
struct SweptScene {
  Scene scene;
  Trace trace;
  SweepSummary summary;
  SolveStatus status = SolveStatus::kSuccess;
};
inline SweptScene sweep_scene(const std::string& rel) {
  SweptScene s;
  s.scene = load_scene(model_path(rel));
  s.status = sweep(*s.scene.model, s.scene.sweep, &s.trace, &s.summary);
  return s;
}

// The notes' crank-slider built in code: q = [theta2, xA, yA, xB], L2 = 0.3, L3 = 1.0, theta2 = theta0 + omega t,
// from a rough placement.
inline Model crank_slider_model(double omega = 1.0, double theta0 = 0.0,
                                LinearSolverKind lu = LinearSolverKind::kUmfpack) {
  ModelBuilder b;
  Index th = b.add_coordinate("theta2", theta0), xa = b.add_coordinate("xA", 0.25), ya = b.add_coordinate("yA", 0.05),
        xb = b.add_coordinate("xB", 1.2);
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, 0.3, S(th)});
  b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, 1.0});
  b.add_driver("motor", th, MotionLaw::linear(theta0, omega));
  b.set_linear_solver(lu);
  return std::move(b).build();
}

// IFToMM N four-bar in natural coordinates (x0, y0, …, xN, yN, theta), placed on the parallelogram solution, which
// is exact for all t: the benchmarks' very model (bench/nfourbar_model.hpp).
inline Model nfourbar_model(Index n, double theta0, double rate, LinearSolverKind lu = LinearSolverKind::kKlu) {
  return phiq_bench::nfourbar(n, theta0, rate, lu);
}

// Its exact motion (the parallelogram, tools/accuracy/closed_forms.hpp) bound to the model's coordinates, for t in [0,
// 1] (θ = theta0 + rate·t).
inline std::unique_ptr<tools::ClosedForm> nfourbar_exact(const Model& m, double theta0, double rate) {
  char spec[96];
  std::snprintf(spec, sizeof spec, "nfourbar:from=%.17g,to=%.17g", theta0, theta0 + rate);
  auto f = tools::make_closed_form(spec);
  f->bind(m.coordinate_names());
  return f;
}

// Largest difference between the rows of two traces in positions (order 0), velocities (1) or accelerations (2);
// infinity if their times or row counts differ.
inline double max_difference(const Trace& a, const Trace& b, int order = 0) {
  const auto& va = order == 0 ? a.q : order == 1 ? a.qd : a.qdd;
  const auto& vb = order == 0 ? b.q : order == 1 ? b.qd : b.qdd;
  if (a.t != b.t || va.size() != vb.size()) return INFINITY;
  double d = 0;
  for (std::size_t k = 0; k < va.size(); ++k) d = std::max(d, (va[k] - vb[k]).cwiseAbs().maxCoeff());
  return d;
}

// Two models are the same model: coordinates (names, order, initial values), constraints (names, kinds, rows), the
// Jacobian pattern, and bit for bit the same Φ, Φq, Φt and γ at the initial point (q̇ = 1).
inline void expect_same_model(const Model& a, const Model& b) {
  ASSERT_EQ(a.coordinate_names(), b.coordinate_names());
  ASSERT_EQ(a.num_equations(), b.num_equations());
  for (Index j = 0; j < a.num_coordinates(); ++j)
    EXPECT_EQ(a.initial_positions()(j), b.initial_positions()(j)) << a.coordinate_names()[static_cast<std::size_t>(j)];
  ASSERT_EQ(a.constraints().size(), b.constraints().size());
  for (std::size_t k = 0; k < a.constraints().size(); ++k) {
    EXPECT_EQ(a.constraints()[k].name, b.constraints()[k].name);
    EXPECT_EQ(a.constraints()[k].kind, b.constraints()[k].kind);
    EXPECT_EQ(a.constraints()[k].first_row, b.constraints()[k].first_row);
  }
  EXPECT_EQ(a.jacobian_pattern().col_ptr, b.jacobian_pattern().col_ptr);
  EXPECT_EQ(a.jacobian_pattern().row_idx, b.jacobian_pattern().row_idx);
  EXPECT_EQ(a.length_scale(), b.length_scale());
  const Eigen::VectorXd& q = a.initial_positions();
  const Eigen::VectorXd qd = Eigen::VectorXd::Ones(q.size());
  const auto m = static_cast<std::size_t>(a.num_equations());
  const auto nnz = static_cast<std::size_t>(a.jacobian_pattern().nnz());
  std::vector<double> ra(m), rb(m), ja(nnz, 0.0), jb(nnz, 0.0), ta(m), tb(m), ga(m), gb(m);
  a.residual(q.data(), 0.0, ra.data()), b.residual(q.data(), 0.0, rb.data());
  a.jacobian(q.data(), 0.0, ja.data()), b.jacobian(q.data(), 0.0, jb.data());
  a.phi_t(q.data(), 0.0, ta.data()), b.phi_t(q.data(), 0.0, tb.data());
  a.gamma(q.data(), qd.data(), 0.0, ga.data()), b.gamma(q.data(), qd.data(), 0.0, gb.data());
  EXPECT_EQ(ra, rb);
  EXPECT_EQ(ja, jb);
  EXPECT_EQ(ta, tb);
  EXPECT_EQ(ga, gb);
}

// Options of `phiq generate KIND N`: the coordinates, the driven range and the steps (the rest as defaults).
inline tools::GenerateOptions generate_options(const std::string& kind, std::int64_t n, const std::string& coords,
                                               double from, double to, std::int64_t steps = 24) {
  tools::GenerateOptions o;
  o.kind = kind;
  o.n = n;
  o.coords = coords;
  o.from = from;
  o.to = to;
  o.steps = steps;
  return o;
}

// The message tools::generate_scene() refuses `o` with, or "(no error)".
inline std::string generate_error(const tools::GenerateOptions& o) {
  try {
    tools::generate_scene(o);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

// The README's crank-slider built in code (engine/README.md, "Using the API"): q = [θ2, xA, yA, xB] from its rough
// placement, crank `l2`, rod `l3`, θ2 driven by `law` (the README's 2t); sharing `share`'s analysis when given (the
// models along a length, sensitivity_along()).
inline Model readme_crank_slider(double l2 = 0.3, double l3 = 1.0, const MotionLaw& law = MotionLaw::linear(0.0, 2.0),
                                 const Model* share = nullptr) {
  ModelBuilder b;
  const Index th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", 0.3), ya = b.add_coordinate("yA", 0.0),
              xb = b.add_coordinate("xB", 1.3);
  b.add("crank", PolarSpec{{Slot::coordinate(xa), Slot::coordinate(ya)}, {}, l2, Slot::coordinate(th)});
  b.add("rod", DistanceSpec{{Slot::coordinate(xa), Slot::coordinate(ya)}, {Slot::coordinate(xb), {}}, l3});
  b.add_driver("motor", th, law);
  if (share) b.share_analysis_with(*share);
  return std::move(b).build();
}

// Difference of two angles, wrapped to (-pi, pi].
inline double angle_diff(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

}  // namespace phiq::test

namespace phiq {
// A scene text's one-line error (test::scene_error() with its defaults): what the scene tests compare.
inline std::string error_of(const std::string& text) { return test::scene_error(text); }
}  // namespace phiq
