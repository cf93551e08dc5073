// The model's rows as find_polynomial_system() reads them, and the elimination of what affine rows fix
// (model_rows.hpp).
#include "modes/model_rows.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "modes/homotopy.hpp"
#include "phiq/constraint_block.hpp"
#include "phiq/kinds/euler_parameters.hpp"
#include "phiq/kinds/joint_drivers.hpp"

namespace phiq::modes_detail {

ModelRows::ModelRows(const Model& model, double t)
    : model_(model), t_(t), surrogate_(static_cast<std::size_t>(model.num_equations())) {
  for (const auto& block : model.blocks()) {
    const auto* drivers = dynamic_cast<const TypedBlock<JointAngleDriverSpec>*>(block.get());
    if (!drivers) continue;
    for (std::size_t i = 0; i < drivers->size(); ++i) {
      const JointAngleDriverSpec* spec = &drivers->spec(i);
      const double f = spec->law.evaluate(t).f, cf = std::cos(f), sf = std::sin(f);
      // the numerator of the row's atan2 (JointAngleDriverSpec): x_b's component across x_a turned by f
      surrogate_[static_cast<std::size_t>(drivers->first_row(i))] = [spec, cf, sf](const double* q) {
        const double c = detail3::row_value(spec->att.data(), JointAngleDriverSpec::kCompact.rows[0], q, 1.0, 0.0);
        const double s = detail3::row_value(spec->att.data(), JointAngleDriverSpec::kCompact.rows[1], q, 1.0, 0.0);
        return s * cf - c * sf;
      };
    }
  }
}

double ModelRows::row(const Eigen::VectorXd& q, Index r) {
  const auto& replaced = surrogate_[static_cast<std::size_t>(r)];
  if (replaced) return replaced(q.data());
  phi_.resize(static_cast<std::size_t>(model_.num_equations()));
  model_.residual(q.data(), t_, phi_.data());
  return phi_[static_cast<std::size_t>(r)];
}

std::vector<std::array<Index, 4>> euler_parameter_coordinates(const Model& model) {
  std::vector<std::array<Index, 4>> bodies;
  for (const auto& block : model.blocks()) {
    const auto* euler = dynamic_cast<const TypedBlock<EulerParametersSpec>*>(block.get());
    if (!euler) continue;
    for (std::size_t i = 0; i < euler->size(); ++i) {
      std::array<Index, 4> body{};
      bool coordinates = true;
      for (int k = 0; k < 4; ++k) {
        const Slot& s = euler->spec(i).e[k];
        coordinates = coordinates && s.is_coordinate();
        body[static_cast<std::size_t>(k)] = s.coord();
      }
      if (coordinates) bodies.push_back(body);
    }
  }
  return bodies;
}

bool affine_row(ModelRows& rows, Index r, const std::vector<Index>& columns, const Eigen::VectorXd& scale,
                const Eigen::VectorXd& base, Random& random, double& value, Eigen::VectorXd& slope) {
  Eigen::VectorXd q = base;
  value = rows.row(q, r);
  slope.resize(static_cast<Eigen::Index>(columns.size()));
  double size = std::abs(value);
  for (std::size_t k = 0; k < columns.size(); ++k) {
    q(columns[k]) = base(columns[k]) + scale(columns[k]);
    slope(static_cast<Eigen::Index>(k)) = rows.row(q, r) - value;
    q(columns[k]) = base(columns[k]);
    size += std::abs(slope(static_cast<Eigen::Index>(k)));
  }
  if (!std::isfinite(size) || !(slope.cwiseAbs().maxCoeff() > 1e-12 * size)) return false;
  for (int trial = 0; trial < 3; ++trial) {
    double predicted = value;
    for (std::size_t k = 0; k < columns.size(); ++k) {
      const double u = 2.0 * random.symmetric();
      q(columns[k]) = base(columns[k]) + scale(columns[k]) * u;
      predicted += slope(static_cast<Eigen::Index>(k)) * u;
    }
    if (!(std::abs(rows.row(q, r) - predicted) <= 1e-11 * size)) return false;
  }
  return true;
}

namespace {

// The columns a row reads that no earlier pass has fixed (ModelPolynomials::fixed is NaN there).
std::vector<Index> free_columns(const std::vector<Index>& columns, const ModelPolynomials& out) {
  std::vector<Index> free;
  for (Index j : columns)
    if (std::isnan(out.fixed[static_cast<std::size_t>(j)])) free.push_back(j);
  return free;
}

// One pass over the rows that read one free coordinate and are affine in it. True when it fixed one.
bool eliminate_single_coordinates(ModelRows& rows, const std::vector<std::vector<Index>>& row_columns,
                                  ModelPolynomials& out, Eigen::VectorXd& base, std::vector<bool>& eliminated,
                                  Random& random) {
  bool fixed_any = false;
  for (std::size_t r = 0; r < row_columns.size(); ++r) {
    if (eliminated[r]) continue;
    const std::vector<Index> free = free_columns(row_columns[r], out);
    double value = 0.0;
    Eigen::VectorXd slope;
    if (free.size() != 1 || !affine_row(rows, static_cast<Index>(r), free, out.scale, base, random, value, slope))
      continue;
    const Index only = free[0];
    const double h = out.scale(only);
    Eigen::VectorXd q = base;
    q(only) = base(only) - h * value / slope(0);
    // refine on the row itself (an affine row: one step lands on it to rounding)
    q(only) -= h * rows.row(q, static_cast<Index>(r)) / slope(0);
    out.fixed[static_cast<std::size_t>(only)] = base(only) = q(only);
    eliminated[r] = true;
    out.eliminated_rows.push_back(static_cast<Index>(r));
    fixed_any = true;
  }
  return fixed_any;
}

// The rows affine in all (two or more) free coordinates they read, solved together: every coordinate they
// determine is fixed, and every row whose free coordinates are all fixed so is eliminated. True when it fixed one.
bool eliminate_affine_sets(ModelRows& rows, const std::vector<std::vector<Index>>& row_columns, ModelPolynomials& out,
                           Eigen::VectorXd& base, std::vector<bool>& eliminated, Random& random) {
  auto is_fixed = [&](Index j) { return !std::isnan(out.fixed[static_cast<std::size_t>(j)]); };
  std::vector<Index> set_rows, columns;
  std::vector<std::vector<Index>> set_free;
  std::vector<double> values;
  std::vector<Eigen::VectorXd> slopes;
  for (std::size_t r = 0; r < row_columns.size(); ++r) {
    if (eliminated[r]) continue;
    const std::vector<Index> free = free_columns(row_columns[r], out);
    double value = 0.0;
    Eigen::VectorXd slope;
    if (free.size() < 2 || !affine_row(rows, static_cast<Index>(r), free, out.scale, base, random, value, slope))
      continue;
    set_rows.push_back(static_cast<Index>(r)), set_free.push_back(free);
    values.push_back(value), slopes.push_back(slope);
    for (Index j : free)
      if (std::find(columns.begin(), columns.end(), j) == columns.end()) columns.push_back(j);
  }
  if (set_rows.empty()) return false;
  const Eigen::Index m = static_cast<Eigen::Index>(set_rows.size()), n = static_cast<Eigen::Index>(columns.size());
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(m, n);
  Eigen::VectorXd b(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto& free = set_free[static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < free.size(); ++k) {
      const auto at = std::find(columns.begin(), columns.end(), free[k]) - columns.begin();
      a(i, at) = slopes[static_cast<std::size_t>(i)](static_cast<Eigen::Index>(k));
    }
    b(i) = -values[static_cast<std::size_t>(i)];
  }
  // rows scaled to unit size, so that the rank and the consistency are judged relative to each row
  for (Eigen::Index i = 0; i < m; ++i) {
    const double size = a.row(i).cwiseAbs().maxCoeff();
    a.row(i) /= size, b(i) /= size;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV | Eigen::ComputeThinU);
  svd.setThreshold(1e-10);
  const Eigen::Index rank = svd.rank();
  const Eigen::VectorXd u = svd.solve(b);
  if (!((a * u - b).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + b.cwiseAbs().maxCoeff()))) return false;  // inconsistent
  const Eigen::MatrixXd null = svd.matrixV().rightCols(n - rank);
  bool fixed_any = false;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (null.rows() > 0 && null.cols() > 0 && !(null.row(k).cwiseAbs().maxCoeff() <= 1e-9)) continue;
    const Index j = columns[static_cast<std::size_t>(k)];
    out.fixed[static_cast<std::size_t>(j)] = base(j) = base(j) + out.scale(j) * u(k);
    fixed_any = true;
  }
  if (!fixed_any) return false;
  for (std::size_t i = 0; i < set_rows.size(); ++i) {
    bool all = true;  // every coordinate the row moves with (a zero slope: read by the pattern, not by the row)
    const Eigen::VectorXd& slope = slopes[i];
    for (std::size_t k = 0; k < set_free[i].size(); ++k)
      all = all && (is_fixed(set_free[i][k]) ||
                    !(std::abs(slope(static_cast<Eigen::Index>(k))) > 1e-14 * slope.cwiseAbs().maxCoeff()));
    if (!all) continue;
    eliminated[static_cast<std::size_t>(set_rows[i])] = true;
    out.eliminated_rows.push_back(set_rows[i]);
  }
  return true;
}

}  // namespace

void eliminate_affine_rows(ModelRows& rows, const std::vector<std::vector<Index>>& row_columns, ModelPolynomials& out,
                           Eigen::VectorXd& base, std::vector<bool>& eliminated) {
  Random random(0x51A7E5ull);
  for (bool changed = true; changed;) {
    while (eliminate_single_coordinates(rows, row_columns, out, base, eliminated, random)) {
    }
    changed = eliminate_affine_sets(rows, row_columns, out, base, eliminated, random);
  }
}

}  // namespace phiq::modes_detail
