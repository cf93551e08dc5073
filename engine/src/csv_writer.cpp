#include "phiq/csv_writer.hpp"

#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

namespace phiq {

CsvFormat::CsvFormat(const Model& model, std::vector<Index> columns, bool velocities, bool accelerations)
    : model_(model), columns_(std::move(columns)), velocities_(velocities), accelerations_(accelerations) {
  for (Index j : columns_)
    if (j < 0 || j >= model.num_coordinates()) throw Error("CsvFormat: column index out of range");
}

CsvFormat::CsvFormat(const Scene& scene)
    : CsvFormat(*scene.model, scene.output_coordinates, scene.sweep.velocities, scene.sweep.accelerations) {
  scene_ = &scene;
  for (Index c : scene.output_residuals)
    if (c < 0 || c >= static_cast<Index>(model_.constraints().size()))
      throw Error("CsvFormat: residual constraint index out of range");
}

std::vector<std::string> CsvFormat::column_names() const {
  std::vector<std::string> h{"t"};
  const auto& names = model_.coordinate_names();
  for (Index j : columns_) h.push_back(names[j]);
  if (velocities_)
    for (Index j : columns_) h.push_back(names[j] + ".v");
  if (accelerations_)
    for (Index j : columns_) h.push_back(names[j] + ".a");
  if (!scene_) return h;
  static const char* const axis[] = {"x", "y", "z"};
  for (const OutputPoint& p : scene_->sweep.points) {
    for (int d = 0; d < p.dimension(); ++d) h.push_back(p.name + "." + axis[d]);
    if (velocities_)
      for (int d = 0; d < p.dimension(); ++d) h.push_back(p.name + ".v" + axis[d]);
    if (accelerations_)
      for (int d = 0; d < p.dimension(); ++d) h.push_back(p.name + ".a" + axis[d]);
  }
  for (const OutputDriver& d : scene_->output_drivers) {
    h.push_back(d.name + ".f");
    if (velocities_) h.push_back(d.name + ".df");
    if (accelerations_) h.push_back(d.name + ".ddf");
  }
  for (Index c : scene_->output_residuals) h.push_back(model_.constraints()[c].name + ".residual");
  if (scene_->output_max_residual) h.push_back("residual");
  if (scene_->sweep.condition) h.push_back("rcond");
  return h;
}

std::string CsvFormat::header() const {
  std::string h;
  for (const std::string& c : column_names()) h += (h.empty() ? "" : ",") + c;
  h += "\n";
  return h;
}

namespace {
inline void put(double v, std::string& out) {
  if (v == 0.0) v = 0.0;  // −0 → 0: same value, and text diffs of results stay quiet
  char buf[32];
  auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, p);
}
}  // namespace

void CsvFormat::append_outputs(const StepView& s, std::string& out) const {
  const auto& points = scene_->sweep.points;
  if (!points.empty() && !s.points) throw Error("CsvFormat: step has no point motions");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const PointMotion& m = s.points[i];
    const int dim = points[i].dimension();
    for (int d = 0; d < dim; ++d) out += ',', put(m.r[d], out);
    if (velocities_)
      for (int d = 0; d < dim; ++d) out += ',', put(m.v[d], out);
    if (accelerations_)
      for (int d = 0; d < dim; ++d) out += ',', put(m.a[d], out);
  }
  for (const OutputDriver& d : scene_->output_drivers) {
    const LawValue v = d.law.evaluate(s.t);
    out += ',', put(v.f, out);
    if (velocities_) out += ',', put(v.df, out);
    if (accelerations_) out += ',', put(v.ddf, out);
  }
  if (!scene_->output_residuals.empty() || scene_->output_max_residual) {
    if (!s.phi) throw Error("CsvFormat: step has no residuals");
    // Φ of every row: a model solved on its independent rows (Model::without_rows) still evaluates all of them.
    const Eigen::VectorXd* phi = s.phi;
    if (phi->size() != model_.num_equations()) throw Error("CsvFormat: step's Φ is not the scene model's");
    const Eigen::VectorXd& rs = model_.tolerance_scales().row_scale;
    for (Index c : scene_->output_residuals) {
      // the measure of the convergence test: |Φ_i| / scale_i, the largest over the constraint's rows
      const ConstraintInfo& ci = model_.constraints()[c];
      double r = 0.0;
      for (Index i = ci.first_row; i < ci.first_row + ci.rows; ++i) r = std::max(r, std::fabs((*phi)(i)) / rs(i));
      out += ',', put(r, out);
    }
    if (scene_->output_max_residual) out += ',', put(scaled_residual(model_, *phi), out);
  }
  if (scene_->sweep.condition) out += ',', put(s.rcond, out);
}

void CsvFormat::append_row(const StepView& s, std::string& out) const {
  put(s.t, out);
  for (Index j : columns_) out += ',', put(s.q(j), out);
  if (velocities_) {
    if (!s.qd) throw Error("CsvFormat: step has no velocities");
    for (Index j : columns_) out += ',', put((*s.qd)(j), out);
  }
  if (accelerations_) {
    if (!s.qdd) throw Error("CsvFormat: step has no accelerations");
    for (Index j : columns_) out += ',', put((*s.qdd)(j), out);
  }
  if (scene_) append_outputs(s, out);
  out += '\n';
}

AtomicOutputFile::AtomicOutputFile(std::string path) : path_(std::move(path)) {
  tmp_ = path_ + ".tmp-" + std::to_string(::getpid());
  f_ = std::fopen(tmp_.c_str(), "wb");
  if (!f_) throw Error(path_ + ": cannot write: " + std::strerror(errno));
}

AtomicOutputFile::~AtomicOutputFile() {
  if (f_) std::fclose(f_);
  if (!committed_) std::remove(tmp_.c_str());
}

void AtomicOutputFile::write(const std::string& data) {
  if (!f_ || std::fwrite(data.data(), 1, data.size(), f_) != data.size())
    throw Error(path_ + ": write failed: " + std::strerror(errno));
}

void AtomicOutputFile::commit() {
  if (!f_) throw Error(path_ + ": already closed");
  const bool ok = std::fflush(f_) == 0 && ::fsync(::fileno(f_)) == 0;
  const int err = errno;
  std::fclose(f_);
  f_ = nullptr;
  if (!ok) throw Error(path_ + ": write failed: " + std::strerror(err));
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) throw Error(path_ + ": cannot rename: " + std::strerror(errno));
  committed_ = true;
}

}  // namespace phiq
