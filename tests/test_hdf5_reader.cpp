// read_hdf5_table / read_result_table (engine/src/output/hdf5_reader.cpp): files that are not phiq's HDF5 results
// are refused with one line naming the file and what is wrong; CSV goes to the CSV reader.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "output/hdf5_handle.hpp"
#include "phiq/phiq.hpp"
#include "scratch_path.hpp"

namespace {

using namespace phiq;
namespace h5 = phiq::detail::h5;
namespace fs = std::filesystem;

struct TempDir {
  fs::path dir = phiq::test::test_scratch_path("phiq_h5r_");
  TempDir() { fs::remove_all(dir), fs::create_directories(dir); }
  ~TempDir() { fs::remove_all(dir); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return (dir / name).string();
  }
};

std::string read_refusal(const std::string& path) {
  try {
    read_result_table(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// An HDF5 file made here with `root_format` / `version` attributes (when given) and a /t of 3 rows.
std::string make_file(const TempDir& tmp, const std::string& name, const char* root_format, long long version) {
  const std::string path = (tmp.dir / name).string();
  const h5::Hid f = h5::checked(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose, path);
  if (root_format) h5::write_attribute(f.get(), "format", std::string(root_format));
  if (version) h5::write_attribute(f.get(), "format_version", version);
  const hsize_t n = 3;
  const h5::Hid space = h5::checked(H5Screate_simple(1, &n, nullptr), H5Sclose, "t");
  const h5::Hid t = h5::checked(
      H5Dcreate2(f.get(), "t", H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose, "t");
  const double v[3] = {0.0, 0.5, 1.0};
  h5::check(H5Dwrite(t.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v), "t");
  h5::write_attribute(t.get(), "columns", std::vector<std::string>{"t"});
  return path;
}

TEST(Hdf5Reader, RefusesWhatIsNotPhiqResults) {
  TempDir tmp;
  const std::string text = tmp.write("text.h5", "t,x\n0,1\n");
  EXPECT_EQ(read_refusal(text).rfind(text + ": not a readable HDF5 file: ", 0), 0u) << read_refusal(text);
  // a real file cut after its signature and superblock start
  const std::string good = make_file(tmp, "good.h5", "phiq results", 1);
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string cut = tmp.write("cut.dat", bytes.substr(0, 100));
  EXPECT_TRUE(is_hdf5_file(cut));  // by its signature, whatever its name
  EXPECT_EQ(read_refusal(cut).rfind(cut + ": not a readable HDF5 file: ", 0), 0u) << read_refusal(cut);
  const std::string other = make_file(tmp, "other.h5", nullptr, 0);
  EXPECT_EQ(read_refusal(other), other + ": not phiq results: attribute 'format' is missing");
  const std::string v2 = make_file(tmp, "v2.h5", "phiq results", 2);
  EXPECT_EQ(read_refusal(v2), v2 + ": HDF5 results format version 2 (this phiq reads 1)");
  const std::string missing = (tmp.dir / "missing.h5").string();
  EXPECT_EQ(read_refusal(missing), missing + ": cannot read: No such file or directory");
  // the smallest valid file: /t alone
  const CsvTable t = read_result_table(good);
  EXPECT_EQ(t.columns, std::vector<std::string>{"t"});
  ASSERT_EQ(t.rows.size(), 3u);
  EXPECT_EQ(t.rows[2][0], 1.0);
  // CSV by content, whatever the name
  const CsvTable csv = read_result_table(tmp.write("x.dat", "t,x\n0,1\n"));
  EXPECT_EQ(csv.columns, (std::vector<std::string>{"t", "x"}));
}

}  // namespace
