#include "output/hdf5_handle.hpp"

#include <cstring>

namespace phiq::detail::h5 {

namespace {

struct ErrorWalk {
  std::string innermost, system;
};

herr_t visit(unsigned /*n*/, const H5E_error2_t* e, void* data) {
  auto& w = *static_cast<ErrorWalk*>(data);
  const std::string desc = e->desc ? e->desc : "";
  if (w.innermost.empty()) w.innermost = desc;
  // the sec2 driver quotes strerror: the reason a user can act on (a full disk, a permission)
  static const char kQuote[] = "error message = '";
  if (const auto at = desc.find(kQuote); w.system.empty() && at != std::string::npos) {
    const auto from = at + sizeof kQuote - 1, to = desc.find('\'', from);
    w.system = desc.substr(from, to == std::string::npos ? std::string::npos : to - from);
  }
  return 0;
}

}  // namespace

std::string last_error() {
  ErrorWalk w;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, visit, &w);
  H5Eclear2(H5E_DEFAULT);
  std::string s = !w.system.empty() ? w.system : !w.innermost.empty() ? w.innermost : "HDF5 error";
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';  // one line
  return s;
}

Hid checked(hid_t id, Hid::Closer close, const std::string& what) {
  if (id < 0) throw Error(what + ": " + last_error());
  return Hid(id, close);
}

void check(herr_t status, const std::string& what) {
  if (status < 0) throw Error(what + ": " + last_error());
}

Hid string_type() {
  Hid t = checked(H5Tcopy(H5T_C_S1), H5Tclose, "string type");
  check(H5Tset_size(t.get(), H5T_VARIABLE), "string type");
  check(H5Tset_cset(t.get(), H5T_CSET_UTF8), "string type");
  return t;
}

namespace {

void write_strings(hid_t object, const char* name, const std::vector<const char*>& p, bool scalar) {
  const std::string what = std::string("attribute '") + name + "'";
  const Hid type = string_type();
  const hsize_t n = p.size();
  const Hid space = checked(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose, what);
  const Hid a = checked(H5Acreate2(object, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  if (n > 0) check(H5Awrite(a.get(), type.get(), p.data()), what);
}

}  // namespace

void write_attribute(hid_t object, const char* name, const std::string& value) {
  write_strings(object, name, {value.c_str()}, true);
}

void write_attribute(hid_t object, const char* name, const std::vector<std::string>& values) {
  std::vector<const char*> p;
  p.reserve(values.size());
  for (const auto& v : values) p.push_back(v.c_str());
  write_strings(object, name, p, false);
}

void write_attribute(hid_t object, const char* name, long long value) {
  const std::string what = std::string("attribute '") + name + "'";
  const Hid space = checked(H5Screate(H5S_SCALAR), H5Sclose, what);
  const Hid a = checked(H5Acreate2(object, name, H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  check(H5Awrite(a.get(), H5T_NATIVE_LLONG, &value), what);
}

void write_attribute(hid_t object, const char* name, const std::vector<double>& values) {
  const std::string what = std::string("attribute '") + name + "'";
  const hsize_t n = values.size();
  const Hid space = checked(H5Screate_simple(1, &n, nullptr), H5Sclose, what);
  const Hid a =
      checked(H5Acreate2(object, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  if (n > 0) check(H5Awrite(a.get(), H5T_NATIVE_DOUBLE, values.data()), what);
}

namespace {

// The attribute's strings (variable-length, as phiq writes them), with the number of elements of its space.
std::vector<std::string> read_strings(hid_t object, const char* name, const std::string& what, bool scalar) {
  const std::string where = what + ": attribute '" + name + "'";
  if (const htri_t exists = H5Aexists(object, name); exists <= 0)  // (< 0: unreadable, a corrupt header)
    throw Error(where + (exists < 0 ? ": " + last_error() : std::string(" is missing")));
  const Hid a = checked(H5Aopen(object, name, H5P_DEFAULT), H5Aclose, where);
  const Hid ftype = checked(H5Aget_type(a.get()), H5Tclose, where);
  if (H5Tget_class(ftype.get()) != H5T_STRING || H5Tis_variable_str(ftype.get()) <= 0)
    throw Error(where + " is not a variable-length string");
  const Hid space = checked(H5Aget_space(a.get()), H5Sclose, where);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (scalar ? rank != 0 : rank != 1) throw Error(where + (scalar ? " is not one string" : " is not a list"));
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0) throw Error(where + ": " + last_error());
  std::vector<char*> p(static_cast<std::size_t>(n), nullptr);
  const Hid type = string_type();
  if (n > 0) check(H5Aread(a.get(), type.get(), p.data()), where);
  std::vector<std::string> out;
  out.reserve(p.size());
  for (char* s : p) out.emplace_back(s ? s : "");
  if (n > 0) H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, p.data());
  return out;
}

}  // namespace

std::string read_string_attribute(hid_t object, const char* name, const std::string& what) {
  return read_strings(object, name, what, true).at(0);
}

std::vector<std::string> read_strings_attribute(hid_t object, const char* name, const std::string& what) {
  return read_strings(object, name, what, false);
}

long long read_integer_attribute(hid_t object, const char* name, const std::string& what) {
  const std::string where = what + ": attribute '" + name + "'";
  if (const htri_t exists = H5Aexists(object, name); exists <= 0)  // (< 0: unreadable, a corrupt header)
    throw Error(where + (exists < 0 ? ": " + last_error() : std::string(" is missing")));
  const Hid a = checked(H5Aopen(object, name, H5P_DEFAULT), H5Aclose, where);
  const Hid ftype = checked(H5Aget_type(a.get()), H5Tclose, where);
  const Hid space = checked(H5Aget_space(a.get()), H5Sclose, where);
  if (H5Tget_class(ftype.get()) != H5T_INTEGER || H5Sget_simple_extent_npoints(space.get()) != 1)
    throw Error(where + " is not one integer");
  long long v = 0;
  check(H5Aread(a.get(), H5T_NATIVE_LLONG, &v), where);
  return v;
}

std::vector<double> read_doubles_attribute(hid_t object, const char* name, const std::string& what) {
  const std::string where = what + ": attribute '" + name + "'";
  if (H5Aexists(object, name) <= 0) throw Error(where + " is missing");
  const Hid a = checked(H5Aopen(object, name, H5P_DEFAULT), H5Aclose, where);
  const Hid ftype = checked(H5Aget_type(a.get()), H5Tclose, where);
  const Hid space = checked(H5Aget_space(a.get()), H5Sclose, where);
  if (H5Tget_class(ftype.get()) != H5T_FLOAT || H5Sget_simple_extent_ndims(space.get()) != 1)
    throw Error(where + " is not a list of numbers");
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0) throw Error(where + ": " + last_error());
  std::vector<double> v(static_cast<std::size_t>(n));
  if (n > 0) check(H5Aread(a.get(), H5T_NATIVE_DOUBLE, v.data()), where);
  return v;
}

}  // namespace phiq::detail::h5
