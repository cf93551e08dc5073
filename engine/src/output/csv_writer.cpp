#include "phiq/csv_writer.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <type_traits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "base/names.hpp"
#include "phiq/model.hpp"
#include "phiq/kinematics.hpp"  // scaled_residual: the `residual` column is the convergence test's measure

namespace phiq {

CsvFormat::CsvFormat(const Model& model, std::vector<Index> columns, bool velocities, bool accelerations)
    : model_(model), columns_(std::move(columns)), velocities_(velocities), accelerations_(accelerations) {
  if (velocities_) v_columns_ = columns_;
  if (accelerations_) a_columns_ = columns_;
  for (Index j : columns_)
    if (j < 0 || j >= model.num_coordinates()) throw Error("CsvFormat: column index out of range");
}

CsvFormat::CsvFormat(const Model& model, const OutputPlan& plan)
    : CsvFormat(model, plan.coordinate_columns, plan.velocities, plan.accelerations) {
  plan_ = &plan;
  v_columns_ = plan.written_velocities();
  a_columns_ = plan.written_accelerations();
  for (const std::vector<Index>* cs : {&v_columns_, &a_columns_})
    for (Index j : *cs)
      if (j < 0 || j >= model.num_coordinates()) throw Error("CsvFormat: column index out of range");
  for (Index c : plan.residual_columns)
    if (c < 0 || c >= static_cast<Index>(model_.constraints().size()))
      throw Error("CsvFormat: residual constraint index out of range");
}

std::string identifier_column_name(const std::string& dotted) {
  std::string id;
  if (!dotted.empty() && dotted[0] >= '0' && dotted[0] <= '9') id += '_';
  for (char c : dotted) {
    if (c == '.')
      id += "__";
    else
      id += detail::is_name_char(c) ? c : '_';
  }
  return id;
}

void CsvFormat::set_naming(ColumnNaming naming) {
  if (naming == ColumnNaming::kIdentifiers) {
    // Python's keywords (attribute access cannot spell them) and the names numpy.genfromtxt renames
    static const std::set<std::string> reserved = {
        "False",    "None",   "True",  "and",  "as",     "assert",   "async",   "await", "break", "class",
        "continue", "def",    "del",   "elif", "else",   "except",   "finally", "for",   "from",  "global",
        "if",       "import", "in",    "is",   "lambda", "nonlocal", "not",     "or",    "pass",  "raise",
        "return",   "try",    "while", "with", "yield",  "file",     "print"};
    std::map<std::string, std::string> first;  // identifier form -> the dotted name that has it
    for (const std::string& d : dotted_names()) {
      const std::string id = identifier_column_name(d);
      if (reserved.count(id))
        throw Error("column '" + d + "' would be named '" + id +
                    "', which Python reserves or numpy.genfromtxt renames: rename it in the scene");
      auto [it, fresh] = first.emplace(id, d);
      if (!fresh)
        throw Error("columns '" + it->second + "' and '" + d + "' would both be named '" + id +
                    "': rename one in the scene");
    }
  }
  naming_ = naming;
}

std::vector<std::string> CsvFormat::column_names() const {
  std::vector<std::string> h = dotted_names();
  if (naming_ == ColumnNaming::kIdentifiers)
    for (std::string& n : h) n = identifier_column_name(n);
  return h;
}

std::vector<std::string> CsvFormat::dotted_names() const {
  std::vector<std::string> h{"t"};
  const auto& names = model_.coordinate_names();
  for (Index j : columns_) h.push_back(names[j]);
  for (Index j : v_columns_) h.push_back(names[j] + ".v");
  for (Index j : a_columns_) h.push_back(names[j] + ".a");
  if (!plan_) return h;
  static const char* const axis[] = {"x", "y", "z"};
  for (const OutputPoint& p : plan_->points) {
    for (int d = 0; d < p.dimension(); ++d) h.push_back(p.name + "." + axis[d]);
    if (velocities_)
      for (int d = 0; d < p.dimension(); ++d) h.push_back(p.name + ".v" + axis[d]);
    if (accelerations_)
      for (int d = 0; d < p.dimension(); ++d) h.push_back(p.name + ".a" + axis[d]);
  }
  for (const OutputJoint& j : plan_->joints) {
    const std::string m = j.name + (j.measure == JointMeasure::kAngle ? ".angle" : ".distance");
    h.push_back(m);
    if (velocities_) h.push_back(m + ".v");
    if (accelerations_) h.push_back(m + ".a");
  }
  const std::vector<std::string> suffixes = plan_->orientation_form.suffixes();
  for (const OutputOrientation& o : plan_->orientations) {
    for (const std::string& s : suffixes) h.push_back(o.name + "." + s);
    if (velocities_)
      for (int d = 0; d < 3; ++d) h.push_back(o.name + ".omega_" + axis[d]);
    if (accelerations_)
      for (int d = 0; d < 3; ++d) h.push_back(o.name + ".alpha_" + axis[d]);
  }
  for (const OutputDriver& d : plan_->driver_columns) {
    h.push_back(d.name + ".f");
    if (velocities_) h.push_back(d.name + ".df");
    if (accelerations_) h.push_back(d.name + ".ddf");
  }
  for (Index c : plan_->residual_columns) h.push_back(model_.constraints()[c].name + ".residual");
  if (plan_->max_residual_column) h.push_back("residual");
  if (plan_->condition) h.push_back("rcond");
  for (const OutputSensitivity& p : plan_->sensitivities) {
    const std::string d = ".d_" + p.name;
    for (Index j : columns_) h.push_back(names[j] + d);
    for (Index j : v_columns_) h.push_back(names[j] + ".v" + d);
    for (Index j : a_columns_) h.push_back(names[j] + ".a" + d);
  }
  for (Index c : plan_->efforts.constraints) h.push_back(model_.constraints()[c].name + ".effort");
  if (plan_->efforts.power)
    for (Index c : plan_->efforts.constraints) h.push_back(model_.constraints()[c].name + ".power");
  static constexpr const char* kSpatial[] = {".Fx", ".Fy", ".Fz", ".Mx", ".My", ".Mz"};
  static constexpr const char* kPlanar[] = {".Fx", ".Fy", ".Mz"};
  for (const OutputReaction& r : plan_->efforts.reactions)
    for (int k = 0; k < (r.spatial ? 6 : 3); ++k)
      h.push_back(plan_->efforts.reaction_name(model_, r) + (r.spatial ? kSpatial : kPlanar)[k]);
  for (const OutputLoss& l : plan_->efforts.losses) {
    if (l.bearing) h.push_back(l.name + ".friction");
    h.push_back(l.name + ".loss");
  }
  for (const OutputSensitivity& p : plan_->sensitivities)  // ∂τ/∂p (phiq/effort_sensitivity.hpp)
    for (Index c : plan_->efforts.constraints) h.push_back(model_.constraints()[c].name + ".effort.d_" + p.name);
  if (plan_->efforts.power)  // ∂P/∂p
    for (const OutputSensitivity& p : plan_->sensitivities)
      for (Index c : plan_->efforts.constraints) h.push_back(model_.constraints()[c].name + ".power.d_" + p.name);
  return h;
}

std::string CsvFormat::header() const {
  std::string h;
  for (const std::string& c : column_names()) h += (h.empty() ? "" : ",") + c;
  h += "\n";
  return h;
}

namespace {
// The longest shortest-round-trip text of a double, "-2.2250738585072014e-308", and its comma.
constexpr std::size_t kMaxValueChars = 25;

// Writes v at w (at most kMaxValueChars − 1 characters); returns the end.
inline char* put(double v, char* w) {
  if (v == 0.0) {  // −0 → 0: same value, and text diffs of results stay quiet; std::to_chars's text of 0, at once
    *w = '0';
    return w + 1;
  }
  return std::to_chars(w, w + kMaxValueChars - 1, v).ptr;
}
inline void put(double v, std::string& out) {
  char buf[kMaxValueChars];
  out.append(buf, put(v, buf));
}

// Coordinate values per task when a wide row is formatted in parallel: about 30 µs of std::to_chars (≈ 30 ns a
// value here), far above TBB's cost of a task.
constexpr std::size_t kValuesPerTask = 1024;
}  // namespace

namespace {
// emit(values, count) where Emit takes a run, else emit() value by value
template <class Emit>
void emit_run(Emit& emit, const double* values, std::size_t count) {
  if constexpr (std::is_invocable_v<Emit&, const double*, std::size_t>)
    emit(values, count);
  else
    for (std::size_t i = 0; i < count; ++i) emit(values[i]);
}
// What the append_output_values() and append_values() emit into: the doubles in order, each `Store`d, into `count`
// consecutive slices (the next sizes[i] of them to out[i]).
template <class Store>
struct Slices {
  double* const* out;
  const std::size_t* sizes;
  std::size_t count;
  Store store;
  std::size_t next_slice = 0, left = 0;
  double* at = nullptr;
  void reach() {  // the slice the next value goes to
    while (left == 0 && next_slice < count) at = out[next_slice], left = sizes[next_slice], ++next_slice;
  }
  void operator()(double v) { reach(), *at++ = store(v), --left; }
  void operator()(const double* values, std::size_t n) {
    while (n > 0) {
      reach();
      const std::size_t m = std::min(n, left);
      at = std::transform(values, values + m, at, store);
      values += m, n -= m, left -= m;
    }
  }
};
template <class Store>
Slices(double* const*, const std::size_t*, std::size_t, Store) -> Slices<Store>;
// The stores, as types: a function pointer held in Slices was called once per value (3·10⁴ of them a row with
// nfourbar 10⁴'s reactions), not inlined into a copy the compiler vectorises.
struct AsComputed {
  double operator()(double v) const { return v; }
};
struct AsStored {
  double operator()(double v) const { return stored_value(v); }
};
}  // namespace

// Calls emit(v) for each value after the coordinate columns, in column order: the one computation of those values
// for the CSV text and for append_output_values() (the HDF5 writer), so that the two files cannot disagree.
template <class Emit>
void CsvFormat::for_each_output(const StepView& s, Emit&& emit) const {
  const auto& points = plan_->points;
  if (!points.empty() && !s.points) throw Error("CsvFormat: step has no point motions");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const PointMotion& m = s.points[i];
    const int dim = points[i].dimension();
    for (int d = 0; d < dim; ++d) emit(m.r[d]);
    if (velocities_)
      for (int d = 0; d < dim; ++d) emit(m.v[d]);
    if (accelerations_)
      for (int d = 0; d < dim; ++d) emit(m.a[d]);
  }
  if (!plan_->joints.empty() && !s.joints) throw Error("CsvFormat: step has no joint measures");
  for (std::size_t i = 0; i < plan_->joints.size(); ++i) {
    emit(s.joints[i].value);
    if (velocities_) emit(s.joints[i].rate);
    if (accelerations_) emit(s.joints[i].acceleration);
  }
  if (!plan_->orientations.empty() && !s.orientations) throw Error("CsvFormat: step has no orientations");
  const int form_size = plan_->orientation_form.size();
  for (std::size_t i = 0; i < plan_->orientations.size(); ++i) {
    const OrientationMotion& o = s.orientations[i];
    for (int d = 0; d < form_size; ++d) emit(o.values[static_cast<std::size_t>(d)]);
    if (velocities_)
      for (int d = 0; d < 3; ++d) emit(o.omega[static_cast<std::size_t>(d)]);
    if (accelerations_)
      for (int d = 0; d < 3; ++d) emit(o.alpha[static_cast<std::size_t>(d)]);
  }
  for (const OutputDriver& d : plan_->driver_columns) {
    const LawValue v = d.law.evaluate(s.t);
    emit(v.f);
    if (velocities_) emit(v.df);
    if (accelerations_) emit(v.ddf);
  }
  if (!plan_->residual_columns.empty() || plan_->max_residual_column) {
    if (!s.phi) throw Error("CsvFormat: step has no residuals");
    // Φ of every row: a model solved on its independent rows (Model::without_rows) still evaluates all of them.
    const Eigen::VectorXd* phi = s.phi;
    if (phi->size() != model_.num_equations()) throw Error("CsvFormat: step's Φ is not the scene model's");
    const Eigen::VectorXd& rs = model_.tolerance_scales().row_scale;
    for (Index c : plan_->residual_columns) {
      // the measure of the convergence test: |Φ_i| / scale_i, the largest over the constraint's rows
      const ConstraintInfo& ci = model_.constraints()[c];
      double r = 0.0;
      for (Index i = ci.first_row; i < ci.first_row + ci.rows; ++i) r = std::max(r, std::fabs((*phi)(i)) / rs(i));
      emit(r);
    }
    if (plan_->max_residual_column) emit(scaled_residual(model_, *phi));
  }
  if (plan_->condition) emit(s.rcond);
  if (!plan_->sensitivities.empty()) {
    if (!s.sensitivities) throw Error("CsvFormat: step has no sensitivities");
    const SensitivityLayout layout{model_.num_coordinates()};
    for (std::size_t i = 0; i < plan_->sensitivities.size(); ++i) {
      const double* base = s.sensitivities;
      for (Index j : columns_) emit(base[layout.offset(i, 0) + j]);
      for (Index j : v_columns_) emit(base[layout.offset(i, 1) + j]);
      for (Index j : a_columns_) emit(base[layout.offset(i, 2) + j]);
    }
  }
  if (plan_->efforts.active()) {
    if (!s.efforts) throw Error("CsvFormat: step has no efforts");
    const std::size_t n = plan_->efforts.constraints.size();
    emit_run(emit, s.efforts, plan_->efforts.power ? 2 * n : n);
    // reactions, then ∂τ/∂p, then ∂P/∂p with the powers
    const std::size_t taus = static_cast<std::size_t>(plan_->efforts.size()) + n * plan_->sensitivities.size();
    const std::size_t all = plan_->efforts.power ? taus + n * plan_->sensitivities.size() : taus;
    emit_run(emit, s.efforts + 2 * n, all - 2 * n);
  }
}

void CsvFormat::append_outputs(const StepView& s, std::string& out) const {
  // As append_coordinates(): room for the longest text of each value, written in place, the row cut to what was
  // written (appending each value's text to the string cost half as much again as its formatting).
  const std::size_t start = out.size();
  out.resize(start + num_output_values() * kMaxValueChars);
  char *w = out.data() + start, *end = out.data() + out.size();
  try {
    for_each_output(s, [&](double v) {
      if (static_cast<std::size_t>(end - w) < kMaxValueChars) {  // (never: the count is exact)
        const std::size_t at = static_cast<std::size_t>(w - out.data());
        out.resize(out.size() + 64 * kMaxValueChars);
        w = out.data() + at, end = out.data() + out.size();
      }
      *w++ = ',', w = put(v, w);
    });
  } catch (...) {
    out.resize(start);  // no room's zeros left behind
    throw;
  }
  out.resize(static_cast<std::size_t>(w - out.data()));
}

void CsvFormat::append_output_values(const StepView& s, double* out) const {
  if (!plan_) return;
  const std::size_t n = num_output_values();
  for_each_output(s, Slices{&out, &n, 1, AsComputed{}});
}

void CsvFormat::append_output_values(const StepView& s, double* const* out, const std::size_t* sizes,
                                     std::size_t count) const {
  if (!plan_) return;
  for_each_output(s, Slices{out, sizes, count, AsStored{}});
}

std::size_t CsvFormat::num_output_values() const {
  if (!plan_) return 0;
  const std::size_t per = 1 + velocities_ + accelerations_;
  std::size_t n = plan_->driver_columns.size() * per + plan_->residual_columns.size() + plan_->max_residual_column +
                  plan_->condition;
  for (const OutputPoint& p : plan_->points) n += static_cast<std::size_t>(p.dimension()) * per;
  n += plan_->joints.size() * per;
  n += plan_->orientations.size() *
       (static_cast<std::size_t>(plan_->orientation_form.size()) + 3 * (velocities_ + accelerations_));
  n += plan_->sensitivities.size() * (columns_.size() + v_columns_.size() + a_columns_.size());
  n += plan_->efforts.constraints.size() * (plan_->efforts.power ? 2 : 1);
  n += static_cast<std::size_t>(plan_->efforts.size()) - 2 * plan_->efforts.constraints.size();           // reactions
  n += plan_->efforts.constraints.size() * plan_->sensitivities.size() * (plan_->efforts.power ? 2 : 1);  // ∂τ, ∂P
  return n;
}

std::size_t CsvFormat::num_values() const {
  return 1 + columns_.size() + v_columns_.size() + a_columns_.size() + num_output_values();
}

void CsvFormat::append_values(const StepView& s, double* out) const {
  check_coordinates(s);
  *out++ = stored_value(s.t);  // (−0 → 0, as put() writes it)
  const Eigen::VectorXd* groups[3] = {&s.q, s.qd, s.qdd};
  const std::vector<Index>* cols[3] = {&columns_, &v_columns_, &a_columns_};
  for (int g = 0; g < 3; ++g)
    for (Index c : *cols[g]) *out++ = stored_value((*groups[g])(c));
  const std::size_t n = num_output_values();
  if (plan_) for_each_output(s, Slices{&out, &n, 1, AsStored{}});
}

void CsvFormat::append_row(const StepView& s, std::string& out) const {
  put(s.t, out);
  append_coordinates(s, out);
  if (plan_) append_outputs(s, out);
  out += '\n';
}

std::size_t CsvFormat::max_row_chars() const { return num_values() * kMaxValueChars + 1; }

void CsvFormat::check_coordinates(const StepView& s) const {
  if (velocities_ && !s.qd) throw Error("CsvFormat: step has no velocities");
  if (accelerations_ && !s.qdd) throw Error("CsvFormat: step has no accelerations");
  if (s.q.size() != model_.num_coordinates() || (velocities_ && s.qd->size() != s.q.size()) ||
      (accelerations_ && s.qdd->size() != s.q.size()))
    throw Error("CsvFormat: step's vectors are not the model's size");
}

void CsvFormat::append_coordinates(const StepView& s, std::string& out) const {
  check_coordinates(s);
  // q's columns, then q̇'s, then q̈'s: group g's values are [first[g], first[g + 1]) of the row's coordinate part
  const double* groups[3] = {s.q.data(), velocities_ ? s.qd->data() : nullptr,
                             accelerations_ ? s.qdd->data() : nullptr};
  const std::vector<Index>* cols[3] = {&columns_, &v_columns_, &a_columns_};
  std::size_t first[4] = {0};
  for (int g = 0; g < 3; ++g) first[g + 1] = first[g] + cols[g]->size();
  const std::size_t total = first[3];
  if (total == 0) return;
  // ",v" for values [begin, end) of the row's coordinate part from w on
  auto format = [&](std::size_t begin, std::size_t end, char* w) {
    std::size_t g = 0;
    while (first[g + 1] <= begin) ++g;
    for (std::size_t k = begin; k < end; ++g) {
      const double* v = groups[g];
      const Index* c = cols[g]->data() + (k - first[g]);
      for (const std::size_t stop = std::min(end, first[g + 1]); k < stop; ++k) *w++ = ',', w = put(v[*c++], w);
    }
    return w;
  };
  // Room for the longest text of every value; the row is cut to what was written. A wide row (a large model's
  // q, q̇, q̈: 6 000 values at 10³ four-bars, 3·10⁶ at 10⁶) is formatted by blocks of kValuesPerTask in parallel,
  // each block into its own stretch, which are then closed up in order: one thread takes longer to write a large
  // model's row than to solve it (bench/README.md), and a sweep's other threads idle once their chunks are done.
  const std::size_t at = out.size();
  out.resize(at + total * kMaxValueChars);
  char* base = out.data() + at;
  const std::size_t blocks = (total + kValuesPerTask - 1) / kValuesPerTask;
  if (blocks < 2) {
    out.resize(static_cast<std::size_t>(format(0, total, base) - out.data()));
    return;
  }
  std::vector<std::size_t> length(blocks);
  const std::size_t stride = kValuesPerTask * kMaxValueChars;
  // isolated: the calling thread waits only for its own blocks (it may be delivering a parallel sweep's rows)
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, blocks, 1),
        [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t b = r.begin(); b < r.end(); ++b) {
            char* w = base + b * stride;
            length[b] =
                static_cast<std::size_t>(format(b * kValuesPerTask, std::min(total, (b + 1) * kValuesPerTask), w) - w);
          }
        },
        tbb::simple_partitioner());
  });
  char* end = base + length[0];
  for (std::size_t b = 1; b < blocks; ++b) {  // leftwards, in order: a block never overtakes the next one's text
    std::memmove(end, base + b * stride, length[b]);
    end += length[b];
  }
  out.resize(static_cast<std::size_t>(end - out.data()));
}

}  // namespace phiq
