// solve_polynomial_system() (phiq/modes.hpp): squares the system up, lowers its degrees and picks the start system
// with the fewest paths (total degree or multi-homogeneous), tracks every path in parallel, refines each endpoint by
// Newton on the original equations, classifies it, merges duplicates and sorts the endpoints so that the result does
// not depend on the order the paths finished in.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include <Eigen/QR>
#include <Eigen/SVD>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "modes/homotopy.hpp"
#include "sweep/resources.hpp"

namespace phiq {

namespace {

using modes_detail::cd;
using modes_detail::CompiledSystem;
using modes_detail::Grouping;
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

// The groups a system's normalisations suggest: an equation of degree 2 whose quadratic terms are squares of two or
// more variables (c² + s² = 1 of an angle, e·e = 1 of a body's Euler parameters, in shifted variables too) names a
// rotation's variables. Candidates: each rotation its own group and the other variables one; all rotations one group
// and the others one; every variable its own group (up to 16 variables).
std::vector<std::vector<int>> candidate_groupings(const PolynomialSystem& s) {
  const int n = s.variables;
  std::vector<int> rotation(static_cast<std::size_t>(n), -1);
  int rotations = 0;
  for (const Polynomial& p : s.equations) {
    if (p.degree() != 2) continue;
    std::vector<int> vars;
    bool squares = true;
    for (const PolynomialTerm& t : p.terms) {
      int d = 0, square = -1;
      for (int v = 0; v < n; ++v) {
        d += t.exponent[static_cast<std::size_t>(v)];
        if (t.exponent[static_cast<std::size_t>(v)] == 2) square = v;
      }
      if (d < 2) continue;
      squares = squares && square >= 0;
      if (square >= 0) vars.push_back(square);
    }
    if (!squares || vars.size() < 2 ||
        std::any_of(vars.begin(), vars.end(), [&](int v) { return rotation[static_cast<std::size_t>(v)] >= 0; }))
      continue;
    for (int v : vars) rotation[static_cast<std::size_t>(v)] = rotations;
    ++rotations;
  }
  std::vector<std::vector<int>> out;
  const bool rest = std::any_of(rotation.begin(), rotation.end(), [](int r) { return r < 0; });
  if (rotations > 0 && (rest || rotations > 1)) {
    std::vector<int> apart(static_cast<std::size_t>(n)), together(static_cast<std::size_t>(n));
    for (int v = 0; v < n; ++v) {
      const int r = rotation[static_cast<std::size_t>(v)];
      apart[static_cast<std::size_t>(v)] = r < 0 ? rotations : r;
      together[static_cast<std::size_t>(v)] = r < 0 ? 1 : 0;
    }
    if (!rest) together.assign(static_cast<std::size_t>(n), 0);
    out.push_back(modes_detail::grouping_from(apart).group_of);
    if (rest && rotations > 1) out.push_back(together);
  }
  if (n >= 2 && n <= 16) {
    std::vector<int> each(static_cast<std::size_t>(n));
    for (int v = 0; v < n; ++v) each[static_cast<std::size_t>(v)] = v;
    out.push_back(each);
  }
  return out;
}

std::string grouping_name(const PolynomialSystem& s, const Grouping& g) {
  if (g.groups == 1) return "total degree";
  std::string name = "multi-homogeneous";
  for (const auto& members : g.members) {
    name += " {";
    for (std::size_t k = 0; k < members.size(); ++k) {
      // appended piece by piece: GCC 12 warns (-Wrestrict, a false positive) on a literal + std::string here
      if (k) name += ' ';
      const auto j = static_cast<std::size_t>(members[k]);
      if (s.names.empty() || s.names[j].empty())
        name.append(1, 'x').append(std::to_string(j + 1));
      else
        name += s.names[j];
    }
    name += "}";
  }
  return name;
}

// The system to track and its start system: of the square system and its lowered form, under one group and under
// each candidate grouping, the one with the fewest paths that options allow (ties: the fewer groups, the system as
// given). The linear products' forms are drawn from their own stream, so that the choice draws nothing from `random`.
struct ChosenStart {
  PolynomialSystem system;
  modes_detail::StartSystem start;
  std::string name;
};

ChosenStart choose_start(const PolynomialSystem& square, const ModesOptions& options) {
  std::vector<PolynomialSystem> systems{square};
  if (options.lower_degrees) {
    PolynomialSystem lowered = modes_detail::lowered_degrees(square);
    if (lowered.total_degree() < square.total_degree()) systems.push_back(std::move(lowered));
  }
  std::vector<std::vector<int>> groupings;
  if (options.start_system != StartSystemChoice::kMultiHomogeneous)
    groupings.push_back(std::vector<int>(static_cast<std::size_t>(square.variables), 0));
  if (options.start_system != StartSystemChoice::kTotalDegree)
    for (auto& g : candidate_groupings(square)) groupings.push_back(std::move(g));
  if (options.start_system != StartSystemChoice::kTotalDegree)
    for (const auto& g : options.groupings) {
      if (static_cast<int>(g.size()) != square.variables || g.empty() ||
          !std::all_of(g.begin(), g.end(), [](int j) { return j >= 0; }))
        continue;
      const Grouping given = modes_detail::grouping_from(g);
      if (given.groups > 1 &&
          std::all_of(given.members.begin(), given.members.end(), [](const auto& m) { return !m.empty(); }))
        groupings.push_back(g);
    }
  if (groupings.empty()) groupings.push_back(std::vector<int>(static_cast<std::size_t>(square.variables), 0));
  ChosenStart best;
  std::int64_t fewest = -1;
  for (const auto& group_of : groupings) {
    const Grouping g = modes_detail::grouping_from(group_of);
    for (std::size_t k = 0; k < systems.size(); ++k) {
      const auto degrees = modes_detail::group_degrees(systems[k], g);
      const std::int64_t paths = modes_detail::multihomogeneous_bezout(degrees, g);
      if (fewest >= 0 && paths >= fewest) continue;
      Random forms(options.seed ^ 0x9E3779B97F4A7C15ull);
      modes_detail::StartSystem start;
      if (!modes_detail::make_start_system(degrees, g, forms, start)) continue;
      fewest = paths;
      best.system = systems[k], best.start = std::move(start);
      best.name = grouping_name(square, g) + (k == 1 ? ", degrees lowered" : "");
    }
  }
  return best;
}

}  // namespace

// Newton (Gauss-Newton for more equations than unknowns) on the original equations from x; returns the residual
// max_i |F_i| / scale_i and sets the condition number of the scaled Jacobian, max(σ_max, 1) / σ_min: its rows at
// their coefficients' scale and the variables at the solution's, a regular solution's singular values are near 1,
// and a Jacobian small in every direction (a multiple root of one equation in one unknown: σ_max = σ_min ≈ 0) is
// singular however equal they are. Converges linearly at a singular solution (ratio 1/2 at a double root): the
// iterations allowed let it get there too.
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
               : sv(sv.size() - 1) > 0.0 ? std::max(sv(0), 1.0) / sv(sv.size() - 1)
                                         : std::numeric_limits<double>::infinity();
  return r;
}

namespace {

// An end whose homogenising coordinate is below this (relative to its group's coordinates) is at infinity whatever
// the accuracy of its end.
constexpr double kAtInfinity = 1e-8;

// An end at infinity: the homogenised equations' residual there (each group's coordinates scaled to |X_j|∞ = 1), and
// the condition of their Jacobian, n × (n + groups), whose n singular values are all nonzero at a regular solution at
// infinity (the Euler relation takes one direction per group), as refine_endpoint() takes it: max(σ_max, 1) / σ_min.
void at_infinity_residual(const CompiledSystem& target, const Grouping& g, Eigen::VectorXcd X, Endpoint& point) {
  for (int j = 0; j < g.groups; ++j) {
    const auto& members = g.members[static_cast<std::size_t>(j)];
    double size = std::abs(X(j));
    for (const int v : members) size = std::max(size, std::abs(X(g.groups + v)));
    if (!(size > 0.0)) continue;
    X(j) /= size;
    for (const int v : members) X(g.groups + v) /= size;
  }
  Eigen::VectorXcd f;
  Eigen::MatrixXcd jac;
  target.homogenised(X, f, &jac);
  point.residual = 0.0;
  for (Eigen::Index i = 0; i < f.size(); ++i) {
    const double scale = target.coefficient_scale[static_cast<std::size_t>(i)];
    point.residual = std::max(point.residual, std::abs(f(i)) / scale);
    jac.row(i) /= scale;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXcd> svd(jac);
  const Eigen::VectorXd& sv = svd.singularValues();
  point.condition = sv.size() == 0            ? 1.0
                    : sv(sv.size() - 1) > 0.0 ? std::max(sv(0), 1.0) / sv(sv.size() - 1)
                                              : std::numeric_limits<double>::infinity();
}

int kind_rank(EndpointKind k) { return static_cast<int>(k); }

bool endpoint_before(const Endpoint& a, const Endpoint& b) {
  if (a.kind != b.kind) return kind_rank(a.kind) < kind_rank(b.kind);
  for (Eigen::Index v = 0; v < a.x.size(); ++v)
    if (a.x(v).real() != b.x(v).real()) return a.x(v).real() < b.x(v).real();
  for (Eigen::Index v = 0; v < a.x.size(); ++v)
    if (a.x(v).imag() != b.x(v).imag()) return a.x(v).imag() < b.x(v).imag();
  return a.multiplicity < b.multiplicity;
}

// A point that several paths still reach after the careful pass, and where the Jacobian is far from well
// conditioned, is a multiple root: Newton places a double root only to about √ε, where the condition is near 1e8
// (a k-fold tangency of circles gives 1e7 … 1e9), below options.singular_condition; a regular solution is the end
// of one path only, and one that two paths jumped onto is well conditioned (counted as duplicate). Then the
// endpoints sorted and counted by kind.
void finish_endpoints(std::vector<Endpoint>& distinct, const ModesOptions& options, ModesSummary& summary) {
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
}

}  // namespace

ModesSummary solve_polynomial_system(const PolynomialSystem& system, const ModesOptions& options) {
  if (options.threads < 0 || options.threads > detail::kMaxThreads)
    throw Error("ModesOptions: threads must be from 0 (all cores) to 1000000, not " + std::to_string(options.threads));
  if (options.max_paths < 1)
    throw Error("ModesOptions: max_paths must be 1 or more, not " + std::to_string(options.max_paths));
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
  summary.total_degree = square.total_degree();
  const ChosenStart chosen = choose_start(square, options);
  summary.paths = chosen.start.paths;
  summary.start_system = chosen.name;
  if (summary.paths > options.max_paths) {
    summary.status = ModesStatus::kTooManyPaths;
    summary.message = (chosen.name == "total degree"
                           ? "the total degree is " + std::to_string(summary.paths) + " paths"
                           : "the start system (" + chosen.name + ") has " + std::to_string(summary.paths) + " paths") +
                      ", above the limit of " + std::to_string(options.max_paths) +
                      " (ModesOptions::max_paths, --max-paths)";
    return summary;
  }
  const CompiledSystem target(chosen.system, chosen.start.grouping);
  const int groups = chosen.start.grouping.groups;
  Homotopy homotopy{&target, &chosen.start, random.unit_complex(), Eigen::VectorXcd(n + groups)};
  for (int v = 0; v < n + groups; ++v) homotopy.patch(v) = random.unit_complex();

  // c paths meet at an end of winding number c: no more turns than paths
  const int max_winding = static_cast<int>(
      std::clamp<std::int64_t>(std::min<std::int64_t>(options.max_winding, summary.paths), 1, 1 << 20));
  // Every path, each into its own slot: the arithmetic of a path does not depend on which thread runs it.
  std::vector<PathEnd> ends(static_cast<std::size_t>(summary.paths));
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, summary.paths, 1), [&](const auto& range) {
      for (std::int64_t p = range.begin(); p != range.end(); ++p)
        ends[static_cast<std::size_t>(p)] = modes_detail::track_path(homotopy, p, max_winding);
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
    summary.failures.clear();
    auto fail = [&](std::size_t path, const std::string& why) {
      ++summary.failed_paths;
      summary.failures.emplace_back(static_cast<std::int64_t>(path), why);
    };
    for (std::size_t path = 0; path < ends.size(); ++path) {
      const PathEnd& e = ends[path];
      Endpoint point;
      if (!e.reached) {
        fail(path, e.failure);
        continue;
      }
      // At infinity when its homogenising coordinate is zero to the accuracy of its end: the end game's last two
      // estimates of X(0) apart, or rounding for a path tracked straight to t = 0.
      bool infinite = !(homotopy.finiteness(e.X) > std::max(kAtInfinity, 10.0 * e.accuracy));
      if (!infinite) {
        point.x = homotopy.affine(e.X);
        point.residual = modes_detail::refine_endpoint(original, point.x, &point.condition);
        if (!(inf_norm(point.x) < 1e8) || !point.x.allFinite()) {
          fail(path, "Newton on the equations goes off to infinity from its end");
          continue;
        }
        if (!(point.residual <= 1e-8)) {  // solves the squared-up system (or the path was lost), not the original
          fail(path, "its end solves none of the original equations to 1e-8 (residual " +
                         std::to_string(point.residual) + ")");
          continue;
        }
      }
      if (infinite) {
        point.kind = EndpointKind::kAtInfinity;
        Eigen::Index largest = 0;
        e.X.tail(n).cwiseAbs().maxCoeff(&largest);
        point.x = e.X.tail(n) / e.X(groups + largest);
        at_infinity_residual(target, chosen.start.grouping, e.X, point);
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
          ends[static_cast<std::size_t>(again[k])] = modes_detail::track_path(homotopy, again[k], max_winding, true);
      });
    });
    classify();
  }
  summary.retracked_paths = static_cast<int>(again.size());
  for (const PathEnd& e : ends) summary.end_game_paths += e.winding > 0;
  finish_endpoints(distinct, options, summary);
  summary.endpoints = std::move(distinct);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return summary;
}

}  // namespace phiq
