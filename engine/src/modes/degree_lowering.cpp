// lowered_degrees() (homotopy.hpp): a square system whose equations' degrees are lowered by adding to each
// polynomial multiples of the equations before it, so that its highest-degree form cancels. The paths of the
// total-degree homotopy are the product of the degrees, and a mechanism's rows share their highest forms: a body's
// Euler parameters make every distance row's quartic part |p|² (e·e)², a multiple of the normalisation's e·e (so the
// row becomes cubic), and the rows' cubic parts 2 t·R(e) p_i span only three dimensions (so three of six become
// quadratic): the Stewart–Gough platform's 4⁶ · 2 = 8192 paths become 3³ · 2³ · 2 = 432.
//
// Exact: the new system is T F with T unit lower triangular (each equation plus polynomial multiples of earlier
// ones), whose inverse is polynomial too, so the two systems generate the same ideal and have the same finite
// solutions with the same multiplicities (only the solutions at infinity, and so the paths that end there, change).
// A reduction is accepted only when the least-squares multipliers cancel the highest form to 1e-10 of its size
// (the fitted rows' own accuracy is 1e-9, find_polynomial_system()); the remainder at that level is dropped as
// rounding. Every endpoint is refined and checked on the original equations (solve_polynomial_system()).
#include <algorithm>
#include <map>
#include <vector>

#include <Eigen/QR>

#include "modes/homotopy.hpp"

namespace phiq::modes_detail {

namespace {

using Exponent = std::vector<int>;
using Terms = std::map<Exponent, cd>;

int exponent_degree(const Exponent& e) {
  int d = 0;
  for (int k : e) d += k;
  return d;
}

Terms lowering_terms(const Polynomial& p) {
  Terms t;
  for (const PolynomialTerm& term : p.terms) t[term.exponent] += term.coefficient;
  return t;
}

int lowering_degree(const Terms& t) {
  int d = 0;
  for (const auto& [e, c] : t)
    if (c != 0.0) d = std::max(d, exponent_degree(e));
  return d;
}

// Every monomial of degree d in the variables `vars` (exponents over all `n` variables).
void lowering_monomials(const std::vector<int>& vars, int n, int d, std::size_t at, Exponent& current,
                        std::vector<Exponent>& out) {
  if (at + 1 == vars.size() || d == 0) {
    if (at < vars.size()) current[static_cast<std::size_t>(vars[at])] = d;
    out.push_back(current);
    if (at < vars.size()) current[static_cast<std::size_t>(vars[at])] = 0;
    return;
  }
  for (int e = d; e >= 0; --e) {
    current[static_cast<std::size_t>(vars[at])] = e;
    lowering_monomials(vars, n, d - e, at + 1, current, out);
  }
  current[static_cast<std::size_t>(vars[at])] = 0;
}

constexpr double kCancelled = 1e-10;       // a highest form cancelled to this fraction of its size is gone
constexpr std::size_t kMaxCells = 200000;  // rows × columns of one least-squares problem (a fraction of a second)

// One reduction of f's highest form (degree d) by the earlier equations `before` times monomials in the variables
// of that form: true, and f replaced, when it cancels.
bool lower_once(Terms& f, const std::vector<Terms>& before, int n) {
  const int d = lowering_degree(f);
  if (d <= 1) return false;
  std::vector<int> vars;  // the variables of f's highest form
  std::vector<bool> in_top(static_cast<std::size_t>(n), false);
  double top_size = 0.0;
  for (const auto& [e, c] : f) {
    if (exponent_degree(e) != d || c == 0.0) continue;
    top_size = std::max(top_size, std::abs(c));
    for (int v = 0; v < n; ++v)
      if (e[static_cast<std::size_t>(v)] > 0) in_top[static_cast<std::size_t>(v)] = true;
  }
  for (int v = 0; v < n; ++v)
    if (in_top[static_cast<std::size_t>(v)]) vars.push_back(v);
  // candidate products μ · g: g's highest form in those variables only, μ a monomial in them
  std::vector<std::pair<std::size_t, Exponent>> columns;
  for (std::size_t g = 0; g < before.size(); ++g) {
    const int dg = lowering_degree(before[g]);
    if (dg < 1 || dg > d) continue;
    bool inside = true;
    for (const auto& [e, c] : before[g])
      if (exponent_degree(e) == dg && c != 0.0)
        for (int v = 0; v < n; ++v)
          inside = inside && (e[static_cast<std::size_t>(v)] == 0 || in_top[static_cast<std::size_t>(v)]);
    if (!inside) continue;
    std::vector<Exponent> mu;
    Exponent current(static_cast<std::size_t>(n), 0);
    lowering_monomials(vars, n, d - dg, 0, current, mu);
    for (Exponent& m : mu) columns.emplace_back(g, std::move(m));
  }
  if (columns.empty()) return false;
  std::vector<Exponent> rows;
  Exponent current(static_cast<std::size_t>(n), 0);
  lowering_monomials(vars, n, d, 0, current, rows);
  if (rows.size() * columns.size() > kMaxCells) return false;
  std::map<Exponent, Eigen::Index> row_of;
  for (std::size_t r = 0; r < rows.size(); ++r) row_of[rows[r]] = static_cast<Eigen::Index>(r);
  Eigen::MatrixXcd a =
      Eigen::MatrixXcd::Zero(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(columns.size()));
  Eigen::VectorXcd b = Eigen::VectorXcd::Zero(a.rows());
  for (const auto& [e, c] : f)
    if (exponent_degree(e) == d) b(row_of.at(e)) = c;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const Terms& g = before[columns[k].first];
    const int dg = lowering_degree(g);
    for (const auto& [e, c] : g) {
      if (exponent_degree(e) != dg) continue;
      Exponent product = e;
      for (int v = 0; v < n; ++v)
        product[static_cast<std::size_t>(v)] += columns[k].second[static_cast<std::size_t>(v)];
      a(row_of.at(product), static_cast<Eigen::Index>(k)) += c;
    }
  }
  const Eigen::VectorXcd q = a.colPivHouseholderQr().solve(b);
  if (!q.allFinite() || !((a * q - b).cwiseAbs().maxCoeff() <= kCancelled * top_size)) return false;
  Terms reduced = f;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const cd m = q(static_cast<Eigen::Index>(k));
    if (m == 0.0) continue;
    for (const auto& [e, c] : before[columns[k].first]) {
      Exponent product = e;
      for (int v = 0; v < n; ++v)
        product[static_cast<std::size_t>(v)] += columns[k].second[static_cast<std::size_t>(v)];
      reduced[product] -= m * c;
    }
  }
  double largest = 0.0;
  for (const auto& [e, c] : reduced) largest = std::max(largest, std::abs(c));
  Terms out;
  for (const auto& [e, c] : reduced)  // the highest form is gone; rounding of a cancelled term is no term
    if (exponent_degree(e) < d && std::abs(c) > 1e-13 * largest) out[e] = c;
  if (out.empty()) return false;  // f was a combination of the others: leave it (the system is degenerate)
  f = std::move(out);
  return true;
}

}  // namespace

PolynomialSystem lowered_degrees(const PolynomialSystem& square) {
  const int n = square.variables;
  std::vector<std::size_t> order(square.equations.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  // lowest degree first: the normalisations and circles reduce the rows after them
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return square.equations[a].degree() < square.equations[b].degree();
  });
  std::vector<Terms> done;
  std::vector<Terms> lowered(square.equations.size());
  for (std::size_t i : order) {
    Terms f = lowering_terms(square.equations[i]);
    while (lower_once(f, done, n)) {
    }
    done.push_back(f);
    lowered[i] = std::move(f);
  }
  PolynomialSystem out{square.variables, square.names, {}};
  for (const Terms& t : lowered) {
    Polynomial p;
    for (const auto& [e, c] : t)
      if (c != 0.0) p.terms.push_back({c, e});
    out.equations.push_back(std::move(p));
  }
  return out;
}

}  // namespace phiq::modes_detail
