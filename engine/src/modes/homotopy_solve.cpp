// solve_polynomial_system() (phiq/modes.hpp): squares the system up, tracks every path of the total-degree homotopy
// in parallel, refines each endpoint by Newton on the original equations, classifies it, merges duplicates and
// sorts the endpoints so that the result does not depend on the order the paths finished in.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include <Eigen/QR>
#include <Eigen/SVD>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "modes/homotopy.hpp"

namespace phiq {

namespace {

using modes_detail::cd;
using modes_detail::CompiledSystem;
using modes_detail::Homotopy;
using modes_detail::PathEnd;
using modes_detail::Random;

double inf_norm(const Eigen::VectorXcd& v) { return v.size() ? v.cwiseAbs().maxCoeff() : 0.0; }

// The first `variables` equations plus random combinations of the rest (equations sorted by degree, highest
// first, so that the combinations add as little degree as possible): a square system whose solutions include
// every solution of the original one.
PolynomialSystem squared_up(const PolynomialSystem& s, Random& random) {
  std::vector<std::size_t> order(s.equations.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return s.equations[a].degree() > s.equations[b].degree(); });
  PolynomialSystem square{s.variables, s.names, {}};
  const std::size_t n = static_cast<std::size_t>(s.variables);
  for (std::size_t i = 0; i < n; ++i) {
    std::map<std::vector<int>, cd> sum;
    for (const PolynomialTerm& t : s.equations[order[i]].terms) sum[t.exponent] += t.coefficient;
    for (std::size_t j = n; j < order.size(); ++j) {
      const cd lambda = random.unit_complex();
      for (const PolynomialTerm& t : s.equations[order[j]].terms) sum[t.exponent] += lambda * t.coefficient;
    }
    Polynomial p;
    for (const auto& [e, c] : sum) p.terms.push_back({c, e});
    square.equations.push_back(std::move(p));
  }
  return square;
}

}  // namespace

// Newton (Gauss-Newton for more equations than unknowns) on the original equations from x; returns the residual
// max_i |F_i| / scale_i and sets the condition number of the scaled Jacobian. Converges linearly at a singular
// solution (ratio 1/2 at a double root): the iterations allowed let it get there too.
double modes_detail::refine_endpoint(const CompiledSystem& f, Eigen::VectorXcd& x, double* condition) {
  Eigen::VectorXcd value;
  Eigen::MatrixXcd jac;
  auto residual_of = [&](const Eigen::VectorXcd& y) {
    f.affine(y, value, nullptr);
    double r = 0.0;
    for (Eigen::Index i = 0; i < value.size(); ++i)
      r = std::max(r, std::abs(value(i)) / f.coefficient_scale[static_cast<std::size_t>(i)]);
    return std::isfinite(r) ? r : std::numeric_limits<double>::infinity();
  };
  double r = residual_of(x);
  for (int it = 0; it < 80 && r > 0.0; ++it) {
    f.affine(x, value, &jac);
    const Eigen::VectorXcd delta = jac.colPivHouseholderQr().solve(value);
    const Eigen::VectorXcd trial = x - delta;
    const double rt = residual_of(trial);
    if (!(rt < r) && !(rt <= 1e-15)) break;  // no progress: at the rounding level (or diverging)
    const bool small = inf_norm(delta) <= 1e-15 * (1.0 + inf_norm(x));
    x = trial, r = rt;
    if (small) break;
  }
  f.affine(x, value, &jac);
  const double size = 1.0 + inf_norm(x);
  for (Eigen::Index i = 0; i < jac.rows(); ++i) jac.row(i) *= size / f.coefficient_scale[static_cast<std::size_t>(i)];
  const Eigen::JacobiSVD<Eigen::MatrixXcd> svd(jac);
  const Eigen::VectorXd& sv = svd.singularValues();
  *condition = sv.size() == 0            ? 1.0
               : sv(sv.size() - 1) > 0.0 ? sv(0) / sv(sv.size() - 1)
                                         : std::numeric_limits<double>::infinity();
  return r;
}

namespace {

int kind_rank(EndpointKind k) { return static_cast<int>(k); }

bool endpoint_before(const Endpoint& a, const Endpoint& b) {
  if (a.kind != b.kind) return kind_rank(a.kind) < kind_rank(b.kind);
  for (Eigen::Index v = 0; v < a.x.size(); ++v)
    if (a.x(v).real() != b.x(v).real()) return a.x(v).real() < b.x(v).real();
  for (Eigen::Index v = 0; v < a.x.size(); ++v)
    if (a.x(v).imag() != b.x(v).imag()) return a.x(v).imag() < b.x(v).imag();
  return a.multiplicity < b.multiplicity;
}

}  // namespace

ModesSummary solve_polynomial_system(const PolynomialSystem& system, const ModesOptions& options) {
  ModesSummary summary;
  const auto start_time = std::chrono::steady_clock::now();
  const int n = system.variables;
  if (static_cast<int>(system.equations.size()) < n) {
    summary.status = ModesStatus::kNotSquare;
    summary.message = std::to_string(system.equations.size()) + " equations in " + std::to_string(n) +
                      " unknowns: the solutions form a continuum, not isolated points";
    return summary;
  }
  Random random(options.seed);
  const CompiledSystem original(system);  // checks the exponents
  const PolynomialSystem square = static_cast<int>(system.equations.size()) > n ? squared_up(system, random) : system;
  summary.paths = square.total_degree();
  if (summary.paths > options.max_paths) {
    summary.status = ModesStatus::kTooManyPaths;
    summary.message = "the total degree is " + std::to_string(summary.paths) + " paths, above the limit of " +
                      std::to_string(options.max_paths) + " (ModesOptions::max_paths, --max-paths)";
    return summary;
  }
  const CompiledSystem target(square);
  Homotopy homotopy{&target, random.unit_complex(), Eigen::VectorXcd(n + 1)};
  for (int v = 0; v <= n; ++v) homotopy.patch(v) = random.unit_complex();

  // Every path, each into its own slot: the arithmetic of a path does not depend on which thread runs it.
  std::vector<PathEnd> ends(static_cast<std::size_t>(summary.paths));
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, summary.paths, 1), [&](const auto& range) {
      for (std::int64_t p = range.begin(); p != range.end(); ++p)
        ends[static_cast<std::size_t>(p)] = modes_detail::track_path(homotopy, p);
    });
  });

  // Classify each endpoint, in path order, merging it into an earlier distinct endpoint it duplicates; cluster_of[p]
  // is the distinct endpoint path p reached (−1: failed).
  std::vector<Endpoint> distinct;
  std::vector<int> cluster_of;
  auto classify = [&] {
    distinct.clear();
    cluster_of.assign(ends.size(), -1);
    summary.failed_paths = 0, summary.duplicate_paths = 0;
    for (std::size_t path = 0; path < ends.size(); ++path) {
      const PathEnd& e = ends[path];
      Endpoint point;
      if (!e.reached) {
        ++summary.failed_paths;
        continue;
      }
      const double x0 = std::abs(e.X(0)), size = inf_norm(e.X);
      bool infinite = !(x0 > 1e-8 * size);
      if (!infinite) {
        point.x = e.X.tail(n) / e.X(0);
        point.residual = modes_detail::refine_endpoint(original, point.x, &point.condition);
        infinite = !(inf_norm(point.x) < 1e8) || !point.x.allFinite();
        // a path stopped short of t = 0 (its step collapsed in the end game) with X0 already small and no solution
        // near it: diverging, to a solution set at infinity
        if (!infinite && !(point.residual <= 1e-8) && e.t > 0.0 && x0 < 1e-2 * size) infinite = true;
        if (!infinite && !(point.residual <= 1e-8)) {
          ++summary.failed_paths;  // solves the squared-up system (or the path was lost), not the original
          continue;
        }
      }
      if (infinite) {
        point.kind = EndpointKind::kAtInfinity;
        Eigen::Index largest = 0;
        e.X.tail(n).cwiseAbs().maxCoeff(&largest);
        point.x = e.X.tail(n) / e.X(1 + largest);
        point.residual = 0.0, point.condition = std::numeric_limits<double>::infinity();
      } else if (!(point.condition <= options.singular_condition)) {
        point.kind = EndpointKind::kSingular;
      } else {
        const double imag = point.x.imag().cwiseAbs().maxCoeff();
        point.kind =
            imag <= options.real_tolerance * (1.0 + inf_norm(point.x)) ? EndpointKind::kReal : EndpointKind::kComplex;
      }
      if (point.kind == EndpointKind::kReal)
        for (Eigen::Index v = 0; v < n; ++v) point.x(v) = point.x(v).real();
      const bool at_infinity = point.kind == EndpointKind::kAtInfinity;
      const double tolerance = (at_infinity ? 1e-4 : options.duplicate_tolerance) * (1.0 + inf_norm(point.x));
      auto same = std::find_if(distinct.begin(), distinct.end(), [&](const Endpoint& d) {
        return (d.kind == EndpointKind::kAtInfinity) == at_infinity && inf_norm(d.x - point.x) <= tolerance;
      });
      if (same == distinct.end()) {
        cluster_of[path] = static_cast<int>(distinct.size());
        distinct.push_back(std::move(point));
      } else {
        // Several paths at one point: a multiple root (singular by its condition number), or, at a regular one, a
        // path that jumped onto another's on the way (counted: ModesSummary::duplicate_paths)
        cluster_of[path] = static_cast<int>(same - distinct.begin());
        ++same->multiplicity;
        if (same->kind == EndpointKind::kReal || same->kind == EndpointKind::kComplex) ++summary.duplicate_paths;
      }
    }
  };
  classify();
  // A second, careful pass over the paths that failed and those that met at a regular point (where one of them
  // jumped), then the classification again: deterministic, as the first pass.
  std::vector<std::int64_t> again;
  for (std::size_t path = 0; path < ends.size(); ++path) {
    const int c = cluster_of[path];
    if (c < 0 || (distinct[static_cast<std::size_t>(c)].multiplicity > 1 &&
                  (distinct[static_cast<std::size_t>(c)].kind == EndpointKind::kReal ||
                   distinct[static_cast<std::size_t>(c)].kind == EndpointKind::kComplex)))
      again.push_back(static_cast<std::int64_t>(path));
  }
  if (!again.empty()) {
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, again.size(), 1), [&](const auto& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k)
          ends[static_cast<std::size_t>(again[k])] = modes_detail::track_path(homotopy, again[k], true);
      });
    });
    classify();
  }
  summary.retracked_paths = static_cast<int>(again.size());
  // A point that several paths still reach after the careful pass, and where the Jacobian is far from well
  // conditioned, is a multiple root: Newton places a double root only to about √ε, where the condition is near
  // 1e8 (a k-fold tangency of circles gives 1e7 … 1e9), below options.singular_condition; a regular solution is
  // the end of one path only, and one that two paths jumped onto is well conditioned (counted as duplicate).
  for (Endpoint& d : distinct)
    if (d.multiplicity > 1 && (d.kind == EndpointKind::kReal || d.kind == EndpointKind::kComplex) &&
        !(d.condition <= options.multiple_root_condition)) {
      d.kind = EndpointKind::kSingular;
      summary.duplicate_paths -= d.multiplicity - 1;
    }
  std::sort(distinct.begin(), distinct.end(), endpoint_before);
  for (const Endpoint& d : distinct) {
    summary.real += d.kind == EndpointKind::kReal;
    summary.complex += d.kind == EndpointKind::kComplex;
    summary.singular += d.kind == EndpointKind::kSingular;
    summary.at_infinity += d.kind == EndpointKind::kAtInfinity;
  }
  summary.endpoints = std::move(distinct);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return summary;
}

}  // namespace phiq
