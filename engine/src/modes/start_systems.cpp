// The start systems of the homotopy (homotopy.hpp) and the homotopy itself. Total degree: G_i = x_i^{d_i} − x0^{d_i},
// Π d_i paths. Multi-homogeneous (Morgan and Sommese 1987; Wampler's linear-product start system): the variables
// split into groups, each equation of degree d_ij in group j, the paths the m-homogeneous Bézout number (the
// coefficient of Π α_j^{n_j} in Π_i Σ_j d_ij α_j), fewer than the total degree when the equations are of low degree
// in each group but high in all (bilinear systems: an eigenproblem's 2ⁿ become n). G_i = Π_j Π_k ℓ_ijk(X_j) with
// random linear forms: a generic member of the system's multi-homogeneous family, so that with the γ trick every
// isolated finite solution of F is the end of a path. Its roots: for each assignment of the equations to the groups
// (group j given n_j equations, each equation one group of nonzero degree) and each choice of one factor of each
// equation, one linear system per group.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include <Eigen/LU>

#include "modes/homotopy.hpp"

namespace phiq::modes_detail {

Grouping single_group(int variables) { return grouping_from(std::vector<int>(static_cast<std::size_t>(variables), 0)); }

Grouping grouping_from(const std::vector<int>& group_of) {
  Grouping g;
  g.group_of = group_of;
  g.groups = group_of.empty() ? 1 : *std::max_element(group_of.begin(), group_of.end()) + 1;
  g.members.assign(static_cast<std::size_t>(g.groups), {});
  for (std::size_t v = 0; v < group_of.size(); ++v)
    g.members[static_cast<std::size_t>(group_of[v])].push_back(static_cast<int>(v));
  return g;
}

std::vector<std::vector<int>> group_degrees(const PolynomialSystem& s, const Grouping& grouping) {
  std::vector<std::vector<int>> out;
  for (const Polynomial& p : s.equations) {
    std::vector<int> d(static_cast<std::size_t>(grouping.groups), 0);
    for (const PolynomialTerm& t : p.terms) {
      std::vector<int> k(static_cast<std::size_t>(grouping.groups), 0);
      for (std::size_t v = 0; v < t.exponent.size(); ++v)
        k[static_cast<std::size_t>(grouping.group_of[v])] += t.exponent[v];
      for (std::size_t j = 0; j < d.size(); ++j) d[j] = std::max(d[j], k[j]);
    }
    out.push_back(std::move(d));
  }
  return out;
}

namespace {

constexpr std::int64_t kSaturated = std::int64_t{1} << 62;

std::int64_t saturated_add(std::int64_t a, std::int64_t b) { return a > kSaturated - b ? kSaturated : a + b; }
std::int64_t saturated_mul(std::int64_t a, std::int64_t b) {
  return (b != 0 && a > kSaturated / b) ? kSaturated : a * b;
}

// Σ over the assignments of equations i … to groups with `left` places: Π degrees (weighted) or 1 (counting).
std::int64_t bezout_from(const std::vector<std::vector<int>>& degrees, std::size_t i, std::vector<int>& left,
                         bool weighted, std::map<std::pair<std::size_t, std::vector<int>>, std::int64_t>& memo) {
  if (i == degrees.size()) return 1;
  const auto key = std::make_pair(i, left);
  if (const auto found = memo.find(key); found != memo.end()) return found->second;
  std::int64_t sum = 0;
  for (std::size_t j = 0; j < left.size(); ++j) {
    if (left[j] == 0 || degrees[i][j] == 0) continue;
    --left[j];
    const std::int64_t rest = bezout_from(degrees, i + 1, left, weighted, memo);
    ++left[j];
    sum = saturated_add(sum, weighted ? saturated_mul(rest, degrees[i][j]) : rest);
  }
  memo[key] = sum;
  return sum;
}

void list_assignments(const std::vector<std::vector<int>>& degrees, std::size_t i, std::vector<int>& left,
                      std::vector<int>& current, std::vector<std::vector<int>>& out) {
  if (i == degrees.size()) {
    out.push_back(current);
    return;
  }
  for (std::size_t j = 0; j < left.size(); ++j) {
    if (left[j] == 0 || degrees[i][j] == 0) continue;
    --left[j], current[i] = static_cast<int>(j);
    list_assignments(degrees, i + 1, left, current, out);
    ++left[j];
  }
}

constexpr std::int64_t kMaxAssignments = 100000;  // start points listed by assignment; more: the grouping is not used

}  // namespace

std::int64_t multihomogeneous_bezout(const std::vector<std::vector<int>>& group_degree, const Grouping& grouping) {
  std::vector<int> left;
  for (const auto& m : grouping.members) left.push_back(static_cast<int>(m.size()));
  std::map<std::pair<std::size_t, std::vector<int>>, std::int64_t> memo;
  return bezout_from(group_degree, 0, left, true, memo);
}

bool make_start_system(const std::vector<std::vector<int>>& degrees, const Grouping& grouping, Random& random,
                       StartSystem& out) {
  out = StartSystem{};
  out.grouping = grouping;
  out.degrees = degrees;
  const std::size_t n = degrees.size();
  if (grouping.groups == 1) {
    out.paths = 1;
    for (const auto& d : degrees) out.paths = saturated_mul(out.paths, std::max(1, d[0]));
    out.assignments.assign(1, std::vector<int>(n, 0));
    out.first_path = {0};
    return true;
  }
  std::vector<int> left;
  for (const auto& m : grouping.members) left.push_back(static_cast<int>(m.size()));
  std::map<std::pair<std::size_t, std::vector<int>>, std::int64_t> memo;
  if (bezout_from(degrees, 0, left, false, memo) > kMaxAssignments) return false;
  std::vector<int> current(n, 0);
  list_assignments(degrees, 0, left, current, out.assignments);
  for (const auto& a : out.assignments) {
    out.first_path.push_back(out.paths);
    std::int64_t count = 1;
    for (std::size_t i = 0; i < n; ++i) count = saturated_mul(count, degrees[i][static_cast<std::size_t>(a[i])]);
    out.paths = saturated_add(out.paths, count);
  }
  out.linear_product = true;
  out.factors.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.factors[i].resize(static_cast<std::size_t>(grouping.groups));
    for (int j = 0; j < grouping.groups; ++j) {
      const auto size = static_cast<Eigen::Index>(grouping.members[static_cast<std::size_t>(j)].size() + 1);
      for (int k = 0; k < degrees[i][static_cast<std::size_t>(j)]; ++k) {
        Eigen::VectorXcd a(size);
        for (Eigen::Index c = 0; c < size; ++c) a(c) = random.unit_complex();
        out.factors[i][static_cast<std::size_t>(j)].push_back(std::move(a));
      }
    }
  }
  return true;
}

namespace {
// Group j's homogeneous coordinates in X: X(j), then X(groups + v) for its variables.
Eigen::VectorXcd group_part(const Grouping& g, const Eigen::VectorXcd& X, int j) {
  const auto& m = g.members[static_cast<std::size_t>(j)];
  Eigen::VectorXcd part(static_cast<Eigen::Index>(m.size() + 1));
  part(0) = X(j);
  for (std::size_t k = 0; k < m.size(); ++k) part(static_cast<Eigen::Index>(k + 1)) = X(g.groups + m[k]);
  return part;
}
Eigen::Index group_index(const Grouping& g, int j, Eigen::Index c) {
  return c == 0 ? j : g.groups + g.members[static_cast<std::size_t>(j)][static_cast<std::size_t>(c - 1)];
}
}  // namespace

Eigen::VectorXcd Homotopy::start(std::int64_t p) const {
  const StartSystem& s = *start_system;
  const Grouping& g = s.grouping;
  const int n = target->variables;
  Eigen::VectorXcd X(n + g.groups);
  if (!s.linear_product) {
    X(0) = 1.0;
    for (int i = 0; i < n; ++i) {
      const int d = std::max(1, s.degrees[static_cast<std::size_t>(i)][0]);
      const std::int64_t k = p % d;
      p /= d;
      X(i + 1) = std::polar(1.0, 2.0 * std::numbers::pi * static_cast<double>(k) / d);
    }
    return X / patch.dot(X);  // (dot conjugates its first argument: patch holds the conjugated a)
  }
  const auto which = std::upper_bound(s.first_path.begin(), s.first_path.end(), p) - s.first_path.begin() - 1;
  const std::vector<int>& assignment = s.assignments[static_cast<std::size_t>(which)];
  p -= s.first_path[static_cast<std::size_t>(which)];
  std::vector<int> factor(static_cast<std::size_t>(n), 0);
  for (int i = 0; i < n; ++i) {
    const int d =
        s.degrees[static_cast<std::size_t>(i)][static_cast<std::size_t>(assignment[static_cast<std::size_t>(i)])];
    factor[static_cast<std::size_t>(i)] = static_cast<int>(p % d);
    p /= d;
  }
  for (int j = 0; j < g.groups; ++j) {
    const auto size = static_cast<Eigen::Index>(g.members[static_cast<std::size_t>(j)].size() + 1);
    Eigen::MatrixXcd a(size, size);
    Eigen::VectorXcd b = Eigen::VectorXcd::Zero(size);
    Eigen::Index row = 0;
    for (int i = 0; i < n; ++i)
      if (assignment[static_cast<std::size_t>(i)] == j)
        a.row(row++) = s.factors[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]
                                [static_cast<std::size_t>(factor[static_cast<std::size_t>(i)])]
                                    .transpose();
    for (Eigen::Index c = 0; c < size; ++c) a(row, c) = std::conj(patch(group_index(g, j, c)));
    b(row) = 1.0;
    const Eigen::VectorXcd part = a.partialPivLu().solve(b);
    for (Eigen::Index c = 0; c < size; ++c) X(group_index(g, j, c)) = part(c);
  }
  return X;
}

void Homotopy::evaluate(const Eigen::VectorXcd& X, cd t, Eigen::VectorXcd& h, Eigen::MatrixXcd* hx,
                        Eigen::VectorXcd* ht) const {
  const StartSystem& s = *start_system;
  const Grouping& g = s.grouping;
  const int n = target->variables, m = g.groups;
  thread_local Eigen::VectorXcd f;
  thread_local Eigen::MatrixXcd jf;
  target->homogenised(X, f, hx ? &jf : nullptr);
  h.resize(n + m);
  if (hx) hx->setZero(n + m, n + m);
  if (ht) ht->resize(n + m);
  thread_local std::vector<cd> values;
  thread_local std::vector<std::pair<int, const Eigen::VectorXcd*>> forms;
  for (int i = 0; i < n; ++i) {
    cd value;
    if (!s.linear_product) {
      const int d = std::max(1, s.degrees[static_cast<std::size_t>(i)][0]);
      value = std::pow(X(i + 1), d) - std::pow(X(0), d);
      if (hx) {
        (*hx)(i, i + 1) += t * gamma * static_cast<double>(d) * std::pow(X(i + 1), d - 1);
        (*hx)(i, 0) -= t * gamma * static_cast<double>(d) * std::pow(X(0), d - 1);
      }
    } else {
      forms.clear(), values.clear();
      for (int j = 0; j < m; ++j)
        for (const Eigen::VectorXcd& a : s.factors[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]) {
          const Eigen::VectorXcd part = group_part(g, X, j);
          forms.emplace_back(j, &a), values.push_back(a.cwiseProduct(part).sum());  // aᵀ part, unconjugated
        }
      value = 1.0;
      for (const cd v : values) value *= v;
      if (hx)
        for (std::size_t k = 0; k < forms.size(); ++k) {
          cd others = t * gamma;
          for (std::size_t l = 0; l < forms.size(); ++l)
            if (l != k) others *= values[l];
          const Eigen::VectorXcd& a = *forms[k].second;
          for (Eigen::Index c = 0; c < a.size(); ++c) (*hx)(i, group_index(g, forms[k].first, c)) += others * a(c);
        }
    }
    h(i) = (1.0 - t) * f(i) + t * gamma * value;
    if (ht) (*ht)(i) = gamma * value - f(i);
    if (hx) hx->row(i) += (1.0 - t) * jf.row(i);
  }
  for (int j = 0; j < m; ++j) {
    cd sum = 0.0;
    const auto size = static_cast<Eigen::Index>(g.members[static_cast<std::size_t>(j)].size() + 1);
    for (Eigen::Index c = 0; c < size; ++c) {
      const Eigen::Index at = group_index(g, j, c);
      sum += std::conj(patch(at)) * X(at);
      if (hx) (*hx)(n + j, at) = std::conj(patch(at));
    }
    h(n + j) = sum - 1.0;
    if (ht) (*ht)(n + j) = 0.0;
  }
}

Eigen::VectorXcd Homotopy::affine(const Eigen::VectorXcd& X) const {
  const Grouping& g = start_system->grouping;
  Eigen::VectorXcd x(target->variables);
  for (int v = 0; v < target->variables; ++v) x(v) = X(g.groups + v) / X(g.group_of[static_cast<std::size_t>(v)]);
  return x;
}

double Homotopy::finiteness(const Eigen::VectorXcd& X) const {
  const Grouping& g = start_system->grouping;
  double ratio = 1.0;
  for (int j = 0; j < g.groups; ++j) {
    const Eigen::VectorXcd part = group_part(g, X, j);
    const double size = part.cwiseAbs().maxCoeff();
    ratio = std::min(ratio, size > 0.0 ? std::abs(part(0)) / size : 0.0);
  }
  return ratio;
}

}  // namespace phiq::modes_detail

namespace phiq {

std::int64_t multihomogeneous_bezout_number(const PolynomialSystem& system, const std::vector<int>& group_of) {
  if (static_cast<int>(group_of.size()) != system.variables)
    throw Error("multihomogeneous_bezout_number: " + std::to_string(group_of.size()) + " groups given for " +
                std::to_string(system.variables) + " variables");
  const modes_detail::Grouping g = modes_detail::grouping_from(group_of);
  for (const auto& m : g.members)
    if (m.empty()) throw Error("multihomogeneous_bezout_number: a group without variables");
  return modes_detail::multihomogeneous_bezout(modes_detail::group_degrees(system, g), g);
}

}  // namespace phiq
