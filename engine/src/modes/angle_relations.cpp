// Rows linear in angles with rational ratios, solved modulo 2π as multiple-angle polynomials (AngleRelation in
// phiq/modes.hpp, model_rows.hpp). A gear between a driven wheel and another is eliminated as an affine row; one
// between angles a linkage turns (a geared five-bar driven elsewhere, a wheel on a rocker) is none, and no
// polynomial in (c, s) reproduces θ itself: but n_1 θ_1 + n_2 θ_2 = φ with integers n_k holds, modulo 2π, exactly
// where (c_1 + i s_1)^{n_1} (c_2 + i s_2)^{n_2} = e^{iφ}, and on the unit circles a negative power is the
// conjugate's. Real solutions of that one complex equation are the placements the gear admits; the whole turns the
// gear's own row needs are found afterwards (apply_relation_turns()).
#include <algorithm>
#include <cmath>
#include <complex>
#include <map>
#include <numbers>
#include <numeric>

#include "modes/homotopy.hpp"
#include "modes/model_rows.hpp"

namespace phiq::modes_detail {

namespace {

constexpr int kMaxRelationDegree = 24;  // the degree of the polynomial (each of its paths' factor)
constexpr int kMaxDenominator = 60;     // the ratios looked for: p/q with q up to this

using Terms = std::map<std::vector<int>, cd>;  // exponents → coefficient

Terms multiply(const Terms& a, const Terms& b) {
  Terms out;
  for (const auto& [ea, ca] : a)
    for (const auto& [eb, cb] : b) {
      std::vector<int> e = ea;
      for (std::size_t v = 0; v < e.size(); ++v) e[v] += eb[v];
      out[e] += ca * cb;
    }
  return out;
}

// (c + σ i s)^n with c variable v and s variable v + 1, by the binomial theorem.
Terms circle_power(int variables, int v, int n, double sigma) {
  Terms out;
  double binomial = 1.0;
  cd i_power = 1.0;
  for (int j = 0; j <= n; ++j) {
    std::vector<int> e(static_cast<std::size_t>(variables), 0);
    e[static_cast<std::size_t>(v)] = n - j, e[static_cast<std::size_t>(v + 1)] = j;
    out[e] += binomial * i_power;
    binomial = binomial * (n - j) / (j + 1);
    i_power *= cd(0.0, sigma);
  }
  return out;
}

// g = gcd(a, b) ≥ 0 and u, v with a u + b v = g.
long long extended_gcd(long long a, long long b, long long& u, long long& v) {
  long long u0 = 1, v0 = 0, u1 = 0, v1 = 1;
  while (b != 0) {
    const long long k = a / b;
    a -= k * b, std::swap(a, b);
    u0 -= k * u1, std::swap(u0, u1);
    v0 -= k * v1, std::swap(v0, v1);
  }
  if (a < 0) a = -a, u0 = -u0, v0 = -v0;
  u = u0, v = v0;
  return a;
}

}  // namespace

bool angle_relation(ModelRows& rows, Index r, const std::vector<Index>& free, const std::vector<int>& variable_of,
                    const Eigen::VectorXd& base, int variables, Random& random, AngleRelation& relation,
                    Polynomial& polynomial) {
  if (free.empty() || rows.surrogate(r)) return false;
  const Eigen::VectorXd unit = Eigen::VectorXd::Ones(base.size());  // per radian
  double value = 0.0;
  Eigen::VectorXd slope;
  if (!affine_row(rows, r, free, unit, base, random, value, slope)) return false;
  // the slopes as integers: the smallest denominator that makes every ratio to the largest whole
  const Eigen::Index largest = [&] {
    Eigen::Index k;
    slope.cwiseAbs().maxCoeff(&k);
    return k;
  }();
  std::vector<int> n;
  for (int q = 1; q <= kMaxDenominator && n.empty(); ++q) {
    std::vector<int> candidate;
    for (Eigen::Index k = 0; k < slope.size(); ++k) {
      const double x = q * slope(k) / std::abs(slope(largest));
      if (!(std::abs(x - std::round(x)) <= 1e-9 * q)) break;
      candidate.push_back(static_cast<int>(std::lround(x)));
    }
    if (candidate.size() == static_cast<std::size_t>(slope.size())) n = candidate;
  }
  if (n.empty()) return false;
  int divisor = 0, positive = 0, negative = 0;
  for (int x : n) divisor = std::gcd(divisor, x);
  for (int& x : n) x /= divisor, (x > 0 ? positive : negative) += std::abs(x);
  if (std::max(positive, negative) > kMaxRelationDegree) return false;
  // row = value + Σ slope_k (θ_k − base_k) with slope = λ n: Σ n_k θ_k = (Σ slope_k base_k − value) / λ
  const double lambda = slope(largest) / n[static_cast<std::size_t>(largest)];
  double phase = -value / lambda;
  for (std::size_t k = 0; k < free.size(); ++k) phase += n[k] * base(free[k]);
  Terms left{{std::vector<int>(static_cast<std::size_t>(variables), 0), cd(1.0)}};
  Terms right{{std::vector<int>(static_cast<std::size_t>(variables), 0), -std::polar(1.0, phase)}};
  for (std::size_t k = 0; k < free.size(); ++k) {
    const int v = variable_of[static_cast<std::size_t>(free[k])];
    if (n[k] > 0) left = multiply(left, circle_power(variables, v, n[k], 1.0));
    if (n[k] < 0) right = multiply(right, circle_power(variables, v, -n[k], -1.0));
  }
  polynomial.terms.clear();
  for (const Terms* side : {&left, &right})
    for (const auto& [e, c] : *side)
      if (std::abs(c) > 1e-14) polynomial.terms.push_back({c, e});
  relation = AngleRelation{r, free, n, phase};
  return true;
}

void apply_relation_turns(const AngleRelation& relation, Eigen::VectorXd& q) {
  // Σ n_k θ_k − phase = 2π K; whole turns m_k with Σ n_k m_k = −K put it to 0 (gcd of the n_k is 1)
  double sum = -relation.phase;
  for (std::size_t k = 0; k < relation.angles.size(); ++k) sum += relation.multiples[k] * q(relation.angles[k]);
  const long long turns = std::llround(sum / (2.0 * std::numbers::pi));
  if (turns == 0) return;
  // coefficients c_k with Σ n_k c_k = 1, built one angle at a time
  std::vector<long long> c(relation.angles.size(), 0);
  long long g = relation.multiples[0];
  c[0] = 1;
  for (std::size_t k = 1; k < c.size(); ++k) {
    long long u = 0, v = 0;
    g = extended_gcd(g, relation.multiples[k], u, v);
    for (std::size_t j = 0; j < k; ++j) c[j] *= u;
    c[k] = v;
  }
  if (g < 0) g = -g, std::for_each(c.begin(), c.end(), [](long long& x) { x = -x; });
  if (g != 1) return;  // cannot be: the multiples were divided by their gcd
  for (std::size_t k = 0; k < c.size(); ++k)
    q(relation.angles[k]) -= 2.0 * std::numbers::pi * static_cast<double>(turns * c[k]);
}

}  // namespace phiq::modes_detail
