// find_polynomial_system() (phiq/modes.hpp): the model's rows recovered as polynomials from their evaluations in
// double. The constraint kinds evaluate only in double (residual(q, t, φ)); rather than a second, templated copy of
// every kind, each row is fitted: it reads few coordinates (its Jacobian pattern), so the coefficients of every
// monomial up to degree d in them are found by least squares on random points and the fit is accepted only when it
// reproduces the row on fresh points to rounding. Angles enter through (c, s) = (cos θ, sin θ) on the unit circle,
// in the normal form modulo c² + s² = 1 (s to the power 0 or 1), where the fit is unique.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/QR>

#include "modes/homotopy.hpp"
#include "modes/model_rows.hpp"
#include "phiq/text.hpp"

namespace phiq {

namespace {

using modes_detail::ModelRows;
using modes_detail::Random;

// One unknown of a row: coordinate j, as a scaled variable (angle false) or as the pair (c, s) (angle true).
struct RowCoordinate {
  Index coordinate;
  bool angle;
  int variable;  // its variable in the system (c for an angle; s is variable + 1)
};

// Every exponent vector over `width` local variables with total degree ≤ d, the s of each angle pair (flagged in
// `second_of_pair`) at most 1 and, where `caps` is not empty, each variable's group (a scaled coordinate, or the pair
// (c, s) of an angle, whose exponents add up) at most its cap.
void monomials(int width, const std::vector<bool>& second_of_pair, const std::vector<int>& caps,
               std::vector<std::vector<int>>& out, std::vector<int>& current, int at, int left) {
  if (at == width) {
    out.push_back(current);
    return;
  }
  const std::size_t a = static_cast<std::size_t>(at);
  int top = second_of_pair[a] ? std::min(1, left) : left;
  if (!caps.empty()) top = std::min(top, caps[a] - (second_of_pair[a] ? current[a - 1] : 0));
  for (int e = 0; e <= top; ++e) {
    current[a] = e;
    monomials(width, second_of_pair, caps, out, current, at + 1, left - e);
  }
  current[a] = 0;
}

constexpr int kMaxMonomials = 1500;     // a row of more terms than this is refused (fitting it would take minutes)
constexpr double kFitTolerance = 1e-9;  // relative to the row's largest sampled value

// c² + s² − 1 = 0 for every free angle coordinate (angle[j]) of `out`'s system.
void add_circle_equations(const std::vector<bool>& angle, ModelPolynomials& out) {
  PolynomialSystem& system = out.system;
  const int nv = system.variables;
  for (std::size_t j = 0; j < angle.size(); ++j) {
    const int v = out.variable_of[j];
    if (v < 0 || !angle[j]) continue;
    Polynomial circle;
    std::vector<int> e(static_cast<std::size_t>(nv), 0);
    circle.terms.push_back({-1.0, e});
    e[static_cast<std::size_t>(v)] = 2;
    circle.terms.push_back({1.0, e});
    e[static_cast<std::size_t>(v)] = 0, e[static_cast<std::size_t>(v + 1)] = 2;
    circle.terms.push_back({1.0, e});
    system.equations.push_back(std::move(circle));
  }
}

// Row r as an angle relation (model_rows.hpp) when it is linear in the free angles it reads (`reads`) alone: no
// polynomial in (c, s) reproduces it, a multiple-angle one holds it modulo 2π. Appends the equation and the relation.
bool add_angle_relation(ModelRows& eval, Index r, const std::vector<RowCoordinate>& reads, const Eigen::VectorXd& base,
                        Random& random, ModelPolynomials& out) {
  std::vector<Index> free;
  bool all_angles = !reads.empty();
  for (const RowCoordinate& c : reads) free.push_back(c.coordinate), all_angles = all_angles && c.angle;
  AngleRelation relation;
  Polynomial p;
  if (!all_angles ||
      !modes_detail::angle_relation(eval, r, free, out.variable_of, base, out.system.variables, random, relation, p))
    return false;
  out.system.equations.push_back(std::move(p));
  out.angle_relations.push_back(std::move(relation));
  return true;
}

}  // namespace

Eigen::VectorXd ModelPolynomials::coordinates(const Eigen::VectorXcd& x) const {
  Eigen::VectorXd q = origin;
  for (std::size_t j = 0; j < variable_of.size(); ++j) {
    const Eigen::Index jj = static_cast<Eigen::Index>(j);
    if (variable_of[j] < 0) {
      q(jj) = fixed[j];
    } else if (system.names[static_cast<std::size_t>(variable_of[j])].rfind("cos(", 0) == 0) {
      const double angle = std::atan2(x(variable_of[j] + 1).real(), x(variable_of[j]).real());
      q(jj) = angle + 2.0 * std::numbers::pi * std::round((origin(jj) - angle) / (2.0 * std::numbers::pi));
    } else {
      q(jj) = origin(jj) + scale(jj) * x(variable_of[j]).real();
    }
  }
  for (const AngleRelation& relation : angle_relations) modes_detail::apply_relation_turns(relation, q);
  return q;
}

namespace {

// The time's checks, before the fit blames a constraint for it: finite (else every driver is "not polynomial"),
// within the drivers' domain, and no row taken by it beyond what doubles resolve of its coordinates at the initial
// positions: not finite, or above 1e11 times its scale (its rounding 1e-5 of a unit; a decade below where a unit
// step of a coordinate changes the row by less than the 1e-12 of its size that affine_row() resolves) where it is
// not at the time-domain point nearest 0. That is a law that overflows or runs away (a linear driver at t = 1e308
// or 1e20), which the fit would call not polynomial, or whose paths would all fail.
void check_time(const Model& model, double t) {
  if (!std::isfinite(t)) throw Error("ModesOptions: time " + shortest(t) + " is not finite");
  if (t < model.time_domain_begin() || t > model.time_domain_end())
    throw Error("ModesOptions: driver '" + model.time_domain_limiter() + "' is not defined at t = " + shortest(t));
  const double reference = std::clamp(0.0, model.time_domain_begin(), model.time_domain_end());
  const Eigen::VectorXd q = model.initial_positions();
  std::vector<double> at_t(static_cast<std::size_t>(model.num_equations())), at_reference(at_t.size());
  model.residual(q.data(), t, at_t.data());
  model.residual(q.data(), reference, at_reference.data());
  for (std::size_t r = 0; r < at_t.size(); ++r) {
    const double limit = 1e11 * model.tolerance_scales().row_scale(static_cast<Index>(r));
    if (std::abs(at_t[r]) <= limit || !(std::abs(at_reference[r]) <= limit)) continue;
    throw Error("ModesOptions: constraint '" +
                model.constraints()[static_cast<std::size_t>(model.constraint_of_row(static_cast<Index>(r)))].name +
                "' is " + shortest(at_t[r]) + " at t = " + shortest(t) + " at the initial positions (" +
                shortest(at_reference[r]) + " at t = " + shortest(reference) +
                "): its law runs beyond what doubles resolve of its coordinates there");
  }
}

// Above this many monomials of one degree, a row's fit first finds each read coordinate's own degree and fits only
// the monomials those allow (a spatial chain's row is a product of one pair (c, s) per joint: of degree 1 in each,
// 3^k monomials against the C(2k + d, d) of every degree-d one). Smaller rows fit every monomial, which costs less
// than the probes.
constexpr std::size_t kBoundDegreesAbove = 64;

// Row r in the local variables of the coordinates it reads (`reads`: a scaled variable, or the pair (c, s) of an
// angle), fitted by least squares on random points and accepted when it reproduces the row on fresh points to
// kFitTolerance of the largest value sampled.
class RowFitter {
 public:
  enum class Result { kFitted, kVanishes, kNotPolynomial };

  RowFitter(ModelRows& eval, Index r, const std::vector<RowCoordinate>& reads, const std::vector<bool>& second,
            const ModelPolynomials& out, const Eigen::VectorXd& base, Random& random, double row_scale)
      : eval_(eval),
        r_(r),
        reads_(reads),
        second_(second),
        out_(out),
        q_(base),
        random_(random),
        row_scale_(row_scale),
        width_(static_cast<int>(second.size())) {}

  // The lowest degree ≤ max_degree at which the row fits, its monomials in `basis` and their coefficients.
  Result fit(int max_degree, std::vector<std::vector<int>>& basis, Eigen::VectorXd& coefficients) {
    std::vector<int> caps;  // each local variable's group's degree, once the monomials grow past kBoundDegreesAbove
    int highest = 0, total = 0;
    for (int d = (width_ == 0 ? 0 : 1); d <= max_degree; ++d) {
      basis.clear();
      std::vector<int> current(static_cast<std::size_t>(width_), 0);
      monomials(width_, second_, caps, basis, current, 0, d);
      if (caps.empty() && basis.size() > kBoundDegreesAbove) {
        if (!group_degrees(max_degree, caps, highest, total)) return Result::kNotPolynomial;
        // no polynomial of total degree below the highest read's has it; at the degrees' sum the caps allow all
        d = std::clamp(d, highest, total);
        basis.clear();
        monomials(width_, second_, caps, basis, current, 0, d);
      }
      if (basis.size() > static_cast<std::size_t>(kMaxMonomials)) return Result::kNotPolynomial;
      switch (fit_basis(basis, -1, coefficients)) {
        case Fit::kFits:
          return Result::kFitted;
        case Fit::kVanishes:
          return Result::kVanishes;
        case Fit::kNotFinite:
          return Result::kNotPolynomial;
        case Fit::kNoFit:
          if (!caps.empty() && d >= total) return Result::kNotPolynomial;  // the caps' whole box did not reproduce it
          continue;
      }
    }
    return Result::kNotPolynomial;
  }

 private:
  enum class Fit { kFits, kVanishes, kNoFit, kNotFinite };

  // One sample: the local variables of read `only` (every read when only < 0) drawn afresh, angles uniformly on the
  // circle and scaled variables in [−1, 1], the others kept in `local` and q_; the row there.
  double sample(Eigen::VectorXd& local, int only) {
    int k = 0;
    for (std::size_t g = 0; g < reads_.size(); ++g) {
      const RowCoordinate& c = reads_[g];
      const bool draw = only < 0 || static_cast<std::size_t>(only) == g;
      if (c.angle) {
        if (draw) {
          const double theta = std::numbers::pi * random_.symmetric();
          local(k) = std::cos(theta), local(k + 1) = std::sin(theta);
          q_(c.coordinate) = theta;
        }
        k += 2;
      } else {
        if (draw) {
          local(k) = random_.symmetric();
          q_(c.coordinate) = out_.origin(c.coordinate) + out_.scale(c.coordinate) * local(k);
        }
        ++k;
      }
    }
    return eval_.row(q_, r_);
  }

  // The design matrix of `basis` at `points` samples (of read `only`, from local_ and q_ as they are) and the row.
  bool design(const std::vector<std::vector<int>>& basis, int points, int only, Eigen::MatrixXd& a,
              Eigen::VectorXd& b) {
    const int count = static_cast<int>(basis.size());
    a.resize(points, count), b.resize(points);
    Eigen::VectorXd local = only < 0 ? Eigen::VectorXd(width_) : local_;
    for (int i = 0; i < points; ++i) {
      b(i) = sample(local, only);
      for (int k = 0; k < count; ++k) {
        double v = 1.0;
        for (int w = 0; w < width_; ++w)
          for (int e = 0; e < basis[static_cast<std::size_t>(k)][static_cast<std::size_t>(w)]; ++e) v *= local(w);
        a(i, k) = v;
      }
    }
    return b.allFinite();
  }

  // Least squares over `basis` on 2·count + 8 samples, checked on count + 8 fresh ones. Its monomials in the normal
  // form are independent functions, so the design has full column rank at random points: Householder QR without
  // pivoting, which Eigen blocks (its column-pivoting QR is not).
  Fit fit_basis(const std::vector<std::vector<int>>& basis, int only, Eigen::VectorXd& coefficients) {
    const int count = static_cast<int>(basis.size());
    Eigen::MatrixXd a, a2;
    Eigen::VectorXd b, b2;
    if (!design(basis, 2 * count + 8, only, a, b)) return Fit::kNotFinite;
    coefficients = a.householderQr().solve(b);
    if (!design(basis, count + 8, only, a2, b2)) return Fit::kNotFinite;
    const double size = std::max(b.cwiseAbs().maxCoeff(), b2.cwiseAbs().maxCoeff());
    const double error = (a2 * coefficients - b2).cwiseAbs().maxCoeff();
    if (size <= 1e-12 * row_scale_) return Fit::kVanishes;  // holds wherever the fixed ones put it: no equation
    return error <= kFitTolerance * size || size == 0.0 ? Fit::kFits : Fit::kNoFit;
  }

  // Each read's degree in the row at one random point of the others (the degree of a polynomial in one group of
  // variables, everywhere but on a set of measure zero): the lowest whose monomials in that group alone reproduce
  // the row along it. Sets `caps` per local variable, the highest and their sum; false when a read has none ≤
  // max_degree (nor has the row, then).
  bool group_degrees(int max_degree, std::vector<int>& caps, int& highest, int& total) {
    local_.resize(width_);
    sample(local_, -1);
    const Eigen::VectorXd anchor = q_;
    std::vector<int> caps_of(static_cast<std::size_t>(width_), 0);
    int k = 0;
    for (std::size_t g = 0; g < reads_.size(); ++g) {
      const int size = reads_[g].angle ? 2 : 1;
      int degree = -1;
      for (int d = 0; d <= max_degree && degree < 0; ++d) {
        std::vector<int> only_here(static_cast<std::size_t>(width_), 0), current(only_here.size(), 0);
        for (int i = k; i < k + size; ++i) only_here[static_cast<std::size_t>(i)] = d;
        std::vector<std::vector<int>> basis;
        monomials(width_, second_, only_here, basis, current, 0, d);
        Eigen::VectorXd coefficients;
        const Fit f = fit_basis(basis, static_cast<int>(g), coefficients);
        q_ = anchor;
        if (f == Fit::kNotFinite) return false;
        if (f != Fit::kNoFit) degree = d;
      }
      if (degree < 0) return false;
      for (int i = k; i < k + size; ++i) caps_of[static_cast<std::size_t>(i)] = degree;
      highest = std::max(highest, degree), total += degree;
      k += size;
    }
    caps = std::move(caps_of);
    return true;
  }

  ModelRows& eval_;
  Index r_;
  const std::vector<RowCoordinate>& reads_;
  const std::vector<bool>& second_;
  const ModelPolynomials& out_;
  Eigen::VectorXd q_;
  Eigen::VectorXd local_;  // the point the group probes hold the other reads at (empty otherwise)
  Random& random_;
  double row_scale_;
  int width_;
};

}  // namespace

ModelPolynomials find_polynomial_system(const Model& model, const ModesOptions& options) {
  check_time(model, options.time);
  ModelPolynomials out;
  const Index n = model.num_coordinates(), m = model.num_equations();
  Random random(options.seed ^ 0x5DEECE66Dull);
  ModelRows eval(model, options.time);
  out.origin = model.initial_positions();
  out.scale = Eigen::VectorXd::Ones(n);
  std::vector<bool> angle(static_cast<std::size_t>(n));
  for (Index j = 0; j < n; ++j) {
    angle[static_cast<std::size_t>(j)] = model.coordinate_unit(j) == Unit::kAngle;
    if (model.coordinate_unit(j) == Unit::kLength) out.scale(j) = model.length_scale();
  }
  // The coordinates each row reads, from the Jacobian's pattern.
  const CscPattern& pattern = model.jacobian_pattern();
  std::vector<std::vector<Index>> row_columns(static_cast<std::size_t>(m));
  for (Index j = 0; j < n; ++j)
    for (Index k = pattern.col_ptr[static_cast<std::size_t>(j)]; k < pattern.col_ptr[static_cast<std::size_t>(j) + 1];
         ++k)
      row_columns[static_cast<std::size_t>(pattern.row_idx[static_cast<std::size_t>(k)])].push_back(j);
  auto constraint_name = [&](Index r) {
    return model.constraints()[static_cast<std::size_t>(model.constraint_of_row(r))].name;
  };

  // 1. Affine rows fix coordinates: drivers, then gears among driven angles, pins at fixed angles (model_rows.hpp).
  out.fixed.assign(static_cast<std::size_t>(n), std::numeric_limits<double>::quiet_NaN());
  Eigen::VectorXd base = out.origin;
  std::vector<bool> eliminated(static_cast<std::size_t>(m), false);
  auto is_fixed = [&](Index j) { return !std::isnan(out.fixed[static_cast<std::size_t>(j)]); };
  modes_detail::eliminate_affine_rows(eval, row_columns, out, base, eliminated);
  std::sort(out.eliminated_rows.begin(), out.eliminated_rows.end());

  // 2. The variables: one per free coordinate, two (c, s) per free angle.
  out.variable_of.assign(static_cast<std::size_t>(n), -1);
  PolynomialSystem& system = out.system;
  for (Index j = 0; j < n; ++j) {
    if (is_fixed(j)) continue;
    const std::string& name = model.coordinate_names()[static_cast<std::size_t>(j)];
    out.variable_of[static_cast<std::size_t>(j)] = system.variables;
    if (angle[static_cast<std::size_t>(j)]) {
      system.names.push_back("cos(" + name + ")"), system.names.push_back("sin(" + name + ")");
      system.variables += 2;
    } else {
      system.names.push_back(name);
      system.variables += 1;
    }
  }
  const int nv = system.variables;

  // 3. Each remaining row fitted, lowest degree first.
  for (Index r = 0; r < m; ++r) {
    if (eliminated[static_cast<std::size_t>(r)]) continue;
    std::vector<RowCoordinate> reads;
    std::vector<bool> second;  // per local variable: the s of an angle pair
    for (Index j : row_columns[static_cast<std::size_t>(r)]) {
      if (is_fixed(j)) continue;
      const bool a = angle[static_cast<std::size_t>(j)];
      reads.push_back({j, a, out.variable_of[static_cast<std::size_t>(j)]});
      second.push_back(false);
      if (a) second.push_back(true);
    }
    if (add_angle_relation(eval, r, reads, base, random, out)) continue;  // a gear a linkage turns
    RowFitter fitter(eval, r, reads, second, out, base, random, model.tolerance_scales().row_scale(r));
    std::vector<std::vector<int>> basis;
    Eigen::VectorXd coefficients;
    const RowFitter::Result fit = fitter.fit(options.max_fit_degree, basis, coefficients);
    if (fit == RowFitter::Result::kNotPolynomial) {
      out.status = ModesStatus::kNotPolynomial;
      out.message = "constraint '" + constraint_name(r) +
                    "' is not polynomial in its coordinates (no polynomial of "
                    "degree <= " +
                    std::to_string(options.max_fit_degree) +
                    " in them, angles as cos and sin, reproduces it, nor is it linear in angles alone with "
                    "rational ratios): phiq modes cannot count its assemblies";
      out.system = PolynomialSystem{};
      return out;
    }
    if (fit == RowFitter::Result::kFitted) {
      Polynomial p;
      const double largest = coefficients.cwiseAbs().maxCoeff();
      for (std::size_t k = 0; k < basis.size(); ++k) {
        const double coefficient = coefficients(static_cast<Eigen::Index>(k));
        if (!(std::abs(coefficient) > 1e-11 * largest)) continue;  // rounding of a zero coefficient
        PolynomialTerm term{coefficient, std::vector<int>(static_cast<std::size_t>(nv), 0)};
        int w = 0;
        for (const RowCoordinate& c : reads) {
          term.exponent[static_cast<std::size_t>(c.variable)] = basis[k][static_cast<std::size_t>(w++)];
          if (c.angle)
            term.exponent[static_cast<std::size_t>(c.variable + 1)] = basis[k][static_cast<std::size_t>(w++)];
        }
        p.terms.push_back(std::move(term));
      }
      system.equations.push_back(std::move(p));
    }
  }
  add_circle_equations(angle, out);  // 4. c² + s² = 1 for every free angle
  return out;
}

}  // namespace phiq
