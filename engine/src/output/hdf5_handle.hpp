// Owners of HDF5 identifiers (hid_t) and the translation of HDF5's error stack into phiq::Error: shared by the
// HDF5 results writer and reader (phiq/hdf5_writer.hpp, phiq/hdf5_reader.hpp), kept out of the public headers so
// that an embedder's translation units never see <hdf5.h>.
#pragma once

#include <hdf5.h>

#include <atomic>
#include <string>
#include <utility>
#include <vector>

#include "phiq/types.hpp"

namespace phiq::detail::h5 {

// Files whose H5Fclose failed (a full disk as it flushed): HDF5 1.10 leaves them half released, and closes them
// again, crashing, when the process exits (phiq::hdf5_file_left_open()).
inline std::atomic<int> files_left_open{0};

// One hid_t and the function that closes it (H5Fclose, H5Dclose, H5Sclose, H5Tclose, H5Pclose, H5Aclose, H5Gclose):
// every identifier is closed on every path, exceptions included, so that a failed write leaves no open file behind
// (an HDF5 file held open keeps its descriptor and its metadata cache).
class Hid {
 public:
  using Closer = herr_t (*)(hid_t);
  Hid() = default;
  Hid(hid_t id, Closer close) : id_(id), close_(close) {}
  ~Hid() { reset(); }
  Hid(Hid&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), close_(o.close_) {}
  Hid& operator=(Hid&& o) noexcept {
    if (this != &o) reset(), id_ = std::exchange(o.id_, H5I_INVALID_HID), close_ = o.close_;
    return *this;
  }
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;

  hid_t get() const { return id_; }
  // Closes now and reports whether HDF5 could (H5Fclose flushes the file: its failure is a write error).
  bool close() {
    const bool ok = id_ < 0 || close_(id_) >= 0;
    if (!ok && close_ == &H5Fclose) ++files_left_open;
    id_ = H5I_INVALID_HID;
    return ok;
  }
  void reset() { close(); }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer close_ = nullptr;
};

// HDF5 prints its error stack to stderr by default; phiq reports errors as one line of its own. Silences the
// automatic printing for the lifetime of the guard and restores the caller's handler after (an embedder may have
// installed one).
class QuietErrors {
 public:
  QuietErrors() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietErrors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// The most specific line of the current error stack: the system's reason when HDF5 quotes one ("error message =
// 'No space left on device'"), else the innermost description. "HDF5 error" when the stack is empty.
std::string last_error();

// `id` owned with `close`, or phiq::Error "WHAT: <last_error()>" when the call that made it failed (id < 0).
Hid checked(hid_t id, Hid::Closer close, const std::string& what);
// Throws phiq::Error "WHAT: <last_error()>" when an HDF5 call returned a negative status.
void check(herr_t status, const std::string& what);

// A variable-length UTF-8 string type (h5py reads it as str).
Hid string_type();
// Writes the attribute `name` of `object`: one string, an array of strings, or one integer.
void write_attribute(hid_t object, const char* name, const std::string& value);
void write_attribute(hid_t object, const char* name, const std::vector<std::string>& values);
void write_attribute(hid_t object, const char* name, long long value);
/// A list of little-endian float64 (a one-dimensional attribute; an empty list has an empty extent).
void write_attribute(hid_t object, const char* name, const std::vector<double>& values);
// Reads them back; throws phiq::Error "WHAT: ..." for a missing attribute or one of another type or shape.
std::string read_string_attribute(hid_t object, const char* name, const std::string& what);
std::vector<std::string> read_strings_attribute(hid_t object, const char* name, const std::string& what);
long long read_integer_attribute(hid_t object, const char* name, const std::string& what);
std::vector<double> read_doubles_attribute(hid_t object, const char* name, const std::string& what);

}  // namespace phiq::detail::h5
