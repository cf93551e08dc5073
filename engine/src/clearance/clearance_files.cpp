// A ClearanceReport as CSV text and as an HDF5 file (phiq/clearance_files.hpp; layout in tools/README.md).
#include "phiq/clearance_files.hpp"

#include <cmath>

#include "output/hdf5_handle.hpp"
#include "phiq/text.hpp"
#include "phiq/types.hpp"
#include "phiq/version.hpp"

namespace phiq {

std::vector<std::string> clearance_pair_names(const ClearanceReport& report, const std::vector<Part>& parts) {
  std::vector<std::string> names;
  names.reserve(report.pairs.size());
  for (const PairClearance& p : report.pairs)
    names.push_back(parts[static_cast<std::size_t>(p.a)].name + "." + parts[static_cast<std::size_t>(p.b)].name);
  return names;
}

std::string clearance_csv(const ClearanceReport& report, const std::vector<Part>& parts) {
  std::string text = "t";
  for (const std::string& n : clearance_pair_names(report, parts)) text.append(",").append(n);
  text += '\n';
  for (std::size_t k = 0; k < report.times.size(); ++k) {
    text += shortest(report.times[k]);
    for (const PairClearance& p : report.pairs) text.append(",").append(shortest(p.row_distance[k]));
    text += '\n';
  }
  return text;
}

namespace {

using detail::h5::check;
using detail::h5::checked;
using detail::h5::Hid;
using detail::h5::write_attribute;

void clearance_double_attribute(hid_t object, const char* name, double value) {
  const std::string what = std::string("attribute '") + name + "'";
  const Hid space = checked(H5Screate(H5S_SCALAR), H5Sclose, what);
  const Hid a =
      checked(H5Acreate2(object, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  check(H5Awrite(a.get(), H5T_NATIVE_DOUBLE, &value), what);
}

// A float64 dataset of `rows` × columns.size() values (row-major in `values`; one-dimensional when `vector`), with
// its `columns` and `units` attributes. Contiguous: the report is in memory whole, and small.
void clearance_dataset(hid_t file, const char* name, std::size_t rows, const std::vector<std::string>& columns,
                       const std::vector<std::string>& units, const std::vector<double>& values, bool vector = false) {
  const std::string what = std::string("dataset '") + name + "'";
  const hsize_t dims[2] = {rows, columns.size()};
  const Hid space = checked(H5Screate_simple(vector ? 1 : 2, dims, nullptr), H5Sclose, what);
  const Hid dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, what);
  check(H5Pset_obj_track_times(dcpl.get(), false), what);  // the same report, the same bytes
  const Hid d = checked(H5Dcreate2(file, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
                        H5Dclose, what);
  if (!values.empty()) check(H5Dwrite(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), what);
  write_attribute(d.get(), "columns", columns);
  write_attribute(d.get(), "units", units);
}

// −0 stored as 0, as the results' writer stores it (a CSV's "-0" reads back as −0: equal all the same).
double clearance_stored(double v) { return v == 0.0 ? 0.0 : v; }

void append_point(std::vector<double>& v, kin3::V3 p) {
  v.push_back(clearance_stored(p.x)), v.push_back(clearance_stored(p.y)), v.push_back(clearance_stored(p.z));
}

void write_clearance_contents(hid_t file, const ClearanceReport& r, const std::vector<Part>& parts,
                              const ClearanceHdf5Options& o) {
  const std::vector<std::string> names = clearance_pair_names(r, parts);
  write_attribute(file, "format", std::string("phiq clearance"));
  write_attribute(file, "format_version", static_cast<long long>(kClearanceHdf5Format));
  write_attribute(file, "phiq_version", std::string(kVersion));
  write_attribute(file, "scene_path", o.scene_path);
  write_attribute(file, "scene", o.scene_text);
  if (!o.parameters.empty()) {
    std::vector<std::string> pn;
    std::vector<double> pv;
    for (const auto& [n, v] : o.parameters) pn.push_back(n), pv.push_back(v);
    write_attribute(file, "parameter_names", pn);
    write_attribute(file, "parameter_values", pv);
  }
  clearance_double_attribute(file, "threshold", r.threshold);
  write_attribute(file, "pairs", names);
  write_attribute(file, "pairs_selected", static_cast<long long>(r.pairs_selected));
  write_attribute(file, "pairs_measured", static_cast<long long>(r.pairs_measured));
  write_attribute(file, "positions_solved", static_cast<long long>(r.positions_solved));
  write_attribute(file, "interferes", static_cast<long long>(r.interferes()));
  write_attribute(file, "bound_held", static_cast<long long>(r.bound_held()));

  const std::size_t rows = r.times.size(), k = r.pairs.size();
  std::vector<double> values;
  for (double t : r.times) values.push_back(clearance_stored(t));
  clearance_dataset(file, "t", rows, {"t"}, {"s"}, values, true);
  values.clear();
  for (std::size_t row = 0; row < rows; ++row)
    for (const PairClearance& p : r.pairs) values.push_back(clearance_stored(p.row_distance[row]));
  clearance_dataset(file, "distance", rows, names, std::vector<std::string>(k, "m"), values);

  // each pair's worst pose: one row per pair, in /distance's column order
  values.clear();
  for (const PairClearance& p : r.pairs) {
    values.push_back(clearance_stored(p.worst.t));
    values.push_back(clearance_stored(p.worst.at.distance));
    append_point(values, p.worst.at.point_a);
    append_point(values, p.worst.at.point_b);
    append_point(values, p.worst.at.normal);
    values.push_back(p.worst.refined ? 1.0 : 0.0);
    values.push_back(static_cast<double>(p.unproven_intervals));
  }
  clearance_dataset(file, "worst", k,
                    {"t", "distance", "point_a.x", "point_a.y", "point_a.z", "point_b.x", "point_b.y", "point_b.z",
                     "normal.x", "normal.y", "normal.z", "refined", "unproven_intervals"},
                    {"s", "m", "m", "m", "m", "m", "m", "m", "", "", "", "", ""}, values);

  std::vector<std::string> columns, units;
  for (const std::string& p : r.parameters) columns.push_back("distance.d_" + p), units.push_back("m/" + p);
  values.clear();
  for (const PairClearance& p : r.pairs)
    for (std::size_t j = 0; j < r.parameters.size(); ++j)
      values.push_back(j < p.worst.sensitivities.size() ? clearance_stored(p.worst.sensitivities[j]) : std::nan(""));
  clearance_dataset(file, "sensitivities", k, columns, units, values);

  values.clear();
  std::size_t intervals = 0;
  for (std::size_t i = 0; i < k; ++i)
    for (const InterferenceInterval& in : r.pairs[i].interference) {
      values.push_back(static_cast<double>(i));
      values.push_back(clearance_stored(in.entry));
      values.push_back(clearance_stored(in.exit));
      ++intervals;
    }
  clearance_dataset(file, "interference", intervals, {"pair", "entry", "exit"}, {"", "s", "s"}, values);

  // every local minimum of every pair, in pair then time order (the worst is one of its pair's)
  values.clear();
  std::size_t minima = 0;
  for (std::size_t i = 0; i < k; ++i)
    for (const ClearanceMinimum& m : r.pairs[i].minima) {
      values.push_back(static_cast<double>(i));
      values.push_back(clearance_stored(m.t));
      values.push_back(clearance_stored(m.at.distance));
      values.push_back(m.refined ? 1.0 : 0.0);
      for (std::size_t j = 0; j < r.parameters.size(); ++j)
        values.push_back(j < m.sensitivities.size() ? clearance_stored(m.sensitivities[j]) : std::nan(""));
      ++minima;
    }
  std::vector<std::string> minima_columns{"pair", "t", "distance", "refined"}, minima_units{"", "s", "m", ""};
  minima_columns.insert(minima_columns.end(), columns.begin(), columns.end());
  minima_units.insert(minima_units.end(), units.begin(), units.end());
  clearance_dataset(file, "minima", minima, minima_columns, minima_units, values);
}

}  // namespace

void write_clearance_hdf5(const std::string& path, const ClearanceReport& report, const std::vector<Part>& parts,
                          const ClearanceHdf5Options& options) {
  const std::string shown = options.shown_path.empty() ? path : options.shown_path;
  const detail::h5::QuietErrors quiet;
  try {
    const Hid fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "file access list");
    // the results' choices (hdf5_writer.cpp): HDF5 1.8's format, no advisory lock, no times in object headers
    check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18), "file format");
    check(H5Pset_file_locking(fapl.get(), false, true), "file locking");
    const Hid fcpl = checked(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "file creation list");
    check(H5Pset_obj_track_times(fcpl.get(), false), "file creation list");
    Hid file = checked(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), H5Fclose, "create");
    write_clearance_contents(file.get(), report, parts, options);
    if (!file.close()) throw Error("close: " + detail::h5::last_error());
  } catch (const Error& e) {
    throw Error(shown + ": cannot write: " + e.what());
  }
}

}  // namespace phiq
