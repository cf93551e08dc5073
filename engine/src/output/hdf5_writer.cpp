#include "phiq/hdf5_writer.hpp"

#include <sys/mman.h>  // memfd_create
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "output/hdf5_handle.hpp"
#include "phiq/csv_writer.hpp"
#include "phiq/model.hpp"
#include "phiq/version.hpp"

namespace phiq {

using detail::h5::check;
using detail::h5::checked;
using detail::h5::Hid;
using detail::h5::QuietErrors;
using detail::h5::write_attribute;

namespace {

// Chunks of at most 1 MiB: HDF5's default chunk cache holds one, and h5py's guidance is 10 KiB – 1 MiB. A chunk is
// written once, whole (a block of rows is a chunk's rows), so the cache never evicts a half-written one.
constexpr std::size_t kChunkBytes = std::size_t{1} << 20;

// The unit of a coordinate and of its derivatives ("" where the model does not know it).
std::string unit_of(Unit u, const char* per_time) {
  const char* base = u == Unit::kLength ? "m" : u == Unit::kAngle ? "rad" : "";
  return *base ? std::string(base) + per_time : std::string();
}

// Rows per block (= per chunk): as many as the buffer holds, at most a chunk of one column, and — when the number
// of rows is known — the count in [max/4, max] whose last block is fullest: the last chunk of an uncompressed
// dataset takes its whole size on disk, so 1 001 rows in blocks of 34 would store 1 020.
std::size_t choose_block_rows(std::size_t row_bytes, const Hdf5Options& o) {
  std::size_t most = std::max<std::size_t>(1, o.buffer_bytes / std::max<std::size_t>(row_bytes, 1));
  most = std::min(most, kChunkBytes / sizeof(double));
  if (o.expected_rows > 0) most = std::min(most, o.expected_rows);
  if (o.expected_rows == 0) return most;
  std::size_t best = most, best_waste = o.expected_rows;
  for (std::size_t r = most; r >= std::max<std::size_t>(1, most / 4); --r) {
    const std::size_t waste = (o.expected_rows + r - 1) / r * r - o.expected_rows;
    if (waste < best_waste) best = r, best_waste = waste;
    if (r == 1) break;
  }
  return best;
}

// A file given up (a write failed, or the writer was destroyed before close()) cannot simply be closed: HDF5
// flushes its cached metadata and chunks on closing, the flush fails again on a full disk, the close fails, and
// HDF5 1.10 closes the half-released file once more when the process exits: SIGSEGV. The file is the caller's to
// remove, so its descriptor is pointed at an anonymous memory file first, where the flush and the close succeed.
void divert_to_memory(hid_t file) {
  void* handle = nullptr;  // the sec2 driver's: its descriptor
  if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0 || handle == nullptr) return;
  const int sink = memfd_create("phiq-hdf5-given-up", MFD_CLOEXEC);
  if (sink < 0) return;
  (void)dup2(sink, *static_cast<int*>(handle));
  ::close(sink);
}

}  // namespace

// One dataset: its columns' names and units, the rows held for the next write, and where they go.
struct Group {
  const char* name;
  std::vector<std::string> columns, units;
  bool one_dimensional = false;  // /t and /rcond: one value per row
  Hid dataset;
  std::vector<double> held;  // block_rows × columns, row-major
};

struct Hdf5Writer::Impl {
  std::string path;
  const Model& model;
  const OutputPlan& plan;
  CsvFormat format;
  Hid file;
  std::vector<Group> groups;    // in CSV column order
  Group* batch_case = nullptr;  // /case (Hdf5Options::case_column)
  Group *t = nullptr, *q = nullptr, *qd = nullptr, *qdd = nullptr;
  std::vector<Group*> outputs;     // points, drivers, residuals, rcond: the CsvFormat::append_output_values() slices
  std::vector<double*> output_at;  // a row's place in each of `outputs` (append_row())
  std::vector<std::size_t> output_size;  // each one's columns
  std::size_t block_rows = 1, held_rows = 0, written_rows = 0;
  bool closed = false;

  Impl(const std::string& p, const Model& m, const OutputPlan& pl) : path(p), model(m), plan(pl), format(m, pl) {}
  // Still open here: the file is given up (its datasets close after this, then the file).
  ~Impl() {
    if (file.get() >= 0) divert_to_memory(file.get());
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  std::string file_path;  // what H5Fcreate opens (`path` names it in messages)

  std::string cannot(const std::string& why) const { return path + ": cannot write: " + why; }
  void create(const Hdf5Options& o);
  void create_dataset(Group& g, const Hdf5Options& o);
  void open_to_append(const Hid& fapl, std::size_t keep_rows);  // Hdf5Options::append
  void flush();
  // The place of the next row in the held block; a full one (a block whose write failed) is written first, tried
  // again, never overrun.
  std::size_t next_row() {
    if (held_rows == block_rows) {
      const QuietErrors quiet;
      flush();
    }
    return held_rows;
  }
  // The row at next_row() is held: a block that is full is written.
  void row_held() {
    if (++held_rows == block_rows) {
      const QuietErrors quiet;
      flush();
    }
  }
  // A row given as its values in column order, each group taking its slice: copy(to, first value, count).
  template <class Copy>
  void hold_values(Copy&& copy) {
    const std::size_t k = next_row();
    std::size_t first = 0;
    for (Group& g : groups) {
      const std::size_t m = g.columns.size();
      copy(g.held.data() + k * m, first, m);
      first += m;
    }
    row_held();
  }
};

void Hdf5Writer::Impl::create(const Hdf5Options& o) {
  // The groups, their columns named as CsvFormat names them, in its order.
  const std::vector<std::string> names = format.column_names();
  std::size_t at = 0;
  auto take = [&](const char* name, std::size_t n, auto unit) -> Group* {
    if (n == 0) return nullptr;
    Group g{name, {names.begin() + at, names.begin() + at + n}, {}, false, {}, {}};
    for (std::size_t k = 0; k < n; ++k) g.units.push_back(unit(k));
    at += n;
    groups.push_back(std::move(g));
    return &groups.back();
  };
  groups.reserve(16);   // pointers into it are kept
  if (o.case_column) {  // first, as the batch CSV's `case` column
    groups.push_back(Group{"case", {"case"}, {""}, true, {}, {}});
    batch_case = &groups.back();
  }
  // (the q̇ and q̈ columns may be other coordinates than q's: OutputPlan::velocity_columns)
  auto coordinate_unit = [&](const std::vector<Index>& cols, const char* per_time) {
    return [&, per_time](std::size_t k) { return unit_of(model.coordinate_unit(cols[k]), per_time); };
  };
  const std::vector<Index>& q_cols = plan.coordinate_columns;
  const std::vector<Index>& qd_cols = plan.written_velocities();
  const std::vector<Index>& qdd_cols = plan.written_accelerations();
  t = take("t", 1, [](std::size_t) { return std::string("s"); });
  t->one_dimensional = true;
  q = take("q", q_cols.size(), coordinate_unit(q_cols, ""));
  qd = take("qd", qd_cols.size(), coordinate_unit(qd_cols, "/s"));
  qdd = take("qdd", qdd_cols.size(), coordinate_unit(qdd_cols, "/s^2"));
  std::vector<std::string> point_units;
  for (const OutputPoint& p : plan.points) {
    point_units.insert(point_units.end(), static_cast<std::size_t>(p.dimension()), "m");
    if (plan.velocities) point_units.insert(point_units.end(), static_cast<std::size_t>(p.dimension()), "m/s");
    if (plan.accelerations) point_units.insert(point_units.end(), static_cast<std::size_t>(p.dimension()), "m/s^2");
  }
  std::vector<std::string> joint_units;
  for (const OutputJoint& j : plan.joints) {
    const std::string u = j.measure == JointMeasure::kAngle ? "rad" : "m";
    joint_units.push_back(u);
    if (plan.velocities) joint_units.push_back(u + "/s");
    if (plan.accelerations) joint_units.push_back(u + "/s^2");
  }
  std::vector<std::string> orientation_units;
  for (std::size_t i = 0; i < plan.orientations.size(); ++i) {
    const std::string& form = plan.orientation_form.form;
    for (int d = 0; d < plan.orientation_form.size(); ++d)
      orientation_units.push_back(form == "matrix" ? "" : form == "axis_angle" ? (d == 3 ? "rad" : "") : "rad");
    if (plan.velocities) orientation_units.insert(orientation_units.end(), 3, "rad/s");
    if (plan.accelerations) orientation_units.insert(orientation_units.end(), 3, "rad/s^2");
  }
  const std::size_t per_driver = 1 + plan.velocities + plan.accelerations;
  const std::size_t residuals = plan.residual_columns.size() + plan.max_residual_column;
  auto none = [](std::size_t) { return std::string(); };
  for (Group* g : {take("points", point_units.size(), [&](std::size_t k) { return point_units[k]; }),
                   take("joints", joint_units.size(), [&](std::size_t k) { return joint_units[k]; }),
                   take("orientations", orientation_units.size(), [&](std::size_t k) { return orientation_units[k]; }),
                   take("drivers", plan.driver_columns.size() * per_driver, none), take("residuals", residuals, none)})
    if (g) outputs.push_back(g);
  if (plan.condition) {
    outputs.push_back(take("rcond", 1, none));
    outputs.back()->one_dimensional = true;
  }
  // The sensitivities' unit: the coordinate's per the parameter's, which the scene does not state ("/P").
  std::vector<std::string> sensitivity_units;
  for (const OutputSensitivity& p : plan.sensitivities) {
    const std::string per = "/" + p.name;
    for (Index j : q_cols) sensitivity_units.push_back(unit_of(model.coordinate_unit(j), "") + per);
    for (Index j : qd_cols) sensitivity_units.push_back(unit_of(model.coordinate_unit(j), "/s") + per);
    for (Index j : qdd_cols) sensitivity_units.push_back(unit_of(model.coordinate_unit(j), "/s^2") + per);
  }
  if (Group* g = take("sensitivities", sensitivity_units.size(), [&](std::size_t k) { return sensitivity_units[k]; }))
    outputs.push_back(g);
  // A driver's effort: a force where its first row is a length, a torque where it is an angle (J per the row's unit
  // otherwise, which the scene does not state: ""); its power in watts.
  std::vector<std::string> effort_units;
  for (Index c : plan.efforts.constraints) {
    const Unit u = model.row_unit(model.constraints()[static_cast<std::size_t>(c)].first_row);
    effort_units.push_back(u == Unit::kLength ? "N" : u == Unit::kAngle ? "N m" : "");
  }
  if (plan.efforts.power) effort_units.insert(effort_units.end(), plan.efforts.constraints.size(), "W");
  for (const OutputReaction& r : plan.efforts.reactions)  // forces, then moments (N m)
    for (int k = 0; k < (r.spatial ? 6 : 3); ++k) effort_units.push_back(k < (r.spatial ? 3 : 2) ? "N" : "N m");
  for (const OutputLoss& l : plan.efforts.losses) {  // a bearing's friction, then the power it dissipates
    if (l.bearing) effort_units.push_back(l.slide ? "N" : "N m");
    effort_units.push_back("W");
  }
  for (const OutputSensitivity& p : plan.sensitivities)  // ∂τ/∂p: the effort's unit per the parameter's ("/P")
    for (std::size_t i = 0; i < plan.efforts.constraints.size(); ++i)
      effort_units.push_back(effort_units[i] + "/" + p.name);
  if (plan.efforts.power)  // ∂P/∂p
    for (const OutputSensitivity& p : plan.sensitivities)
      effort_units.insert(effort_units.end(), plan.efforts.constraints.size(), "W/" + p.name);
  if (Group* g = take("efforts", effort_units.size(), [&](std::size_t k) { return effort_units[k]; }))
    outputs.push_back(g);
  if (at != names.size() || groups.size() > 16) throw Error(cannot("the columns do not match the CSV's (phiq bug)"));
  output_at.resize(outputs.size());
  for (const Group* g : outputs) output_size.push_back(g->columns.size());

  block_rows = choose_block_rows((names.size() + o.case_column) * sizeof(double), o);
  if (o.deflate < 0 || o.deflate > 9) throw Error(cannot("deflate level " + std::to_string(o.deflate) + " is not 0–9"));
  if (o.deflate > 0 && H5Zfilter_avail(H5Z_FILTER_DEFLATE) <= 0) throw Error(cannot("HDF5 has no deflate filter"));

  const Hid fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, cannot("file access list"));
  if (o.append) return open_to_append(fapl, o.append_after_rows);
  // The 1.8 file format: attributes larger than 64 KiB (the names of 10⁴ coordinates) go to dense storage, and
  // readers from HDF5 1.8 on (MATLAB, older h5py) can open the file.
  check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18), cannot("file format"));
  // No advisory lock: the file is the caller's own (the CLI writes a temporary nobody else knows), and file
  // systems without flock (some NFS mounts) would refuse it.
  check(H5Pset_file_locking(fapl.get(), false, true), cannot("file locking"));
  // No creation or modification times in the object headers (HDF5 stores them by default): the same run writes
  // the same bytes, which regression suites compare.
  const Hid fcpl = checked(H5Pcreate(H5P_FILE_CREATE), H5Pclose, cannot("file creation list"));
  check(H5Pset_obj_track_times(fcpl.get(), false), cannot("file creation list"));
  file =
      checked(H5Fcreate(file_path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), H5Fclose, path + ": cannot write");
  const std::string attrs = cannot("attributes");
  try {
    write_attribute(file.get(), "format", std::string("phiq results"));
    write_attribute(file.get(), "format_version", static_cast<long long>(kHdf5Format));
    write_attribute(file.get(), "phiq_version", std::string(kVersion));
    write_attribute(file.get(), "scene_path", o.scene_path);
    write_attribute(file.get(), "scene", o.scene_text);
    if (!o.parameters.empty()) {
      std::vector<std::string> names;
      std::vector<double> values;
      for (const auto& [n, v] : o.parameters) names.push_back(n), values.push_back(v);
      write_attribute(file.get(), "parameter_names", names);
      write_attribute(file.get(), "parameter_values", values);
    }
    if (o.case_column) write_attribute(file.get(), "batch_format_version", static_cast<long long>(kHdf5BatchFormat));
    for (Group& g : groups) create_dataset(g, o);
  } catch (const Error& e) {
    throw Error(path + ": cannot write: " + e.what());
  }
}

void Hdf5Writer::Impl::open_to_append(const Hid& fapl, std::size_t keep_rows) {
  check(H5Pset_file_locking(fapl.get(), false, true), cannot("file locking"));
  file = checked(H5Fopen(file_path.c_str(), H5F_ACC_RDWR, fapl.get()), H5Fclose, path + ": cannot write");
  // each group's dataset as this plan makes it: its columns, and as many rows as every other
  bool first = true;
  for (Group& g : groups) {
    const std::string what = cannot("not results of this layout: dataset /" + std::string(g.name));
    if (H5Lexists(file.get(), g.name, H5P_DEFAULT) <= 0) throw Error(what + " missing");
    g.dataset = checked(H5Dopen2(file.get(), g.name, H5P_DEFAULT), H5Dclose, what);
    const Hid space = checked(H5Dget_space(g.dataset.get()), H5Sclose, what);
    const int rank = H5Sget_simple_extent_ndims(space.get());
    hsize_t dims[2] = {0, 0};
    if (rank != (g.one_dimensional ? 1 : 2) || H5Sget_simple_extent_dims(space.get(), dims, nullptr) != rank ||
        (rank == 2 && dims[1] != g.columns.size()))
      throw Error(what + " has another shape");
    if (first) written_rows = dims[0], first = false;
    if (dims[0] != written_rows) throw Error(what + " has another number of rows");
    g.held.resize(block_rows * g.columns.size());
  }
  if (keep_rows >= written_rows) return;
  for (Group& g : groups) {
    const hsize_t extent[2] = {keep_rows, g.columns.size()};
    check(H5Dset_extent(g.dataset.get(), extent), cannot(std::string("dataset /") + g.name));
  }
  written_rows = keep_rows;
}

void Hdf5Writer::Impl::create_dataset(Group& g, const Hdf5Options& o) {
  const std::string what = std::string("dataset /") + g.name;
  const hsize_t n = g.columns.size();
  const int rank = g.one_dimensional ? 1 : 2;
  const hsize_t dims[2] = {0, n}, maxdims[2] = {H5S_UNLIMITED, n};
  // columns per chunk: a chunk of block_rows rows within kChunkBytes, the columns split evenly so that the last
  // chunk of a row is not mostly empty
  const hsize_t most = std::max<hsize_t>(1, kChunkBytes / (sizeof(double) * block_rows));
  const hsize_t pieces = (n + most - 1) / most;
  const hsize_t chunk[2] = {block_rows, (n + pieces - 1) / pieces};
  const Hid space = checked(H5Screate_simple(rank, dims, maxdims), H5Sclose, what);
  const Hid dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, what);
  check(H5Pset_chunk(dcpl.get(), rank, chunk), what);
  check(H5Pset_obj_track_times(dcpl.get(), false), what);          // the same bytes on every run (above)
  check(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), what);  // every element is written: no fill to write first
  if (o.deflate > 0) {
    if (o.shuffle) check(H5Pset_shuffle(dcpl.get()), what);
    check(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(o.deflate)), what);
  }
  g.dataset = checked(H5Dcreate2(file.get(), g.name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
                      H5Dclose, what);
  write_attribute(g.dataset.get(), "columns", g.columns);
  write_attribute(g.dataset.get(), "units", g.units);
  g.held.resize(block_rows * n);
}

void Hdf5Writer::Impl::flush() {
  if (held_rows == 0) return;
  for (Group& g : groups) {
    const std::string what = cannot(std::string("dataset /") + g.name);
    const int rank = g.one_dimensional ? 1 : 2;
    const hsize_t n = g.columns.size();
    const hsize_t extent[2] = {written_rows + held_rows, n}, start[2] = {written_rows, 0}, count[2] = {held_rows, n};
    check(H5Dset_extent(g.dataset.get(), extent), what);
    const Hid file_space = checked(H5Dget_space(g.dataset.get()), H5Sclose, what);
    check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr), what);
    const Hid memory = checked(H5Screate_simple(rank, count, nullptr), H5Sclose, what);
    check(H5Dwrite(g.dataset.get(), H5T_NATIVE_DOUBLE, memory.get(), file_space.get(), H5P_DEFAULT, g.held.data()),
          what);
  }
  written_rows += held_rows;
  held_rows = 0;
}

Hdf5Writer::Hdf5Writer(const std::string& path, const Model& model, const OutputPlan& plan, const Hdf5Options& options)
    : impl_(std::make_unique<Impl>(options.shown_path.empty() ? path : options.shown_path, model, plan)) {
  const QuietErrors quiet;
  impl_->file_path = path;
  impl_->format.set_naming(options.naming);
  impl_->create(options);
}

Hdf5Writer::~Hdf5Writer() {
  const QuietErrors quiet;
  impl_.reset();  // the datasets, then the file (members in reverse order), given up unless close() closed them
}

void Hdf5Writer::append_row(const StepView& s) {
  Impl& w = *impl_;
  if (w.closed) throw Error(w.cannot("already closed"));
  const std::size_t k = w.next_row();
  if (w.batch_case) throw Error(w.cannot("a batch's rows are given with their case (append_values)"));
  // −0 → 0, as the CSV writes it: the two files of a run hold the same doubles
  w.t->held[k] = stored_value(s.t);
  auto gather = [&](Group* g, const Eigen::VectorXd* v, const std::vector<Index>& cols, const char* what) {
    if (!g) return;
    if (!v) throw Error(std::string("Hdf5Writer: step has no ") + what);
    if (v->size() != w.model.num_coordinates()) throw Error("Hdf5Writer: step's vectors are not the model's size");
    const std::size_t n = cols.size();
    double* out = g->held.data() + k * n;
    for (std::size_t c = 0; c < n; ++c) out[c] = stored_value((*v)(cols[c]));
  };
  gather(w.q, &s.q, w.plan.coordinate_columns, "positions");
  gather(w.qd, s.qd, w.plan.written_velocities(), "velocities");
  gather(w.qdd, s.qdd, w.plan.written_accelerations(), "accelerations");
  if (!w.outputs.empty()) {
    for (std::size_t i = 0; i < w.outputs.size(); ++i)
      w.output_at[i] = w.outputs[i]->held.data() + k * w.output_size[i];
    w.format.append_output_values(s, w.output_at.data(), w.output_size.data(), w.outputs.size());
  }
  w.row_held();
}

void Hdf5Writer::append_values(const double* row) {
  Impl& w = *impl_;
  if (w.closed) throw Error(w.cannot("already closed"));
  w.hold_values([row](double* to, std::size_t first, std::size_t m) {
    std::transform(row + first, row + first + m, to, [](double v) { return stored_value(v); });
  });
}

void Hdf5Writer::append_packed_rows(const std::string& packed) {
  Impl& w = *impl_;
  if (w.closed) throw Error(w.cannot("already closed"));
  const std::size_t row_bytes = row_values() * sizeof(double);
  if (packed.size() % row_bytes != 0) throw Error(w.cannot("packed rows of another width (phiq bug)"));
  for (const char* row = packed.data(); row != packed.data() + packed.size(); row += row_bytes)
    w.hold_values([row](double* to, std::size_t first, std::size_t m) {
      std::memcpy(to, row + first * sizeof(double), m * sizeof(double));  // (`packed` holds bytes, not doubles)
    });
}

std::size_t Hdf5Writer::row_values() const {
  std::size_t n = 0;
  for (const Group& g : impl_->groups) n += g.columns.size();
  return n;
}

void Hdf5Writer::close() {
  Impl& w = *impl_;
  if (w.closed) throw Error(w.cannot("already closed"));
  const QuietErrors quiet;
  w.closed = true;
  w.flush();
  // everything to the disk while the file can still be given up (~Impl): a failed H5Fclose leaves it unusable
  if (H5Fflush(w.file.get(), H5F_SCOPE_LOCAL) < 0) throw Error(w.cannot(detail::h5::last_error()));
  for (Group& g : w.groups)
    if (!g.dataset.close()) throw Error(w.cannot(detail::h5::last_error()));
  if (!w.file.close()) throw Error(w.cannot(detail::h5::last_error()));  // H5Fclose writes the metadata
}

std::size_t Hdf5Writer::rows() const { return impl_->written_rows + impl_->held_rows; }
std::size_t Hdf5Writer::block_rows() const { return impl_->block_rows; }

}  // namespace phiq
