#include "phiq/csv_writer.hpp"

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>

namespace phiq {

CsvFormat::CsvFormat(const Model& model, std::vector<Index> columns, bool velocities, bool accelerations)
    : model_(model), columns_(std::move(columns)), velocities_(velocities), accelerations_(accelerations) {
  for (Index j : columns_)
    if (j < 0 || j >= model.num_coordinates()) throw Error("CsvFormat: column index out of range");
}

std::string CsvFormat::header() const {
  std::string h = "t";
  const auto& names = model_.coordinate_names();
  for (Index j : columns_) h += "," + names[j];
  if (velocities_)
    for (Index j : columns_) h += "," + names[j] + ".v";
  if (accelerations_)
    for (Index j : columns_) h += "," + names[j] + ".a";
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
