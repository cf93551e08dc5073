// Polynomials and polynomial systems (phiq/modes.hpp): evaluation, degrees, PHCpack's input text, and the compiled
// form the path tracker evaluates (homotopy.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "modes/homotopy.hpp"

namespace phiq {

int Polynomial::degree() const {
  int d = 0;
  for (const PolynomialTerm& t : terms) {
    int k = 0;
    for (int e : t.exponent) k += e;
    d = std::max(d, k);
  }
  return d;
}

void PolynomialSystem::evaluate(const std::complex<double>* x, std::complex<double>* f) const {
  for (std::size_t i = 0; i < equations.size(); ++i) {
    std::complex<double> sum = 0.0;
    for (const PolynomialTerm& t : equations[i].terms) {
      std::complex<double> m = t.coefficient;
      for (int v = 0; v < variables; ++v)
        for (int k = 0; k < t.exponent[static_cast<std::size_t>(v)]; ++k) m *= x[v];
      sum += m;
    }
    f[i] = sum;
  }
}

std::int64_t PolynomialSystem::total_degree() const {
  constexpr std::int64_t kSaturated = std::int64_t{1} << 62;
  std::int64_t product = 1;
  for (const Polynomial& p : equations) {
    const std::int64_t d = std::max(1, p.degree());
    if (product > kSaturated / d) return kSaturated;
    product *= d;
  }
  return product;
}

const char* endpoint_kind_name(EndpointKind kind) {
  switch (kind) {
    case EndpointKind::kReal:
      return "real";
    case EndpointKind::kComplex:
      return "complex";
    case EndpointKind::kSingular:
      return "singular";
    case EndpointKind::kAtInfinity:
      return "at infinity";
    case EndpointKind::kFailed:
      return "failed";
  }
  return "failed";
}

const char* modes_method_name(ModesMethod method) {
  return method == ModesMethod::kBlocks ? "block by block" : "whole system";
}

namespace {
std::string phc_number(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17E", v);
  return buffer;
}
}  // namespace

std::string phc_input_text(const PolynomialSystem& system) {
  std::string text = std::to_string(system.equations.size());
  if (static_cast<int>(system.equations.size()) != system.variables)
    text.append(1, ' ').append(std::to_string(system.variables));
  text += '\n';
  // x1 … xn whatever the system's names: those of a model ("cos(psi3)") are no names phc reads
  // (every piece appended on its own: GCC 12 warns, -Wrestrict, a false positive, on a literal + std::string here)
  auto name = [](int v) { return std::string(1, 'x').append(std::to_string(v + 1)); };
  for (const Polynomial& p : system.equations) {
    std::string line;
    for (const PolynomialTerm& t : p.terms) {
      // (re + im*i) in full precision: phc reads 'i' as the imaginary unit
      std::string term = " + (";
      term += phc_number(t.coefficient.real());
      if (t.coefficient.imag() != 0.0) term.append(" + ").append(phc_number(t.coefficient.imag())).append("*i");
      term += ')';
      for (int v = 0; v < system.variables; ++v) {
        const int e = t.exponent[static_cast<std::size_t>(v)];
        if (e >= 1) term.append(1, '*').append(name(v));
        if (e > 1) term.append(1, '^').append(std::to_string(e));
      }
      line += term;
    }
    text += (line.empty() ? " 0" : line) + ";\n";
  }
  return text;
}

namespace modes_detail {

cd Random::unit_complex() { return std::polar(1.0, 2.0 * std::numbers::pi * uniform()); }

CompiledSystem::CompiledSystem(const PolynomialSystem& s, const Grouping& grouping)
    : variables(s.variables), groups(grouping.groups) {
  for (const Polynomial& p : s.equations) {
    const int d = p.degree();
    std::vector<int> in_group(static_cast<std::size_t>(groups), 0);
    for (const PolynomialTerm& t : p.terms) {
      if (static_cast<int>(t.exponent.size()) != variables)
        throw Error("polynomial system: a term has " + std::to_string(t.exponent.size()) + " exponents for " +
                    std::to_string(variables) + " variables");
      std::vector<int> k(static_cast<std::size_t>(groups), 0);
      for (int v = 0; v < variables; ++v) {
        if (t.exponent[static_cast<std::size_t>(v)] < 0) throw Error("polynomial system: a negative exponent");
        k[static_cast<std::size_t>(grouping.group_of[static_cast<std::size_t>(v)])] +=
            t.exponent[static_cast<std::size_t>(v)];
      }
      for (int j = 0; j < groups; ++j)
        in_group[static_cast<std::size_t>(j)] =
            std::max(in_group[static_cast<std::size_t>(j)], k[static_cast<std::size_t>(j)]);
    }
    std::vector<Term> terms;
    double largest = 0.0;
    for (const PolynomialTerm& t : p.terms) {
      Term c{t.coefficient, {}, {}};
      std::vector<int> k(static_cast<std::size_t>(groups), 0);
      for (int v = 0; v < variables; ++v) {
        const int e = t.exponent[static_cast<std::size_t>(v)];
        if (e > 0) c.factors.emplace_back(v, e);
        k[static_cast<std::size_t>(grouping.group_of[static_cast<std::size_t>(v)])] += e;
        max_power = std::max(max_power, e);
      }
      for (int j = 0; j < groups; ++j) {
        const int h = in_group[static_cast<std::size_t>(j)] - k[static_cast<std::size_t>(j)];
        if (h > 0) c.homogenising.emplace_back(j, h);
      }
      largest = std::max(largest, std::abs(t.coefficient));
      terms.push_back(std::move(c));
    }
    max_power = std::max(max_power, d);
    equations.push_back(std::move(terms));
    degree.push_back(d);
    group_degree.push_back(std::move(in_group));
    coefficient_scale.push_back(largest > 0.0 ? largest : 1.0);
  }
}

namespace {
// powers[v * (max + 1) + k] = X_v^k for the variables of `X` (size count)
void power_table(const Eigen::VectorXcd& X, int max, std::vector<cd>& powers) {
  const int count = static_cast<int>(X.size());
  powers.assign(static_cast<std::size_t>(count * (max + 1)), cd(1.0));
  for (int v = 0; v < count; ++v)
    for (int k = 1; k <= max; ++k)
      powers[static_cast<std::size_t>(v * (max + 1) + k)] =
          powers[static_cast<std::size_t>(v * (max + 1) + k - 1)] * X(v);
}
}  // namespace

// shared by affine() and homogenised(): `offset` is the number of homogenising coordinates X carries first
// (homogenised: the groups'), else 0
static void evaluate_compiled(const CompiledSystem& s, const Eigen::VectorXcd& X, bool homogeneous, Eigen::VectorXcd& f,
                              Eigen::MatrixXcd* jac) {
  const int offset = homogeneous ? s.groups : 0, stride = s.max_power + 1;
  thread_local std::vector<cd> powers;
  thread_local std::vector<std::pair<int, int>> all;  // a term's factors as (index into X, power)
  power_table(X, s.max_power, powers);
  auto P = [&](int v, int k) { return powers[static_cast<std::size_t>(v * stride + k)]; };
  const int rows = static_cast<int>(s.equations.size());
  f.setZero(rows);
  if (jac) jac->setZero(rows, s.variables + offset);
  for (int i = 0; i < rows; ++i) {
    for (const CompiledSystem::Term& t : s.equations[static_cast<std::size_t>(i)]) {
      all.clear();
      if (homogeneous) all.insert(all.end(), t.homogenising.begin(), t.homogenising.end());
      for (const auto& [v, e] : t.factors) all.emplace_back(v + offset, e);
      cd value = t.coefficient;
      for (const auto& [v, e] : all) value *= P(v, e);
      f(i) += value;
      if (!jac) continue;
      // each factor's derivative times the product of the others (recomputed: terms have few factors)
      for (const auto& [var, e] : all) {
        cd d = t.coefficient * static_cast<double>(e) * P(var, e - 1);
        for (const auto& [w, k] : all)
          if (w != var) d *= P(w, k);
        (*jac)(i, var) += d;
      }
    }
  }
}

void CompiledSystem::affine(const Eigen::VectorXcd& x, Eigen::VectorXcd& f, Eigen::MatrixXcd* jac) const {
  evaluate_compiled(*this, x, false, f, jac);
}

void CompiledSystem::homogenised(const Eigen::VectorXcd& X, Eigen::VectorXcd& f, Eigen::MatrixXcd* jac) const {
  evaluate_compiled(*this, X, true, f, jac);
}

}  // namespace modes_detail
}  // namespace phiq
