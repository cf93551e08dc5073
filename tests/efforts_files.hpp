// The efforts' files as `phiq run` writes them: a scene's sweep written to HDF5 and as CSV text, and a dataset's
// string attributes (`columns`, `units`) read back; what the efforts' and losses' file tests read.
#pragma once

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "output/hdf5_handle.hpp"
#include "phiq/phiq.hpp"

namespace phiq::test {

// The sweep of `s` from its initial positions written to HDF5 at `path`; returns the CSV text of the same rows.
inline std::string write_efforts_files(const Scene& s, const std::string& path) {
  CsvFormat f(*s.model, s.sweep);
  std::string csv = f.header();
  Hdf5Writer h5(path, *s.model, s.sweep);
  Workspace ws(*s.model);
  ws.q = s.model->initial_positions();
  EXPECT_EQ(run_sweep(
                *s.model, s.sweep, ws,
                [&](const StepView& v) {
                  f.append_row(v, csv);
                  h5.append_row(v);
                  return true;
                },
                nullptr),
            SolveStatus::kSuccess);
  h5.close();
  return csv;
}

// The string attribute `attribute` of dataset `dataset` in the HDF5 file at `path`.
inline std::vector<std::string> hdf5_strings(const std::string& path, const char* dataset, const char* attribute) {
  const detail::h5::QuietErrors quiet;
  const detail::h5::Hid file = detail::h5::checked(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, path);
  const detail::h5::Hid d = detail::h5::checked(H5Dopen2(file.get(), dataset, H5P_DEFAULT), H5Dclose, dataset);
  return detail::h5::read_strings_attribute(d.get(), attribute, dataset);
}

}  // namespace phiq::test
