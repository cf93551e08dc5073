#include "phiq/hdf5_reader.hpp"

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <unordered_map>

#include "output/hdf5_handle.hpp"
#include "phiq/hdf5_writer.hpp"

namespace phiq {

using detail::h5::checked;
using detail::h5::Hid;

namespace {

bool ends_with(const std::string& s, const char* suffix) {
  const std::size_t n = std::strlen(suffix);
  if (s.size() < n) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - n + i])) != suffix[i]) return false;
  return true;
}

// One dataset read whole: its column names and its rows × columns values, row-major.
struct Block {
  std::vector<std::string> columns;
  std::vector<double> values;
  hsize_t rows = 0;
};

// Whether a dataset of `elements` doubles can be stored in a file of `file_bytes`: deflate, the only filter phiq
// writes, shrinks data at most about 1032-fold. A corrupt or crafted file may claim 10¹¹ rows in a few KB, which
// would otherwise be allocated before a byte is read.
bool fits_in_file(hid_t dataset, double elements, double file_bytes) {
  const Hid dcpl(H5Dget_create_plist(dataset), H5Pclose);
  const bool filtered = dcpl.get() >= 0 && H5Pget_nfilters(dcpl.get()) > 0;
  return 8.0 * elements <= file_bytes * (filtered ? 1032.0 : 1.0);
}

Block read_block(hid_t file, const char* name, const std::string& path, double file_bytes) {
  const std::string what = path + ": dataset /" + name;
  Block b;
  const Hid d = checked(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose, what);
  const Hid type = checked(H5Dget_type(d.get()), H5Tclose, what);
  if (H5Tget_class(type.get()) != H5T_FLOAT) throw Error(what + " is not floating point");
  const Hid space = checked(H5Dget_space(d.get()), H5Sclose, what);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank != 1 && rank != 2) throw Error(what + " has rank " + std::to_string(rank) + ", not 1 or 2");
  hsize_t dims[2] = {0, 1};
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if (!fits_in_file(d.get(), static_cast<double>(dims[0]) * static_cast<double>(dims[1]), file_bytes))
    throw Error(what + " claims " + std::to_string(dims[0]) + " rows of " + std::to_string(dims[1]) +
                " columns, more than the file's " + std::to_string(static_cast<long long>(file_bytes)) +
                " bytes hold: a corrupt or truncated file");
  b.columns = detail::h5::read_strings_attribute(d.get(), "columns", what);
  if (b.columns.size() != dims[1])
    throw Error(what + ": " + std::to_string(dims[1]) + " columns, but its 'columns' attribute names " +
                std::to_string(b.columns.size()));
  b.rows = dims[0];
  b.values.resize(static_cast<std::size_t>(dims[0] * dims[1]));
  if (!b.values.empty())
    detail::h5::check(H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, b.values.data()), what);
  return b;
}

}  // namespace

bool has_hdf5_extension(const std::string& path) { return ends_with(path, ".h5") || ends_with(path, ".hdf5"); }

bool is_hdf5_file(const std::string& path) {
  static const unsigned char kSignature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  unsigned char head[8];
  return f && std::fread(head, 1, sizeof head, f.get()) == sizeof head && std::memcmp(head, kSignature, 8) == 0;
}

namespace {

// The file at `path` opened read-only, its format and version checked (read_hdf5_table()'s errors); its size in
// bytes into `file_bytes` (what a dataset's declared extent is held to).
Hid open_results(const std::string& path, double& file_bytes) {
  {  // the system's reason for a file that cannot be opened, before HDF5's
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) throw Error(path + ": cannot read: " + std::strerror(errno));
    if (std::fseek(f.get(), 0, SEEK_END) == 0) file_bytes = static_cast<double>(std::ftell(f.get()));
  }
  const Hid fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, path);
  detail::h5::check(H5Pset_file_locking(fapl.get(), false, true), path);  // read-only: a lock protects nothing
  const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get());
  if (id < 0) throw Error(path + ": not a readable HDF5 file: " + detail::h5::last_error());
  Hid file(id, H5Fclose);
  try {
    const std::string format = detail::h5::read_string_attribute(file.get(), "format", "not phiq results");
    if (format != "phiq results") throw Error("format '" + format + "' is not 'phiq results'");
    const long long version = detail::h5::read_integer_attribute(file.get(), "format_version", "phiq results");
    if (version != kHdf5Format)
      throw Error("HDF5 results format version " + std::to_string(version) + " (this phiq reads " +
                  std::to_string(kHdf5Format) + ")");
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  return file;
}

}  // namespace

Hdf5Provenance read_hdf5_provenance(const std::string& path) {
  const detail::h5::QuietErrors quiet;
  double file_bytes = 0.0;
  const Hid file = open_results(path, file_bytes);
  Hdf5Provenance p;
  p.scene_path = detail::h5::read_string_attribute(file.get(), "scene_path", path);
  p.scene_text = detail::h5::read_string_attribute(file.get(), "scene", path);
  if (H5Aexists(file.get(), "parameter_names") > 0) {
    const std::vector<std::string> names = detail::h5::read_strings_attribute(file.get(), "parameter_names", path);
    const std::vector<double> values = detail::h5::read_doubles_attribute(file.get(), "parameter_values", path);
    if (names.size() != values.size())
      throw Error(path + ": " + std::to_string(names.size()) + " parameter names but " + std::to_string(values.size()) +
                  " values");
    for (std::size_t k = 0; k < names.size(); ++k) p.parameters.emplace_back(names[k], values[k]);
  }
  return p;
}

CsvTable read_hdf5_table(const std::string& path) {
  const detail::h5::QuietErrors quiet;
  double file_bytes = 0.0;
  const Hid file = open_results(path, file_bytes);
  CsvTable table;
  table.path = path;
  std::vector<Block> blocks;
  // a batch's file (hdf5_writer.hpp, Hdf5Options::case_column) has /case first: the column `case` of its CSV
  for (const char* name : {"case", "t", "q", "qd", "qdd", "points", "joints", "orientations", "drivers", "residuals",
                           "rcond", "sensitivities", "efforts"}) {
    const htri_t exists = H5Lexists(file.get(), name, H5P_DEFAULT);
    if (exists < 0) throw Error(path + ": " + detail::h5::last_error());
    if (exists == 0) {
      if (std::string(name) == "case") continue;
      if (blocks.size() < 2 && std::string(name) == "t") throw Error(path + ": no dataset /t");
      continue;
    }
    blocks.push_back(read_block(file.get(), name, path, file_bytes));
    if (blocks.back().rows != blocks.front().rows)
      throw Error(path + ": dataset /" + name + " has " + std::to_string(blocks.back().rows) + " rows, /t has " +
                  std::to_string(blocks.front().rows));
  }
  std::unordered_map<std::string, std::size_t> seen;
  for (const Block& b : blocks)
    for (const std::string& c : b.columns) {
      if (c.empty())
        throw Error(path + ": empty column name (column " + std::to_string(table.columns.size() + 1) + ")");
      if (!seen.emplace(c, table.columns.size() + 1).second) throw Error(path + ": duplicate column name '" + c + "'");
      table.columns.push_back(c);
    }
  const std::size_t rows = static_cast<std::size_t>(blocks.front().rows);
  table.rows.assign(rows, {});
  for (std::size_t r = 0; r < rows; ++r) {
    std::vector<double>& row = table.rows[r];
    row.reserve(table.columns.size());
    for (const Block& b : blocks) {
      const std::size_t n = b.columns.size();
      row.insert(row.end(), b.values.begin() + static_cast<std::ptrdiff_t>(r * n),
                 b.values.begin() + static_cast<std::ptrdiff_t>((r + 1) * n));
    }
  }
  return table;
}

void silence_hdf5_errors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

bool hdf5_file_left_open() { return detail::h5::files_left_open.load() > 0; }

CsvTable read_result_table(const std::string& path) {
  if (is_hdf5_file(path) || has_hdf5_extension(path)) return read_hdf5_table(path);
  return read_csv_table(path);
}

}  // namespace phiq
