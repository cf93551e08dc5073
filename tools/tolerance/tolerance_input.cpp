// The toleranced parameters, their covariance and the samples drawn from it (tolerance_input.hpp).
#include "tolerance_input.hpp"

#include <charconv>
#include <cmath>
#include <set>

#include "phiq/csv_compare.hpp"
#include "phiq/text.hpp"
#include "phiq/types.hpp"

namespace phiq::tolerance {

std::pair<std::string, double> parse_named_value(const std::string& option, const std::string& text) {
  const std::size_t eq = text.find('=');
  auto fail = [&](const std::string& why) { throw Error(option + " " + text + ": " + why); };
  if (eq == std::string::npos || eq == 0) fail("expected NAME=VALUE (a parameter of the scene and a number)");
  const std::string value = text.substr(eq + 1);
  double v = 0.0;
  const char* first = value.data() + (!value.empty() && value[0] == '+');
  const auto [end, ec] = std::from_chars(first, value.data() + value.size(), v);
  if (value.empty() || ec != std::errc() || end != value.data() + value.size()) fail("'" + value + "' is not a number");
  if (!std::isfinite(v)) fail("the value is not finite");
  return {text.substr(0, eq), v};
}

Tolerance parse_tolerance(const std::string& option, const std::string& text) {
  const auto [name, v] = parse_named_value(option, text);
  if (!(v > 0.0))
    throw Error(option + " " + text + ": " +
                (option == "--limit" ? "the limit must be positive (uniform on [p - l, p + l])"
                                     : "the standard deviation must be positive"));
  Tolerance t;
  t.name = name;
  t.distribution = option == "--limit" ? Distribution::kUniform : Distribution::kNormal;
  t.spread = v;
  return t;
}

Eigen::MatrixXd cholesky(const Eigen::MatrixXd& a, const std::vector<std::string>& names) {
  const Eigen::Index n = a.rows();
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    double d = a(j, j);
    for (Eigen::Index k = 0; k < j; ++k) d -= l(j, k) * l(j, k);
    // a pivot at the rounding level of the diagonal is no better than zero: Σ is then singular for our purpose
    if (!(d > 1e-14 * std::fabs(a(j, j))) || !(a(j, j) > 0.0))
      throw Error("not positive definite: the Cholesky factorisation fails at parameter " +
                  names[static_cast<std::size_t>(j)] + " (pivot " + shortest(d) +
                  "; a variance must be positive and a correlation strictly between -1 and 1)");
    l(j, j) = std::sqrt(d);
    for (Eigen::Index i = j + 1; i < n; ++i) {
      double s = a(i, j);
      for (Eigen::Index k = 0; k < j; ++k) s -= l(i, k) * l(j, k);
      l(i, j) = s / l(j, j);
    }
  }
  return l;
}

Covariance read_covariance(const std::string& path) {
  const CsvTable table = read_csv_table(path);  // throws "PATH: ..." for what is not a CSV of numbers
  auto fail = [&](const std::string& why) { throw Error(path + ": " + why); };
  Covariance c;
  c.names = table.columns;
  const std::size_t n = c.names.size();
  if (table.rows.size() != n)
    fail("a covariance needs one row per parameter of its header (" + std::to_string(n) + "), not " +
         std::to_string(table.rows.size()));
  c.matrix.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  double largest = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const double v = table.rows[i][j];
      if (!std::isfinite(v))
        fail("row " + std::to_string(i + 2) + " (" + c.names[i] + "), column " + c.names[j] + ": not a finite number");
      c.matrix(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = v;
      largest = std::max(largest, std::fabs(v));
    }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const double a = c.matrix(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
      const double b = c.matrix(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i));
      if (std::fabs(a - b) > 1e-12 * largest)
        fail("not symmetric: (" + c.names[i] + ", " + c.names[j] + ") = " + shortest(a) + " but (" + c.names[j] + ", " +
             c.names[i] + ") = " + shortest(b));
    }
  try {
    (void)cholesky(c.matrix, c.names);
  } catch (const Error& e) {
    fail(e.what());
  }
  return c;
}

ParameterSpread parameter_spread(const std::vector<Tolerance>& options, const Covariance* covariance) {
  ParameterSpread s;
  std::set<std::string> seen;
  auto add = [&](const Tolerance& t, const std::string& where) {
    if (!seen.insert(t.name).second) throw Error(where + ": parameter " + t.name + " is given more than once");
    s.parameters.push_back(t);
  };
  if (covariance)
    for (const std::string& name : covariance->names) {
      Tolerance t;
      t.name = name, t.from_covariance = true;
      add(t, "--covariance");
    }
  for (const Tolerance& t : options) add(t, t.distribution == Distribution::kUniform ? "--limit" : "--sd");
  const auto n = static_cast<Eigen::Index>(s.parameters.size());
  s.sigma = Eigen::MatrixXd::Zero(n, n);
  const Eigen::Index block = covariance ? covariance->matrix.rows() : 0;
  if (block) s.sigma.topLeftCorner(block, block) = covariance->matrix;
  for (Eigen::Index j = block; j < n; ++j) {
    const Tolerance& t = s.parameters[static_cast<std::size_t>(j)];
    const double sd = t.distribution == Distribution::kUniform ? t.spread / std::sqrt(3.0) : t.spread;
    s.sigma(j, j) = sd * sd;
  }
  std::vector<std::string> names;
  for (const Tolerance& t : s.parameters) names.push_back(t.name);
  s.factor = cholesky(s.sigma, names);
  return s;
}

double NormalStream::uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

double NormalStream::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = 1.0 - uniform();  // (0, 1]: the logarithm stays finite
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double a = 2.0 * M_PI * u2;
  spare_ = r * std::sin(a);
  has_spare_ = true;
  return r * std::cos(a);
}

Eigen::MatrixXd sample_offsets(const ParameterSpread& spread, long samples, std::uint64_t seed) {
  NormalStream stream(seed);
  const auto n = static_cast<Eigen::Index>(spread.parameters.size());
  Eigen::MatrixXd offsets(samples, n);
  Eigen::VectorXd z(n);
  for (long k = 0; k < samples; ++k) {
    for (Eigen::Index j = 0; j < n; ++j)
      z(j) = spread.parameters[static_cast<std::size_t>(j)].distribution == Distribution::kUniform
                 ? std::sqrt(3.0) * (2.0 * stream.uniform() - 1.0)
                 : stream.normal();
    offsets.row(k) = (spread.factor.triangularView<Eigen::Lower>() * z).transpose();
  }
  return offsets;
}

}  // namespace phiq::tolerance
