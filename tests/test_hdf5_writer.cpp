// Hdf5Writer (engine/src/output/hdf5_writer.cpp): the file holds the doubles of the CSV of the same rows bit for bit,
// in datasets of the documented layout (tools/README.md, "HDF5 results"), with their names, units and the root
// attributes; rows are written a block at a time and chunks fit the expected row count.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "output/hdf5_handle.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"
#include "scratch_path.hpp"

namespace {

using namespace phiq;
namespace h5 = phiq::detail::h5;
namespace fs = std::filesystem;

struct ScratchDir {
  fs::path dir = phiq::test::test_scratch_path("phiq_h5_");
  ScratchDir() { fs::remove_all(dir), fs::create_directories(dir); }
  ~ScratchDir() { fs::remove_all(dir); }
};

// The sweep of `scene_text`, written to `h5_path` by an Hdf5Writer with `options` and to CSV text by CsvFormat.
struct Written {
  std::string csv;
  std::size_t rows = 0, block_rows = 0;
};
Written write_both(const Scene& scene, const std::string& h5_path, Hdf5Options options) {
  Written w;
  Eigen::VectorXd q = scene.model->initial_positions();
  std::unique_ptr<Model> solved;
  AssemblySummary as;
  EXPECT_EQ(prepare_square(*scene.model, scene.sweep.t_begin, {}, q, &solved, &as), SolveStatus::kSuccess);
  const Model& model = solved ? *solved : *scene.model;
  Workspace ws(model);
  ws.q = q;
  CsvFormat csv(*scene.model, scene.sweep);
  w.csv = csv.header();
  Hdf5Writer h5w(h5_path, *scene.model, scene.sweep, options);
  SweepSummary sum;
  (void)run_sweep(
      model, scene.sweep, ws,
      [&](const StepView& s) {  // its status is sum.status, checked below
        csv.append_row(s, w.csv);
        h5w.append_row(s);
        return true;
      },
      &sum);
  EXPECT_EQ(sum.status, SolveStatus::kSuccess) << sum.message;
  w.rows = h5w.rows();
  w.block_rows = h5w.block_rows();
  h5w.close();
  return w;
}

// Every cell of `a` has the bits of the same cell of `b` (0 == -0 would pass ==; the files must hold the same double).
void expect_same_bits(const CsvTable& a, const CsvTable& b) {
  ASSERT_EQ(a.columns, b.columns);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (std::size_t r = 0; r < a.rows.size(); ++r)
    for (std::size_t c = 0; c < a.columns.size(); ++c)
      ASSERT_EQ(std::memcmp(&a.rows[r][c], &b.rows[r][c], sizeof(double)), 0)
          << a.columns[c] << " row " << r << ": " << a.rows[r][c] << " vs " << b.rows[r][c];
}

hsize_t rows_of(hid_t file, const char* name, hsize_t* columns = nullptr) {
  const h5::Hid d = h5::checked(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose, name);
  const h5::Hid space = h5::checked(H5Dget_space(d.get()), H5Sclose, name);
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if (columns) *columns = rank == 1 ? 0 : dims[1];
  return dims[0];
}

// The four-bar with every kind of output, over 73 rows in blocks of 5 (the buffer holds 5 rows): the read-back
// table equals the CSV's bit for bit, and the datasets, their shapes, names and units are the documented ones.
TEST(Hdf5Writer, HoldsTheCsvDoublesInTheDocumentedLayout) {
  ScratchDir tmp;
  const Scene scene = parse_scene(test::kFourbarOutputs, "fourbar_outputs.yaml");
  const std::string path = (tmp.dir / "r.h5").string();
  Hdf5Options o;
  o.scene_path = "fourbar_outputs.yaml";
  o.scene_text = test::kFourbarOutputs;
  // t, 8 q, 8 q̇, points B and P with velocities (8), motor f and df (2), rocker.residual, residual, rcond: 30
  o.buffer_bytes = 5 * 30 * sizeof(double);
  const Written w = write_both(scene, path, o);
  EXPECT_EQ(w.rows, 73u);
  EXPECT_EQ(w.block_rows, 5u);
  expect_same_bits(read_hdf5_table(path), parse_csv_table(w.csv, "r.csv"));

  const h5::QuietErrors quiet;
  const h5::Hid f = h5::checked(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, path);
  EXPECT_EQ(h5::read_string_attribute(f.get(), "format", "root"), "phiq results");
  EXPECT_EQ(h5::read_integer_attribute(f.get(), "format_version", "root"), 1);
  EXPECT_EQ(h5::read_string_attribute(f.get(), "phiq_version", "root"), std::string(kVersion));
  EXPECT_EQ(h5::read_string_attribute(f.get(), "scene_path", "root"), "fourbar_outputs.yaml");
  EXPECT_EQ(h5::read_string_attribute(f.get(), "scene", "root"), test::kFourbarOutputs);
  hsize_t cols = 0;
  EXPECT_EQ(rows_of(f.get(), "t", &cols), 73u);
  EXPECT_EQ(cols, 0u);  // one-dimensional
  for (const char* name : {"q", "qd"}) {
    EXPECT_EQ(rows_of(f.get(), name, &cols), 73u);
    EXPECT_EQ(cols, 8u) << name;
  }
  EXPECT_EQ(H5Lexists(f.get(), "qdd", H5P_DEFAULT), 0);  // accelerations not asked for
  EXPECT_EQ(rows_of(f.get(), "points", &cols), 73u);
  EXPECT_EQ(cols, 8u);
  EXPECT_EQ(rows_of(f.get(), "drivers", &cols), 73u);
  EXPECT_EQ(cols, 2u);
  EXPECT_EQ(rows_of(f.get(), "residuals", &cols), 73u);
  EXPECT_EQ(cols, 2u);
  EXPECT_EQ(rows_of(f.get(), "rcond", &cols), 73u);
  auto attr = [&](const char* dataset, const char* name) {
    const h5::Hid d = h5::checked(H5Dopen2(f.get(), dataset, H5P_DEFAULT), H5Dclose, dataset);
    return h5::read_strings_attribute(d.get(), name, dataset);
  };
  using V = std::vector<std::string>;
  EXPECT_EQ(attr("q", "columns"), (V{"theta2", "xA", "yA", "x3", "y3", "psi3", "xB", "yB"}));
  EXPECT_EQ(attr("q", "units"), (V{"rad", "m", "m", "m", "m", "rad", "m", "m"}));
  EXPECT_EQ(attr("qd", "columns")[0], "theta2.v");
  EXPECT_EQ(attr("qd", "units"), (V{"rad/s", "m/s", "m/s", "m/s", "m/s", "rad/s", "m/s", "m/s"}));
  EXPECT_EQ(attr("points", "columns"), (V{"B.x", "B.y", "B.vx", "B.vy", "P.x", "P.y", "P.vx", "P.vy"}));
  EXPECT_EQ(attr("points", "units"), (V{"m", "m", "m/s", "m/s", "m", "m", "m/s", "m/s"}));
  EXPECT_EQ(attr("drivers", "columns"), (V{"motor.f", "motor.df"}));
  EXPECT_EQ(attr("residuals", "columns"), (V{"rocker.residual", "residual"}));
  EXPECT_EQ(attr("t", "columns"), (V{"t"}));
  EXPECT_EQ(attr("t", "units"), (V{"s"}));
  EXPECT_EQ(attr("rcond", "columns"), (V{"rcond"}));
}

// With the row count known, the block (= chunk) holds as many rows as fit, or fewer when that fills the last chunk
// better: 73 rows with room for 34 go in blocks of 25 (3 × 25 = 75: 2 rows of slack; 34 would leave 29), and the
// uncompressed /q takes exactly those 75 rows × 8 doubles on disk.
TEST(Hdf5Writer, ChunksFitTheExpectedRows) {
  ScratchDir tmp;
  const Scene scene = parse_scene(test::kFourbarOutputs, "fourbar_outputs.yaml");
  const std::string path = (tmp.dir / "r.h5").string();
  Hdf5Options o;
  o.expected_rows = 73;
  o.buffer_bytes = 34 * 30 * sizeof(double);
  const Written w = write_both(scene, path, o);
  EXPECT_EQ(w.block_rows, 25u);
  {
    const h5::Hid f = h5::checked(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, path);
    const h5::Hid q = h5::checked(H5Dopen2(f.get(), "q", H5P_DEFAULT), H5Dclose, "q");
    EXPECT_EQ(H5Dget_storage_size(q.get()), 75u * 8u * sizeof(double));
  }  // closed: read_hdf5_table opens it without a lock, which HDF5 refuses while it is open with one
  expect_same_bits(read_hdf5_table(path), parse_csv_table(w.csv, "r.csv"));
}

// Deflate with shuffle stores the same doubles (lossless), in less room than without.
TEST(Hdf5Writer, DeflateIsLossless) {
  ScratchDir tmp;
  const Scene scene = parse_scene(test::kFourbarOutputs, "fourbar_outputs.yaml");
  Hdf5Options o;
  o.expected_rows = 73;
  const std::string plain = (tmp.dir / "plain.h5").string(), packed = (tmp.dir / "packed.h5").string();
  const Written a = write_both(scene, plain, o);
  o.deflate = 4, o.shuffle = true;
  const Written b = write_both(scene, packed, o);
  expect_same_bits(read_hdf5_table(packed), parse_csv_table(b.csv, "b.csv"));
  expect_same_bits(read_hdf5_table(packed), read_hdf5_table(plain));
  EXPECT_LT(fs::file_size(packed), fs::file_size(plain));
}

// Rows packed as CsvFormat::append_values packs them, given 7 at a time across blocks of 5 (as a parallel sweep's
// chunks hand them to phiq run's writer), make the file append_row() makes: the CSV's doubles bit for bit. Bytes
// that are not whole rows are refused, naming the path.
TEST(Hdf5Writer, PackedRowsHoldTheCsvDoubles) {
  ScratchDir tmp;
  const Scene scene = parse_scene(test::kFourbarOutputs, "fourbar_outputs.yaml");
  Eigen::VectorXd q = scene.model->initial_positions();
  std::unique_ptr<Model> solved;
  AssemblySummary as;
  ASSERT_EQ(prepare_square(*scene.model, scene.sweep.t_begin, {}, q, &solved, &as), SolveStatus::kSuccess);
  Workspace ws(*solved);
  ws.q = q;
  const CsvFormat csv(*scene.model, scene.sweep);
  const std::string path = (tmp.dir / "r.h5").string();
  Hdf5Options o;
  o.buffer_bytes = 5 * 30 * sizeof(double);
  Hdf5Writer h5w(path, *scene.model, scene.sweep, o);
  ASSERT_EQ(h5w.row_values(), csv.num_values());
  std::string text = csv.header(), packed;
  std::vector<double> row(csv.num_values());
  SweepSummary sum;
  (void)run_sweep(
      *solved, scene.sweep, ws,
      [&](const StepView& s) {  // its status is sum.status, checked below
        csv.append_row(s, text);
        csv.append_values(s, row.data());
        packed.append(reinterpret_cast<const char*>(row.data()), row.size() * sizeof(double));
        if (packed.size() == 7 * row.size() * sizeof(double)) h5w.append_packed_rows(packed), packed.clear();
        return true;
      },
      &sum);
  ASSERT_EQ(sum.status, SolveStatus::kSuccess) << sum.message;
  h5w.append_packed_rows(packed);
  EXPECT_EQ(h5w.rows(), 73u);
  try {
    h5w.append_packed_rows(std::string(sizeof(double), '\0'));
    FAIL() << "a part of a row accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": cannot write", 0), 0u) << e.what();
  }
  EXPECT_EQ(h5w.rows(), 73u);
  h5w.close();
  expect_same_bits(read_hdf5_table(path), parse_csv_table(text, "r.csv"));
}

// Errors are phiq::Error naming the path (or the name shown for it), never HDF5's printed stack.
TEST(Hdf5Writer, ErrorsNameThePath) {
  ScratchDir tmp;
  const Scene scene = parse_scene(test::kFourbarOutputs, "fourbar_outputs.yaml");
  const std::string missing = (tmp.dir / "nodir" / "r.h5").string();
  try {
    Hdf5Writer w(missing, *scene.model, scene.sweep);
    FAIL() << "created a file in a missing directory";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(missing + ": cannot write", 0), 0u) << e.what();
  }
  Hdf5Options o;
  o.shown_path = "shown.h5";
  o.deflate = 12;
  try {
    Hdf5Writer w((tmp.dir / "r.h5").string(), *scene.model, scene.sweep, o);
    FAIL() << "deflate 12 accepted";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "shown.h5: cannot write: deflate level 12 is not 0–9");
  }
  Hdf5Writer w((tmp.dir / "r.h5").string(), *scene.model, scene.sweep);
  w.close();
  const Eigen::VectorXd q = scene.model->initial_positions();
  EXPECT_THROW(w.append_row(StepView{0, 0.0, q, nullptr, nullptr}), Error);
  EXPECT_THROW(w.close(), Error);
}

}  // namespace
