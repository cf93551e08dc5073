#include "phiq/rank_analysis.hpp"

#include <SuiteSparseQR.hpp>

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "phiq/min_norm_solver.hpp"

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

void scaled_jacobian_rows(const Model& model, const Eigen::VectorXd& q, double t, const std::vector<Index>& rows,
                          CscPattern* pattern, std::vector<double>* values) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  if (q.size() != n) throw Error("scaled_jacobian_rows: q must have " + std::to_string(n) + " entries");
  const CscPattern& full = model.jacobian_pattern();
  std::vector<double> v(static_cast<std::size_t>(full.nnz()));
  model.jacobian(q.data(), t, v.data());
  std::vector<Index> pos(static_cast<std::size_t>(m), -1);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const Index r = rows[k];
    if (r < 0 || r >= m) throw Error("scaled_jacobian_rows: row " + std::to_string(r) + " out of range");
    pos[static_cast<std::size_t>(r)] = static_cast<Index>(k);
  }
  const ToleranceScales& s = model.tolerance_scales();
  CscPattern& p = *pattern;
  p.rows = static_cast<Index>(rows.size());
  p.cols = n;
  p.col_ptr.assign(static_cast<std::size_t>(n) + 1, 0);
  p.row_idx.clear();
  values->clear();
  std::vector<std::pair<Index, double>> col;
  for (Index j = 0; j < n; ++j) {
    col.clear();
    for (Index k = full.col_ptr[j]; k < full.col_ptr[j + 1]; ++k) {
      const Index r = full.row_idx[k], to = pos[static_cast<std::size_t>(r)];
      if (to >= 0) col.emplace_back(to, v[static_cast<std::size_t>(k)] * s.coordinate_scale(j) / s.row_scale(r));
    }
    std::sort(col.begin(), col.end());
    for (const auto& [r, x] : col) p.row_idx.push_back(r), values->push_back(x);
    p.col_ptr[static_cast<std::size_t>(j) + 1] = p.nnz();
  }
}

namespace {

// The transpose of a CSC matrix, as CSC (i.e. the CSR form of the original).
void transpose(const CscPattern& a, const std::vector<double>& av, CscPattern* t, std::vector<double>* tv) {
  t->rows = a.cols;
  t->cols = a.rows;
  t->col_ptr.assign(static_cast<std::size_t>(a.rows) + 1, 0);
  for (Index r : a.row_idx) ++t->col_ptr[static_cast<std::size_t>(r) + 1];
  for (Index i = 0; i < a.rows; ++i) t->col_ptr[i + 1] += t->col_ptr[i];
  t->row_idx.assign(static_cast<std::size_t>(a.nnz()), 0);
  tv->assign(static_cast<std::size_t>(a.nnz()), 0.0);
  std::vector<Index> next(t->col_ptr.begin(), t->col_ptr.end() - 1);
  for (Index j = 0; j < a.cols; ++j)
    for (Index k = a.col_ptr[j]; k < a.col_ptr[j + 1]; ++k) {
      const Index dst = next[static_cast<std::size_t>(a.row_idx[k])]++;
      t->row_idx[dst] = j;
      (*tv)[dst] = av[k];
    }
}

// RAII for CHOLMOD's workspace, the way SuiteSparseQR takes it.
struct Cholmod {
  cholmod_common cc;
  Cholmod() {
    cholmod_l_start(&cc);
    cc.print = 0;
    cc.error_handler = nullptr;
  }
  ~Cholmod() { cholmod_l_finish(&cc); }
};

cholmod_sparse view(const CscPattern& p, const std::vector<double>& v) {
  cholmod_sparse a;
  std::memset(&a, 0, sizeof a);
  a.nrow = static_cast<std::size_t>(p.rows);
  a.ncol = static_cast<std::size_t>(p.cols);
  a.nzmax = static_cast<std::size_t>(std::max<Index>(p.nnz(), 1));
  a.p = const_cast<Index*>(p.col_ptr.data());
  a.i = const_cast<Index*>(p.row_idx.data());
  a.x = const_cast<double*>(v.data());
  a.itype = CHOLMOD_LONG;
  a.xtype = CHOLMOD_REAL;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 1;
  a.packed = 1;
  return a;
}

struct SparseRank {
  std::vector<char> live;        // per column of A (an equation)
  Index rank = 0;
  double smallest_pivot = 1.0;   // min |R_kk| of the live columns (absolute)
};

// Rank-revealing QR of A (n × k, columns = equations) in the fixed column order: SuiteSparseQR with Heath's method
// declares a column dead when its norm, after the live columns before it have been eliminated, is ≤ tol. R comes
// back "squeezed": a live column's pivot is the entry in the row after the previous live column's, a dead column
// has no entry there.
SparseRank sparse_rank(const CscPattern& a, const std::vector<double>& av, double tol) {
  SparseRank out;
  out.live.assign(static_cast<std::size_t>(a.cols), 0);
  if (a.cols == 0 || a.rows == 0) return out;
  Cholmod c;
  cholmod_sparse A = view(a, av);
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
    if (has && pivot > tol) {
      out.live[static_cast<std::size_t>(col)] = 1;
      out.smallest_pivot = std::min(out.smallest_pivot, pivot);
      ++row;
    }
  }
  out.rank = row;
  cholmod_l_free_sparse(&R, &c.cc);
  if (E) cholmod_l_free(static_cast<std::size_t>(a.cols), sizeof(SuiteSparse_long), E, &c.cc);
  if (out.rank != rank) throw Error("SuiteSparseQR: rank " + std::to_string(rank) + " but " +
                                    std::to_string(out.rank) + " live pivots found in R");
  return out;
}

}  // namespace

RankReport analyse_rank(const Model& model, const Eigen::VectorXd& q, double t, const RankOptions& options) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  if (q.size() != n || !q.allFinite()) throw Error("analyse_rank: q must have " + std::to_string(n) + " finite entries");
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

  CscPattern jp, at;
  std::vector<double> jv, atv;
  scaled_jacobian_rows(model, q, t, order, &jp, &jv);
  transpose(jp, jv, &at, &atv);  // n × m: column k is equation order[k]
  double largest = 0.0;
  for (Index k = 0; k < at.cols; ++k) {
    double s = 0.0;
    for (Index e = at.col_ptr[k]; e < at.col_ptr[k + 1]; ++e) s += atv[e] * atv[e];
    largest = std::max(largest, std::sqrt(s));
  }
  if (!(largest > 0.0)) largest = 1.0;  // no entry at all: every equation is (trivially) dependent
  const double tol = options.tolerance * largest;

  // The kinematic rows alone, for the mechanism's degrees of freedom; then all rows, for what to keep.
  CscPattern kin = at;
  kin.cols = rep.kinematic_equations;
  kin.col_ptr.resize(static_cast<std::size_t>(kin.cols) + 1);
  kin.row_idx.resize(static_cast<std::size_t>(kin.col_ptr.back()));
  std::vector<double> kinv(atv.begin(), atv.begin() + kin.col_ptr.back());
  const SparseRank kr = sparse_rank(kin, kinv, tol);
  const SparseRank all = rep.driver_equations ? sparse_rank(at, atv, tol) : kr;
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
  if (rows.empty()) return out;
  auto bp = std::make_shared<CscPattern>();
  std::vector<double> bv;
  scaled_jacobian_rows(model, q, t, basis, bp.get(), &bv);
  MinNormSolver solver(bp);
  if (solver.factorize(bv.data()) != FactorStatus::kOk)
    throw Error("combinations_of: the basis rows are dependent at this configuration");
  CscPattern rp, rt;
  std::vector<double> rv, rtv;
  scaled_jacobian_rows(model, q, t, rows, &rp, &rv);
  transpose(rp, rv, &rt, &rtv);  // column k: J̃ row rows[k]
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
