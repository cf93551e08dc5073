#include "phiq/model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string_view>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_for_each.h>

namespace phiq {

const char* to_string(Unit u) {
  switch (u) {
    case Unit::kNone:
      return "none";
    case Unit::kLength:
      return "length";
    case Unit::kAngle:
      return "angle";
  }
  return "?";
}

const char* unit_symbol(Unit u) { return u == Unit::kLength ? "m" : u == Unit::kAngle ? "rad" : ""; }

// ---- Model ---------------------------------------------------------------------------------------------------

static_assert(std::is_nothrow_move_constructible_v<detail::ModelData> &&
                  std::is_nothrow_move_assignable_v<detail::ModelData>,
              "Model's moves are noexcept (a std::vector<Model> grows by moving)");

void detail::throw_model_gone(const ModelAnchor* anchor, const char* what) {
  if (anchor)
    throw Error(std::string("the Model this ") + what +
                " was made for no longer exists (it was destroyed, or assigned another model)");
  throw Error(std::string("this ") + what + " was moved from: it has no model");
}

Model::Model() : anchor_(std::make_shared<detail::ModelAnchor>(detail::ModelAnchor{this})) {}

Model::Model(const Model& other)
    : detail::ModelData(other), anchor_(std::make_shared<detail::ModelAnchor>(detail::ModelAnchor{this})) {}

Model::Model(Model&& other) noexcept : detail::ModelData(std::move(other)), anchor_(std::move(other.anchor_)) {
  if (anchor_) anchor_->model = this;
}

Model& Model::operator=(Model&& other) noexcept {
  if (this == &other) return *this;
  detail::ModelData::operator=(std::move(other));
  if (anchor_) anchor_->model = nullptr;  // the workspaces of the model overwritten: it no longer exists
  anchor_ = std::move(other.anchor_);
  if (anchor_) anchor_->model = this;
  return *this;
}

Model::~Model() {
  if (anchor_) anchor_->model = nullptr;
}

Index Model::coordinate_index(const std::string& name) const {
  const Index j = index_of_.find(name, coordinate_name_of());
  if (j < 0) throw Error("unknown coordinate '" + name + "'");
  return j;
}

Index Model::find_coordinate(std::string_view name) const { return index_of_.find(name, coordinate_name_of()); }

Index Model::find_constraint(std::string_view name) const { return constraint_index_.find(name, constraint_name_of()); }

Index Model::constraint_index(std::string_view name) const {
  const Index k = find_constraint(name);
  if (k < 0) throw Error("unknown constraint '" + std::string(name) + "'");
  return k;
}

Index Model::row_index(std::string_view row_name) const {
  const Index whole = find_constraint(row_name);
  if (whole >= 0 && constraints_[static_cast<std::size_t>(whole)].rows == 1)
    return constraints_[static_cast<std::size_t>(whole)].first_row;
  // "name[k]": row k of the multi-row constraint `name`
  const std::size_t open = row_name.rfind('[');
  if (open != std::string_view::npos && open > 0 && row_name.size() > open + 2 && row_name.back() == ']') {
    const std::string_view digits = row_name.substr(open + 1, row_name.size() - open - 2);
    const Index c = find_constraint(row_name.substr(0, open));
    if (c >= 0 && digits.find_first_not_of("0123456789") == std::string_view::npos && digits.size() < 10) {
      const ConstraintInfo& info = constraints_[static_cast<std::size_t>(c)];
      const Index k = std::stoll(std::string(digits));
      if (info.rows > 1 && k < info.rows) return info.first_row + k;
    }
  }
  if (whole >= 0)
    throw Error("constraint '" + std::string(row_name) + "' has " +
                std::to_string(constraints_[static_cast<std::size_t>(whole)].rows) + " rows: name one as '" +
                std::string(row_name) + "[k]'");
  throw Error("no row of Φ is named '" + std::string(row_name) + "'");
}

void detail::throw_index_out_of_range(Index i, Index size, const char* what) {
  throw Error(std::string(what) + " index " + std::to_string(i) + " out of range (the model has " +
              std::to_string(size) + " " + what + "s)");
}

std::string Model::row_name(Index row) const {
  const ConstraintInfo& c = constraints_[static_cast<std::size_t>(constraint_of_row(row))];
  if (c.rows == 1) return c.name;
  return c.name + "[" + std::to_string(row - c.first_row) + "]";
}

std::string Model::outside_domain(const double* q) const {
  for (const auto& b : blocks_) {
    auto [i, why] = b->outside_domain(q);
    if (i < b->size())
      return "constraint '" + constraints_[static_cast<std::size_t>(constraint_of_row(b->first_row(i)))].name +
             "': " + why;
  }
  return "";
}

namespace {

// Constraints per parallel task: a task of 8192 distance rows is about 30 µs of work, well above TBB's
// scheduling cost.
constexpr std::size_t kGrain = 8192;
// Below this many constraints the model is evaluated in the calling thread. Not 2 · kGrain: between two
// evaluations a Newton iteration spends a factorisation in one thread, TBB's idle workers go to sleep, and waking
// them costs more than the split gains up to here (nfourbar N = 10⁴, 2·10⁴ constraints: the engine's iteration
// 1.27–1.29 kernels evaluated in one thread against 1.34–1.37 in two, bench/README.md).
constexpr std::size_t kParallelFrom = 65536;

// Calls f(block, begin, end) over all constraints of `blocks`, split into tasks of about kGrain constraints run
// by TBB when the model is large. Disjoint ranges write disjoint outputs (ConstraintBlock's contract), so no
// synchronisation is needed; the result does not depend on the split (each entry is written by one constraint).
template <class Blocks, class F>
void for_each_range(const Blocks& blocks, F&& f) {
  std::size_t total = 0;
  for (const auto& b : blocks) total += b->size();
  if (total < kParallelFrom) {
    for (const auto& b : blocks) f(*b, std::size_t{0}, b->size());
    return;
  }
  tbb::parallel_for_each(blocks.begin(), blocks.end(), [&](const auto& b) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, b->size(), kGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) { f(*b, r.begin(), r.end()); });
  });
}

}  // namespace

void Model::residual(const double* q, double t, double* phi) const {
  for_each_range(blocks_,
                 [&](const ConstraintBlock& b, std::size_t i0, std::size_t i1) { b.residual(i0, i1, q, t, phi); });
}

bool Model::prepare_jacobian_values(double* csc_values) const {
  // Every slot of the pattern has at least one entry (the pattern is made of them); when none has two, storing
  // each entry writes every slot exactly once and the zero fill is not needed.
  const bool overwrite = static_cast<Index>(slot_of_entry_.size()) == pattern_->nnz();
  if (!overwrite) std::fill(csc_values, csc_values + pattern_->nnz(), 0.0);
  return overwrite;
}

void Model::jacobian(const double* q, double t, double* csc_values) const {
  const bool overwrite = prepare_jacobian_values(csc_values);
  for_each_range(blocks_, [&](const ConstraintBlock& b, std::size_t i0, std::size_t i1) {
    b.jacobian(i0, i1, q, t, slot_of_entry_.data(), csc_values, overwrite);
  });
}

void Model::residual_and_jacobian(const double* q, double t, double* phi, double* csc_values) const {
  const bool overwrite = prepare_jacobian_values(csc_values);
  for_each_range(blocks_, [&](const ConstraintBlock& b, std::size_t i0, std::size_t i1) {
    b.residual_and_jacobian(i0, i1, q, t, phi, slot_of_entry_.data(), csc_values, overwrite);
  });
}

void Model::phi_t(const double* q, double t, double* out) const {
  std::fill(out, out + num_equations(), 0.0);
  for_each_range(time_blocks_,
                 [&](const ConstraintBlock& b, std::size_t i0, std::size_t i1) { b.phi_t(i0, i1, q, t, out); });
}

void Model::gamma(const double* q, const double* qd, double t, double* out) const {
  for_each_range(blocks_,
                 [&](const ConstraintBlock& b, std::size_t i0, std::size_t i1) { b.gamma(i0, i1, q, qd, t, out); });
}

double Model::row_rounding_floor(Index row, const double* q, double t) const {
  // Each block's constraints are in the order they were added, so their first rows ascend: the owner of `row` is
  // the last constraint of some block that starts at or before it and still covers it.
  for (const auto& b : blocks_) {
    std::size_t lo = 0, hi = b->size();  // the first constraint starting after `row` is in [lo, hi]
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (b->first_row(mid) <= row)
        lo = mid + 1;
      else
        hi = mid;
    }
    if (lo == 0) continue;
    const Index first = b->first_row(lo - 1);
    if (row < first + b->rows_per_constraint())
      return ToleranceScales::kUlpFloor * b->coordinate_sensitivity(lo - 1, static_cast<int>(row - first), q, t);
  }
  throw Error("row_rounding_floor: row " + std::to_string(row) + " out of range");
}

Model Model::without_rows(std::vector<Index> rows) const {
  const Index m = num_equations(), n = num_coordinates();
  std::sort(rows.begin(), rows.end());
  if (std::adjacent_find(rows.begin(), rows.end()) != rows.end())
    throw Error("without_rows: row " + std::to_string(*std::adjacent_find(rows.begin(), rows.end())) + " repeated");
  if (!rows.empty() && (rows.front() < 0 || rows.back() >= m))
    throw Error("without_rows: row out of range (the model has " + std::to_string(m) + " rows)");
  Model out(*this);
  out.dropped_rows_ = rows;
  out.solve_entries_.clear();
  out.solve_rows_.clear();
  if (rows.empty()) {  // nothing left out: the full system, with its own analysis
    out.solve_pattern_ = pattern_;
    if (solve_pattern_ != pattern_) {
      out.symbolic_.reset();
      if (m == n && n > 0) out.symbolic_ = analyse(lu_kind_, pattern_);
    }
    return out;
  }
  {
    // new row numbers: kept rows in order, dropped rows -1
    std::vector<Index> renumber(static_cast<std::size_t>(m), -1);
    std::size_t d = 0;
    for (Index i = 0; i < m; ++i) {
      if (d < rows.size() && rows[d] == i) {
        ++d;
        continue;
      }
      renumber[static_cast<std::size_t>(i)] = static_cast<Index>(out.solve_rows_.size());
      out.solve_rows_.push_back(i);
    }
    auto p = std::make_shared<CscPattern>();
    p->rows = static_cast<Index>(out.solve_rows_.size());
    p->cols = n;
    p->col_ptr.assign(static_cast<std::size_t>(n) + 1, 0);
    for (Index j = 0; j < n; ++j) {
      for (Index k = pattern_->col_ptr[j]; k < pattern_->col_ptr[j + 1]; ++k) {
        const Index r = renumber[static_cast<std::size_t>(pattern_->row_idx[k])];
        if (r < 0) continue;
        p->row_idx.push_back(r);
        out.solve_entries_.push_back(k);
      }
      p->col_ptr[static_cast<std::size_t>(j) + 1] = p->nnz();
    }
    out.solve_pattern_ = p;
  }
  out.symbolic_.reset();
  if (out.solve_pattern_->rows == n && n > 0) out.symbolic_ = analyse(lu_kind_, out.solve_pattern_);
  return out;
}

// ---- ModelBuilder --------------------------------------------------------------------------------------------

ModelBuilder::ModelBuilder() = default;
ModelBuilder::~ModelBuilder() = default;
ModelBuilder::ModelBuilder(ModelBuilder&&) noexcept = default;

Index ModelBuilder::add_coordinate(const std::string& name, double initial) {
  if (name.empty()) throw Error("coordinate name is empty");
  if (!std::isfinite(initial)) throw Error("coordinate '" + name + "': initial value is not finite");
  if (!model_.index_of_.insert(name, num_coordinates(), model_.coordinate_name_of()))
    throw Error("duplicate coordinate name '" + name + "'");
  model_.names_.push_back(name);
  const Index n = num_coordinates();
  // room grows geometrically (a resize per coordinate would copy the vector each time); build() trims it
  if (model_.initial_.size() < n) model_.initial_.conservativeResize(std::max<Index>(n, 2 * model_.initial_.size()));
  model_.initial_(n - 1) = initial;
  return n - 1;
}

void ModelBuilder::reserve(Index more_coordinates, Index more_constraints) {
  // grow only: a vector's reserve of a little more each time would copy it each time
  auto grow_vector = [](auto& v, std::size_t n) {
    if (n > v.capacity()) v.reserve(std::max(n, 2 * v.capacity()));
  };
  if (more_coordinates > 0) {
    const auto n = static_cast<std::size_t>(num_coordinates() + more_coordinates);
    model_.index_of_.reserve(n);
    grow_vector(model_.names_, n);
    if (model_.initial_.size() < static_cast<Index>(n)) model_.initial_.conservativeResize(static_cast<Index>(n));
  }
  if (more_constraints > 0) {
    const auto n = model_.constraints_.size() + static_cast<std::size_t>(more_constraints);
    constraint_names_.reserve(n);
    grow_vector(model_.constraints_, n);
    grow_vector(model_.row_constraint_, std::max(n, model_.row_constraint_.size()));
  }
}

Index ModelBuilder::find_coordinate(const std::string& name) const {
  return model_.index_of_.find(name, model_.coordinate_name_of());
}

void ModelBuilder::set_initial(Index j, double value) {
  if (j < 0 || j >= num_coordinates()) throw Error("set_initial: coordinate index out of range");
  if (!std::isfinite(value)) throw Error("coordinate '" + model_.names_[j] + "': initial value is not finite");
  model_.initial_(j) = value;
}

void ModelBuilder::set_length_scale(double metres) {
  if (!(metres > 0.0) || !std::isfinite(metres)) throw Error("length scale must be a positive finite number");
  length_scale_override_ = metres;
}

Index ModelBuilder::add_driver(const std::string& name, Index coordinate, MotionLaw law) {
  return add(name, CoordinateDriverSpec{Slot::coordinate(coordinate), std::move(law)});
}

void ModelBuilder::check_slot(const Slot& s, const std::string& name) const {
  if (s.is_coordinate() && s.coord() >= num_coordinates())
    throw Error("constraint '" + name + "': coordinate index " + std::to_string(s.coord()) + " out of range (" +
                std::to_string(num_coordinates()) + " coordinates)");
  if (!s.is_coordinate() && !std::isfinite(s.value())) throw Error("constraint '" + name + "': constant is not finite");
}

Index ModelBuilder::add_info(const std::string& name, const char* kind, int rows, bool depends_on_time) {
  if (!constraint_names_.insert(name, static_cast<Index>(model_.constraints_.size()), model_.constraint_name_of()))
    throw Error("duplicate constraint name '" + name + "'");
  const Index id = static_cast<Index>(model_.constraints_.size());
  model_.constraints_.push_back(
      ConstraintInfo{name, kind, static_cast<Index>(model_.row_constraint_.size()), rows, depends_on_time});
  for (int r = 0; r < rows; ++r) model_.row_constraint_.push_back(id);
  return id;
}

void ModelBuilder::count_joint(const JointCount& c) {
  if (c.role == JointCount::Role::kOther) non_joint_ = true;
  if (c.role != JointCount::Role::kJoint) return;
  const int d = c.dimension == 3 ? 1 : 0;
  joints_of_dimension_[d] = true;
  removed_[d] += c.freedoms;
}

void ModelBuilder::check_body(const std::string& name, std::initializer_list<Slot> slots) {
  if (name.empty()) throw Error("body name is empty");
  for (const Slot& s : slots) {
    if (s.is_coordinate() && s.coord() >= num_coordinates())
      throw Error("body '" + name + "': coordinate index out of range");
    if (!s.is_coordinate() && !std::isfinite(s.value())) throw Error("body '" + name + "': constant is not finite");
  }
  const auto name_of = [this](Index k) -> const std::string& {
    return model_.body_names_[static_cast<std::size_t>(k)];
  };
  if (!body_names_.insert(name, static_cast<Index>(model_.body_names_.size()), name_of))
    throw Error("duplicate body name '" + name + "'");
}

Index ModelBuilder::add_body(const std::string& name, const Frame2& f) {
  check_body(name, {f.x, f.y, f.psi});
  model_.body_names_.push_back(name);
  ++bodies_[0];
  return static_cast<Index>(model_.body_names_.size()) - 1;
}

Index ModelBuilder::add_body(const std::string& name, const Frame3& f) {
  check_body(name, {f.x, f.y, f.z, f.e0, f.e1, f.e2, f.e3});
  // Euler parameters all 0 at the placement are no orientation: the normalisation's gradient 2e vanishes there,
  // and the assembly could only fail ("Gauss-Newton step is not finite").
  double norm2 = 0.0;
  for (const Slot& e : {f.e0, f.e1, f.e2, f.e3}) {
    const double v = e.is_coordinate() ? model_.initial_(e.coord()) : e.value();
    norm2 += v * v;
  }
  if (!(norm2 > 0.0))
    throw Error("body '" + name +
                "': its Euler parameters are all 0 in the placement, which is no orientation "
                "(1, 0, 0, 0 is the body unturned)");
  if (f.e0.is_coordinate() || f.e1.is_coordinate() || f.e2.is_coordinate() || f.e3.is_coordinate())
    add(name + ".euler", EulerParametersSpec{{f.e0, f.e1, f.e2, f.e3}});
  model_.body_names_.push_back(name);
  ++bodies_[1];
  return static_cast<Index>(model_.body_names_.size()) - 1;
}

Index ModelBuilder::add_unit_vector(const std::string& name, const Point3& v) {
  return add(name + ".unit", UnitVectorSpec{v});
}

// ToleranceScales (model.hpp): each length row relative to its own link, each length coordinate to the shortest
// link reading it; the rows' rounding-floor coordinates. `pattern` is the full Jacobian's, `own` each row's own
// length (ConstraintBlock::row_lengths()).
void ModelBuilder::tolerance_scales(const CscPattern& pattern, const std::vector<double>& own) {
  Model& m = model_;
  ToleranceScales& sc = m.scales_;
  const Index n = m.num_coordinates(), rows = m.num_equations();
  const double fallback = m.length_scale_;
  const auto length_row = [&](Index i) { return m.row_units_[static_cast<std::size_t>(i)] == Unit::kLength; };
  const auto length_coordinate = [&](Index j) {
    return m.coordinate_units_[static_cast<std::size_t>(j)] == Unit::kLength;
  };
  if (n >= INT32_MAX) throw Error("the model has " + std::to_string(n) + " coordinates; phiq handles fewer than 2^31");

  // The pattern by rows, as Φqᵀ's: the columns of row i are cols[begin[i] … begin[i + 1] − 1].
  const CscPattern by_rows = transpose_pattern(pattern, nullptr);
  const std::vector<Index>& begin = by_rows.col_ptr;
  const std::vector<Index>& cols = by_rows.row_idx;

  if (length_scale_override_ > 0.0) {  // one scale for every length, as set
    sc.row_scale.resize(rows);
    for (Index i = 0; i < rows; ++i) sc.row_scale(i) = length_row(i) ? fallback : 1.0;
    sc.coordinate_scale.resize(n);
    for (Index j = 0; j < n; ++j) sc.coordinate_scale(j) = length_coordinate(j) ? fallback : 1.0;
  } else {
    constexpr double kUnset = std::numeric_limits<double>::infinity();
    sc.row_scale = Eigen::VectorXd::Ones(rows);
    sc.coordinate_scale = Eigen::VectorXd::Ones(n);
    for (Index j = 0; j < n; ++j)
      if (length_coordinate(j)) sc.coordinate_scale(j) = kUnset;
    // 1. Length rows with a length of their own; length coordinates: the smallest among the rows reading them.
    for (Index i = 0; i < rows; ++i) {
      const double l = own[static_cast<std::size_t>(i)];
      if (!length_row(i)) continue;
      sc.row_scale(i) = l > 0.0 && std::isfinite(l) ? l : kUnset;
      if (sc.row_scale(i) == kUnset) continue;
      for (Index k = begin[static_cast<std::size_t>(i)]; k < begin[static_cast<std::size_t>(i) + 1]; ++k) {
        const Index j = cols[static_cast<std::size_t>(k)];
        if (length_coordinate(j)) sc.coordinate_scale(j) = std::min(sc.coordinate_scale(j), l);
      }
    }
    // 2. Length rows without a length: the largest scale of the length coordinates they read.
    for (Index i = 0; i < rows; ++i) {
      if (sc.row_scale(i) != kUnset) continue;
      double s = 0.0;
      for (Index k = begin[static_cast<std::size_t>(i)]; k < begin[static_cast<std::size_t>(i) + 1]; ++k) {
        const Index j = cols[static_cast<std::size_t>(k)];
        if (length_coordinate(j) && sc.coordinate_scale(j) != kUnset) s = std::max(s, sc.coordinate_scale(j));
      }
      sc.row_scale(i) = s > 0.0 ? s : fallback;
    }
    // 3. Length coordinates read by no row with a length: the smallest scale of the length rows reading them.
    for (Index j = 0; j < n; ++j) {
      if (sc.coordinate_scale(j) != kUnset) continue;
      double s = kUnset;
      for (Index k = pattern.col_ptr[j]; k < pattern.col_ptr[j + 1]; ++k)
        if (length_row(pattern.row_idx[k])) s = std::min(s, sc.row_scale(pattern.row_idx[k]));
      sc.coordinate_scale(j) = s != kUnset ? s : fallback;
    }
  }

  sc.inverse_row_scale = sc.row_scale.cwiseInverse();
  sc.inverse_coordinate_scale = sc.coordinate_scale.cwiseInverse();
}

Model ModelBuilder::build() && {
  Model& m = model_;
  const Index n = m.num_coordinates(), rows = m.num_equations();
  m.initial_.conservativeResize(n);                    // add_coordinate() and reserve() leave room beyond n
  m.constraint_index_ = std::move(constraint_names_);  // kept for Model::constraint_index()
  body_names_.clear();

  // Sparsity pattern, fixed for the life of the model.
  std::vector<Index> trip_rows, trip_cols;
  for (auto& b : m.blocks_) b->build_pattern(trip_rows, trip_cols);
  if (static_cast<Index>(trip_rows.size()) >= INT32_MAX)
    throw Error("the model's Jacobian has " + std::to_string(trip_rows.size()) +
                " entries; phiq handles fewer than 2^31");
  std::vector<Index> slots;
  auto pattern = std::make_shared<CscPattern>(build_csc_pattern(rows, n, trip_rows, trip_cols, &slots));
  m.slot_of_entry_.assign(slots.begin(), slots.end());
  m.constraint_place_.assign(m.constraints_.size(), {0, 0});  // (every constraint is in one block)
  for (std::size_t b = 0; b < m.blocks_.size(); ++b)
    for (std::size_t i = 0; i < m.blocks_[b]->size(); ++i)
      m.constraint_place_[static_cast<std::size_t>(m.constraint_of_row(m.blocks_[b]->first_row(i)))] = {
          static_cast<std::uint32_t>(b), static_cast<std::uint32_t>(i)};
  m.pattern_ = pattern;
  m.solve_pattern_ = pattern;
  {  // a row that involves no coordinate holds at every position or at none: named here, before a factorisation
     // library refuses the empty row of the Jacobian in its own words
    std::vector<char> used(static_cast<std::size_t>(rows), 0);
    for (Index r : pattern->row_idx) used[static_cast<std::size_t>(r)] = 1;
    for (Index r = 0; r < rows && rows == n; ++r)  // square: for the LU (a redundant model's rank analysis copes)
      if (!used[static_cast<std::size_t>(r)])
        throw Error("constraint '" + m.row_name(r) + "' involves no coordinate (an empty row of the Jacobian): " +
                    "it holds at every position or at none");
  }

  // Units and scales.
  m.coordinate_units_.assign(static_cast<std::size_t>(n), Unit::kNone);
  for (auto& b : m.blocks_) b->infer_coordinate_units(m.coordinate_units_);
  m.row_units_.assign(static_cast<std::size_t>(rows), Unit::kNone);
  for (auto& b : m.blocks_) b->row_units(m.coordinate_units_, m.row_units_);

  // Each row's own length (0 if its constraint carries none): the rows' tolerance scales, and their largest the
  // model's length scale.
  std::vector<double> own(static_cast<std::size_t>(rows), 0.0);
  for (auto& b : m.blocks_) b->row_lengths(own);
  double scale = length_scale_override_;
  if (scale <= 0.0)
    for (double l : own) scale = std::max(scale, l);
  if (scale <= 0.0) {
    // no length in the data: the extent of the initial placement of the length coordinates
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (Index j = 0; j < n; ++j)
      if (m.coordinate_units_[j] == Unit::kLength) lo = std::min(lo, m.initial_(j)), hi = std::max(hi, m.initial_(j));
    scale = hi > lo ? hi - lo : 1.0;
  }
  m.length_scale_ = scale;
  tolerance_scales(*pattern, own);

  for (auto& b : m.blocks_) {
    bool td = false;
    for (std::size_t i = 0; i < b->size() && !td; ++i) td = b->depends_on_time(i);
    if (td) m.time_blocks_.push_back(b.get());
  }

  // Every driver's law must be defined on the sweep: keep the intersection of their domains.
  auto limit_time = [&](const MotionLaw& law, Index row) {
    const std::string& name = m.constraints_[static_cast<std::size_t>(m.constraint_of_row(row))].name;
    if (law.domain_begin() > m.time_begin_) m.time_begin_ = law.domain_begin(), m.time_limiter_ = name;
    if (law.domain_end() < m.time_end_) m.time_end_ = law.domain_end(), m.time_limiter_ = name;
  };
  // (every kind that holds a law: the spatial joint drivers too, or a table on a joint's angle was only found
  // undefined where the sweep reached its end)
  auto limit_by_drivers = [&](auto kind) {
    using Spec = decltype(kind);
    if (auto it = block_of_type_.find(std::type_index(typeid(Spec))); it != block_of_type_.end()) {
      auto& blk = static_cast<TypedBlock<Spec>&>(*m.blocks_[it->second]);
      for (std::size_t i = 0; i < blk.size(); ++i) limit_time(blk.spec(i).law, blk.first_row(i));
    }
  };
  limit_by_drivers(CoordinateDriverSpec{});
  limit_by_drivers(JointAngleDriverSpec{});
  limit_by_drivers(JointDistanceDriverSpec{});
  if (auto it = block_of_type_.find(std::type_index(typeid(EquationSpec))); it != block_of_type_.end()) {
    auto& blk = static_cast<TypedBlock<EquationSpec>&>(*m.blocks_[it->second]);
    for (std::size_t i = 0; i < blk.size(); ++i)
      if (blk.spec(i).law) limit_time(*blk.spec(i).law, blk.first_row(i));
  }

  // Grübler–Kutzbach: defined for bodies of one dimension joined only by joints of that dimension.
  const int dim = bodies_[1] > 0 ? 1 : 0;
  if ((bodies_[0] > 0) != (bodies_[1] > 0) && !non_joint_ && !joints_of_dimension_[1 - dim])
    m.grubler_ = (dim == 1 ? 6 : 3) * bodies_[dim] - removed_[dim];

  // Symbolic analysis once per model; square systems only (redundant or under-determined models are analysed by
  // the rank module, not by LU).
  if (rows == n && n > 0) {
    // Batch mode: a model of the same structure (the same scene with other parameter values) shares the other's
    // pattern and analysis read-only instead of analysing again.
    const Model* other = share_analysis_with_;
    if (other && other->symbolic_ && other->lu_kind_ == m.lu_kind_ && other->pattern_->rows == pattern->rows &&
        other->pattern_->cols == pattern->cols && other->pattern_->col_ptr == pattern->col_ptr &&
        other->pattern_->row_idx == pattern->row_idx) {
      m.pattern_ = m.solve_pattern_ = other->pattern_;
      m.symbolic_ = other->symbolic_;
    } else {
      m.symbolic_ = analyse(m.lu_kind_, m.solve_pattern_);
    }
  }
  return std::move(m);
}

}  // namespace phiq
