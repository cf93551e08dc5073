#include "phiq/rank_analysis.hpp"

#include <SuiteSparseQR.hpp>
#include <ccolamd.h>

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "phiq/min_norm_solver.hpp"
#include "linear/cholmod_view.hpp"

namespace phiq {

std::string RankReport::BriefReport() const {
  std::ostringstream s;
  s << coordinates << " coordinates, " << equations << " equations (" << kinematic_equations << " kinematic), rank "
    << rank << ", " << dof << " degrees of freedom";
  if (grubler) s << " (Grübler " << *grubler << ")";
  s << ", " << redundant_rows.size() << " redundant equations";
  if (!redundant.empty()) {
    s << ":";
    for (std::size_t k = 0; k < redundant.size(); ++k) s << (k ? ", " : " ") << redundant[k];
  }
  if (uncertain) s << "; uncertain: " << message;
  return s.str();
}

ScaledJacobianRows::ScaledJacobianRows(const Model& model, std::vector<Index> rows)
    : model_(model.anchor_), rows_(std::move(rows)) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  const CscPattern& full = model.jacobian_pattern();
  std::vector<Index> pos(static_cast<std::size_t>(m), -1);
  for (std::size_t k = 0; k < rows_.size(); ++k) {
    const Index r = rows_[k];
    if (r < 0 || r >= m) throw Error("ScaledJacobianRows: row " + std::to_string(r) + " out of range");
    pos[static_cast<std::size_t>(r)] = static_cast<Index>(k);
  }
  auto p = std::make_shared<CscPattern>();
  p->rows = static_cast<Index>(rows_.size());
  p->cols = n;
  p->col_ptr.assign(static_cast<std::size_t>(n) + 1, 0);
  std::vector<std::pair<Index, Index>> col;  // (new row, source entry), sorted by new row within the column
  for (Index j = 0; j < n; ++j) {
    col.clear();
    for (Index k = full.col_ptr[j]; k < full.col_ptr[j + 1]; ++k)
      if (const Index to = pos[static_cast<std::size_t>(full.row_idx[k])]; to >= 0) col.emplace_back(to, k);
    std::sort(col.begin(), col.end());
    for (const auto& [r, k] : col) {
      p->row_idx.push_back(r);
      source_.push_back(k);
    }
    p->col_ptr[static_cast<std::size_t>(j) + 1] = p->nnz();
  }
  pattern_ = std::move(p);
}

void ScaledJacobianRows::evaluate(const Eigen::VectorXd& q, double t, std::vector<double>& values) {
  const Model& model = detail::model_of(model_.get(), "ScaledJacobianRows");
  if (q.size() != model.num_coordinates())
    throw Error("ScaledJacobianRows: q must have " + std::to_string(model.num_coordinates()) + " entries");
  full_.resize(static_cast<std::size_t>(model.jacobian_pattern().nnz()));
  model.jacobian(q.data(), t, full_.data());
  gather(full_.data(), values);
}

void ScaledJacobianRows::gather(const double* jacobian_values, std::vector<double>& values) const {
  values.resize(source_.size());
  const Model& model = detail::model_of(model_.get(), "ScaledJacobianRows");
  const ToleranceScales& s = model.tolerance_scales();
  const std::vector<Index>& full_rows = model.jacobian_pattern().row_idx;
  const CscPattern& p = *pattern_;
  for (Index j = 0; j < p.cols; ++j)
    for (Index k = p.col_ptr[j]; k < p.col_ptr[j + 1]; ++k) {
      const Index src = source_[static_cast<std::size_t>(k)];
      values[static_cast<std::size_t>(k)] = jacobian_values[src] * s.coordinate_scale(j) / s.row_scale(full_rows[src]);
    }
}

void scaled_jacobian_rows(const Model& model, const Eigen::VectorXd& q, double t, const std::vector<Index>& rows,
                          CscPattern* pattern, std::vector<double>* values) {
  ScaledJacobianRows s(model, rows);
  s.evaluate(q, t, *values);
  *pattern = *s.pattern();
}

namespace {

// The transpose of a CSC matrix with its values.
void transpose(const CscPattern& a, const std::vector<double>& av, CscPattern* t, std::vector<double>* tv) {
  std::vector<Index> from;
  *t = transpose_pattern(a, &from);
  tv->resize(from.size());
  for (std::size_t k = 0; k < from.size(); ++k) (*tv)[k] = av[static_cast<std::size_t>(from[k])];
}

struct SparseRank {
  std::vector<char> live;  // per column of A (an equation)
  Index rank = 0;
  bool order_kept = true;       // SuiteSparseQR pivoted the columns in the given order (no singleton moved ahead)
  double smallest_pivot = 1.0;  // min |R_kk| of the live columns (absolute)
};

// Rank-revealing QR of A (n × k, columns = equations) in the fixed column order: SuiteSparseQR with Heath's method
// declares a column dead when its norm, after the live columns before it have been eliminated, is ≤ tol. R comes
// back "squeezed": a live column's pivot is the entry in the row after the previous live column's, a dead column
// has no entry there.
SparseRank sparse_rank(const CscPattern& a, const std::vector<double>& av, double tol) {
  SparseRank out;
  out.live.assign(static_cast<std::size_t>(a.cols), 0);
  if (a.cols == 0 || a.rows == 0) return out;
  detail::CholmodCommon c;
  cholmod_sparse A = detail::csc_view(a, av.data());
  cholmod_sparse* R = nullptr;
  SuiteSparse_long* E = nullptr;
  const SuiteSparse_long rank = SuiteSparseQR<double>(SPQR_ORDERING_FIXED, tol, 0, &A, &R, &E, &c.cc);
  if (rank < 0 || !R) {
    if (R) cholmod_l_free_sparse(&R, &c.cc);
    throw Error("SuiteSparseQR failed (status " + std::to_string(c.cc.status) + ")");
  }
  const auto* rp = static_cast<const SuiteSparse_long*>(R->p);
  const auto* ri = static_cast<const SuiteSparse_long*>(R->i);
  const auto* rx = static_cast<const double*>(R->x);
  Index row = 0;
  for (Index j = 0; j < a.cols; ++j) {
    double pivot = 0.0;
    bool has = false;
    for (SuiteSparse_long k = rp[j]; k < rp[j + 1]; ++k)
      if (ri[k] == row) has = true, pivot = std::fabs(rx[k]);
    const Index col = E ? static_cast<Index>(E[j]) : j;
    if (col != j) out.order_kept = false;
    if (has && pivot > tol) {
      out.live[static_cast<std::size_t>(col)] = 1;
      out.smallest_pivot = std::min(out.smallest_pivot, pivot);
      ++row;
    }
  }
  out.rank = row;
  cholmod_l_free_sparse(&R, &c.cc);
  if (E) cholmod_l_free(static_cast<std::size_t>(a.cols), sizeof(SuiteSparse_long), E, &c.cc);
  if (out.rank != rank)
    throw Error("SuiteSparseQR: rank " + std::to_string(rank) + " but " + std::to_string(out.rank) +
                " live pivots found in R");
  return out;
}

// CCOLAMD's fill-reducing order of the equations `order` (the columns of J̃ᵀ, whose pattern `at` is) with the
// first `kinematic` of them kept ahead of the others (constraint sets 0 and 1). Only the pattern is read.
std::vector<Index> fill_reducing(const CscPattern& at, const std::vector<Index>& order, Index kinematic) {
  const SuiteSparse_long nr = at.rows, nc = at.cols, nnz = at.nnz();
  const std::size_t alen = ccolamd_l_recommended(nnz, nr, nc);
  if (alen == 0) throw Error("CCOLAMD: invalid matrix");
  std::vector<SuiteSparse_long> A(alen), p(static_cast<std::size_t>(nc) + 1), cmember(static_cast<std::size_t>(nc));
  std::copy(at.row_idx.begin(), at.row_idx.end(), A.begin());
  std::copy(at.col_ptr.begin(), at.col_ptr.end(), p.begin());
  for (SuiteSparse_long k = 0; k < nc; ++k) cmember[static_cast<std::size_t>(k)] = k < kinematic ? 0 : 1;
  double knobs[CCOLAMD_KNOBS];
  SuiteSparse_long stats[CCOLAMD_STATS];
  ccolamd_l_set_defaults(knobs);
  if (!ccolamd_l(nr, nc, static_cast<SuiteSparse_long>(alen), A.data(), p.data(), knobs, stats, cmember.data()))
    throw Error("CCOLAMD failed (status " + std::to_string(stats[CCOLAMD_STATUS]) + ")");
  std::vector<Index> out(order.size());
  for (SuiteSparse_long k = 0; k < nc; ++k) out[static_cast<std::size_t>(k)] = order[static_cast<std::size_t>(p[k])];
  return out;
}

}  // namespace

RankReport analyse_rank(const Model& model, const Eigen::VectorXd& q, double t, const RankOptions& options) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  if (q.size() != n || !q.allFinite())
    throw Error("analyse_rank: q must have " + std::to_string(n) + " finite entries");
  if (!(options.tolerance > 0.0 && options.tolerance < 1.0)) throw Error("RankOptions: tolerance must be in (0, 1)");
  RankReport rep;
  rep.coordinates = n;
  rep.equations = m;
  rep.tolerance = options.tolerance;
  rep.grubler = model.grubler();

  // Kinematic rows first, then the rheonomic ones, each in model order.
  std::vector<Index> order;
  order.reserve(static_cast<std::size_t>(m));
  for (int pass = 0; pass < 2; ++pass)
    for (Index r = 0; r < m; ++r)
      if (model.constraints()[static_cast<std::size_t>(model.constraint_of_row(r))].depends_on_time == (pass == 1))
        order.push_back(r);
  for (Index r = 0; r < m; ++r)
    if (!model.constraints()[static_cast<std::size_t>(model.constraint_of_row(r))].depends_on_time)
      ++rep.kinematic_equations;
  rep.driver_equations = m - rep.kinematic_equations;

  rep.ordering = options.ordering == RankOrdering::kAuto
                     ? (m <= 20000 ? RankOrdering::kModelOrder : RankOrdering::kFillReducing)
                     : options.ordering;
  if (rep.ordering == RankOrdering::kFillReducing && m > 0) {  // the order from the pattern alone
    std::vector<Index> unused;
    order = fill_reducing(transpose_pattern(*ScaledJacobianRows(model, order).pattern(), &unused), order,
                          rep.kinematic_equations);
  }
  ScaledJacobianRows scaled(model, order);
  std::vector<double> jv, atv;
  scaled.evaluate(q, t, jv);
  const CscPattern& jp = *scaled.pattern();
  CscPattern at;
  transpose(jp, jv, &at, &atv);  // n × m: column k is equation order[k]
  double largest = 0.0;
  for (Index k = 0; k < at.cols; ++k) {
    double s = 0.0;
    for (Index e = at.col_ptr[k]; e < at.col_ptr[k + 1]; ++e) s += atv[e] * atv[e];
    largest = std::max(largest, std::sqrt(s));
  }
  if (!(largest > 0.0)) largest = 1.0;  // no entry at all: every equation is (trivially) dependent
  const double tol = options.tolerance * largest;

  // All rows, greedily in `order`: the kinematic rows come first, so the live ones among them are the rank of the
  // kinematic rows (the mechanism's degrees of freedom) — unless SuiteSparseQR moved a column ahead (a singleton),
  // in which case the kinematic rows are factorised again on their own.
  const SparseRank all = sparse_rank(at, atv, tol);
  SparseRank kr;
  if (rep.driver_equations == 0 || all.order_kept) {
    kr.rank = 0;
    for (Index k = 0; k < rep.kinematic_equations; ++k) kr.rank += all.live[static_cast<std::size_t>(k)];
    kr.smallest_pivot = all.smallest_pivot;
  } else {
    // the kinematic columns on their own (the first block of `at`)
    const Index k0 = 0, k1 = rep.kinematic_equations;
    CscPattern kin;
    kin.rows = at.rows;
    kin.cols = rep.kinematic_equations;
    const Index e0 = at.col_ptr[k0];
    for (Index k = k0; k <= k1; ++k) kin.col_ptr.push_back(at.col_ptr[k] - e0);
    kin.row_idx.assign(at.row_idx.begin() + e0, at.row_idx.begin() + at.col_ptr[k1]);
    std::vector<double> kinv(atv.begin() + e0, atv.begin() + at.col_ptr[k1]);
    kr = sparse_rank(kin, kinv, tol);
  }
  rep.rank = kr.rank;
  rep.dof = n - kr.rank;
  rep.driven_rank = all.rank;
  rep.driven_dof = n - all.rank;
  rep.smallest_pivot = std::min(kr.smallest_pivot, all.smallest_pivot) / largest;
  for (std::size_t k = 0; k < order.size(); ++k)
    (all.live[k] ? rep.independent_rows : rep.redundant_rows).push_back(order[k]);
  std::sort(rep.independent_rows.begin(), rep.independent_rows.end());
  std::sort(rep.redundant_rows.begin(), rep.redundant_rows.end());
  Index last = -1;
  for (Index r : rep.redundant_rows) {
    const Index c = model.constraint_of_row(r);
    if (c != last) rep.redundant.push_back(model.constraints()[static_cast<std::size_t>(c)].name), last = c;
  }

  std::ostringstream why;
  if (rep.smallest_pivot <= options.margin * options.tolerance && rep.smallest_pivot < 1.0)
    why << "an independent equation's pivot (" << rep.smallest_pivot << ") is within " << options.margin
        << "× of the rank tolerance " << options.tolerance;
  if (std::min(m, n) <= options.dense_check_limit && m > 0 && n > 0) {
    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(jp.rows, jp.cols);
    for (Index j = 0; j < jp.cols; ++j)
      for (Index e = jp.col_ptr[j]; e < jp.col_ptr[j + 1]; ++e) dense(jp.row_idx[e], j) = jv[e];
    const Eigen::VectorXd sv = Eigen::BDCSVD<Eigen::MatrixXd>(dense).singularValues();
    const double cut = options.tolerance * sv(0);
    rep.dense_checked = true;
    rep.dense_rank = (sv.array() > cut).count();
    const Index near = ((sv.array() > cut / options.margin) && (sv.array() <= cut * options.margin)).count();
    if (rep.dense_rank != rep.driven_rank)
      why << (why.tellp() > 0 ? "; " : "") << "sparse QR rank " << rep.driven_rank << " but " << rep.dense_rank
          << " singular values above the tolerance";
    else if (near > 0)
      why << (why.tellp() > 0 ? "; " : "") << near << " singular value(s) within " << options.margin
          << "× of the rank tolerance";
  }
  rep.message = why.str();
  rep.uncertain = !rep.message.empty();
  return rep;
}

std::vector<RowCombination> combinations_of(const Model& model, const Eigen::VectorXd& q, double t,
                                            const std::vector<Index>& basis, const std::vector<Index>& rows) {
  std::vector<RowCombination> out;
  if (q.size() != model.num_coordinates())
    throw Error("combinations_of: q must have " + std::to_string(model.num_coordinates()) + " entries");
  if (rows.empty()) return out;
  // one evaluation of Φq, gathered twice: the basis rows (factorised) and the rows to express in them
  ScaledJacobianRows basis_rows(model, basis), fit_rows(model, rows);
  std::vector<double> full(static_cast<std::size_t>(model.jacobian_pattern().nnz())), bv, rv, rtv;
  model.jacobian(q.data(), t, full.data());
  basis_rows.gather(full.data(), bv);
  fit_rows.gather(full.data(), rv);
  const CscPattern* bp = basis_rows.pattern().get();
  MinNormSolver solver(basis_rows.pattern());
  if (solver.factorize(bv.data()) != FactorStatus::kOk)
    throw Error("combinations_of: the basis rows are dependent at this configuration");
  CscPattern rt;
  transpose(*fit_rows.pattern(), rv, &rt, &rtv);  // column k: J̃ row rows[k]
  const Index n = model.num_coordinates(), b = static_cast<Index>(basis.size());
  Eigen::VectorXd jr(n), rhs(b), c(b), fit(n);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    jr.setZero();
    for (Index e = rt.col_ptr[k]; e < rt.col_ptr[k + 1]; ++e) jr(rt.row_idx[e]) = rtv[e];
    // least squares J̃_Bᵀ c ≈ J̃_rᵀ: normal equations (J̃_B J̃_Bᵀ) c = J̃_B J̃_rᵀ
    rhs.setZero();
    for (Index j = 0; j < n; ++j)
      for (Index e = bp->col_ptr[j]; e < bp->col_ptr[j + 1]; ++e) rhs(bp->row_idx[e]) += bv[e] * jr(j);
    RowCombination rc;
    rc.row = rows[k];
    if (!solver.solve(rhs.data(), c.data())) throw Error("combinations_of: " + solver.last_message());
    solver.multiply_transposed(c.data(), fit.data());
    const double norm = jr.norm();
    rc.fit_residual = norm > 0.0 ? (fit - jr).norm() / norm : 0.0;
    const double big = c.cwiseAbs().maxCoeff();
    for (Index i = 0; i < b; ++i)
      if (std::fabs(c(i)) > 1e-8 * big) rc.basis.push_back(basis[static_cast<std::size_t>(i)]);
    std::sort(rc.basis.begin(), rc.basis.end());
    out.push_back(std::move(rc));
  }
  return out;
}

}  // namespace phiq
