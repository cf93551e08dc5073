// Reading an earlier batch output for `phiq batch --resume` (batch_resume.hpp).
#include "batch_resume.hpp"

#include <cerrno>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "phiq/hdf5_reader.hpp"

namespace phiq::tools {

ResumePoint read_resume_point(const std::string& out, const std::string& header, std::size_t cases) {
  ResumePoint p;
  std::ifstream in(out, std::ios::binary);
  if (!in) {
    if (errno == ENOENT) return p;  // nothing earlier: the whole batch
    throw ResumeError(out + ": --resume: cannot read: " + std::strerror(errno));
  }
  const std::string bad = out + ": --resume: not an output of this batch: ";
  std::string line;
  if (!std::getline(in, line) || line + "\n" != header)
    throw ResumeError(bad + "its header is not the scene's columns with the case first");
  p.bytes = line.size() + 1;
  std::size_t row = 1;
  long long last = -1;
  while (std::getline(in, line)) {
    ++row;
    if (in.eof()) throw ResumeError(bad + "line " + std::to_string(row) + " ends without its newline");
    p.bytes += line.size() + 1;
    std::size_t digits = 0;
    long long k = 0;
    while (digits < line.size() && line[digits] >= '0' && line[digits] <= '9' && digits < 12)
      k = 10 * k + (line[digits++] - '0');
    if (digits == 0 || digits == line.size() || line[digits] != ',' || k >= static_cast<long long>(cases))
      throw ResumeError(bad + "line " + std::to_string(row) + " does not begin with one of its " +
                        std::to_string(cases) + " cases");
    if (k < last)
      throw ResumeError(bad + "line " + std::to_string(row) + ": case " + std::to_string(k) + " after case " +
                        std::to_string(last));
    if (k != last) {
      p.in_file.resize(static_cast<std::size_t>(k) + 1, 0);
      p.in_file[static_cast<std::size_t>(k)] = 1;
      ++p.cases_in_file;
      last = k;
      p.last_case_bytes = p.bytes - line.size() - 1, p.last_case_row = p.rows, p.last_case_rows = 0;
    }
    ++p.rows, ++p.last_case_rows;
  }
  if (in.bad()) throw ResumeError(out + ": --resume: cannot read: " + std::strerror(errno));
  p.first = static_cast<std::size_t>(last + 1);
  return p;
}

ResumePoint read_resume_point_hdf5(const std::string& out, const std::vector<std::string>& columns, std::size_t cases) {
  ResumePoint p;
  std::error_code ec;
  if (!std::filesystem::exists(out, ec)) return p;  // nothing earlier: the whole batch
  CsvTable table;
  try {
    table = read_hdf5_table(out);
  } catch (const Error& e) {
    throw ResumeError(std::string(e.what()) + " (--resume)");
  }
  const std::string bad = out + ": --resume: not an output of this batch: ";
  if (table.columns != columns) throw ResumeError(bad + "its columns are not the scene's with the case first");
  double last = -1;
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const double k = table.rows[r][0];
    if (!(k >= 0) || k >= static_cast<double>(cases) || k != std::floor(k))
      throw ResumeError(bad + "row " + std::to_string(r) + " is not one of its " + std::to_string(cases) + " cases");
    if (k < last)
      throw ResumeError(bad + "row " + std::to_string(r) + ": case " + std::to_string(static_cast<long long>(k)) +
                        " after case " + std::to_string(static_cast<long long>(last)));
    if (k != last) {
      const auto c = static_cast<std::size_t>(k);
      p.in_file.resize(c + 1, 0);
      p.in_file[c] = 1;
      ++p.cases_in_file;
      last = k;
      p.last_case_row = r, p.last_case_rows = 0;
    }
    ++p.rows, ++p.last_case_rows;
  }
  p.first = static_cast<std::size_t>(last + 1);
  return p;
}

void drop_unfinished_case(ResumePoint& p, std::size_t case_rows, const std::string& out) {
  if (p.first == 0 || p.last_case_rows == case_rows) return;
  const std::size_t k = p.first - 1;
  if (p.last_case_rows > case_rows)
    throw ResumeError(out + ": --resume: not an output of this batch: case " + std::to_string(k) + " has " +
                      std::to_string(p.last_case_rows) + " rows, more than its " + std::to_string(case_rows));
  p.first = k, p.in_file.resize(k), --p.cases_in_file;
  p.bytes = p.last_case_bytes, p.rows = p.last_case_row, p.last_case_rows = 0;
}

std::uint64_t copy_resumed_cases(const std::string& out, const ResumePoint& p, AtomicOutputFile& file) {
  std::ifstream in(out, std::ios::binary);
  std::string chunk(std::size_t{1} << 20, '\0');
  std::uint64_t copied = 0;
  while (copied < p.bytes && in) {
    in.read(chunk.data(), static_cast<std::streamsize>(std::min<std::uint64_t>(chunk.size(), p.bytes - copied)));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (got == 0) break;
    file.write(chunk.substr(0, got));
    copied += got;
  }
  if (copied != p.bytes) throw Error(out + ": --resume: cannot read: the file changed while it was copied");
  return copied;
}

}  // namespace phiq::tools
