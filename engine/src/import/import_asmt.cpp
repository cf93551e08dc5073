// The public entry points of the `.asmt` import (phiq/import_asmt.hpp): the conversion to a phiq scene's text, and
// the TimeSeries of stored results that a comparison reads.
#include "phiq/import_asmt.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>

#include "import/asmt_model.hpp"
#include "phiq/scene.hpp"
#include "scene/read_scene_file.hpp"

namespace phiq {

AsmtImport import_asmt(const std::string& text, const std::string& path) {
  detail::asmt::Assembly a = detail::asmt::read_assembly(text, path);
  AsmtImport out;
  out.parts = static_cast<int>(a.parts.size());
  out.joints = static_cast<int>(a.joints.size());
  out.motions = static_cast<int>(a.motions.size());
  out.yaml = detail::asmt::write_scene(a);
  out.skipped = std::move(a.skipped);
  out.bodies = std::move(a.bodies);
  return out;
}

AsmtImport import_asmt_file(const std::string& path) {
  return import_asmt(detail::scene::read_scene_file(path, SceneLimits{}), path);
}

bool is_asmt_path(const std::string& path) {
  if (path.size() < 5) return false;
  std::string ext = path.substr(path.size() - 5);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".asmt";
}

namespace detail::asmt {
namespace {  // (in detail::asmt: a unity build may join this file with others' anonymous helpers)

// The tab-separated fields of one line, trailing blanks dropped.
std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::size_t at = 0;
  while (at <= line.size()) {
    std::size_t end = line.find('\t', at);
    if (end == std::string::npos) end = line.size();
    std::string f = line.substr(at, end - at);
    while (!f.empty() && (f.back() == ' ' || f.back() == '\r')) f.pop_back();
    out.push_back(f);
    at = end + 1;
  }
  while (!out.empty() && out.back().empty()) out.pop_back();
  return out;
}

// The numbers of a row after its label and the `Input` column.
std::vector<double> row_values(const std::vector<std::string>& f, std::size_t count, const std::string& path,
                               int line) {
  if (f.size() != count + 2)
    refuse(path, line,
           "TimeSeries row '" + f[0] + "' has " + std::to_string(f.size() - 1) + " values; the Time row has " +
               std::to_string(count + 1));
  std::vector<double> v;
  for (std::size_t k = 2; k < f.size(); ++k) {
    char* end = nullptr;
    v.push_back(std::strtod(f[k].c_str(), &end));
    if (end == f[k].c_str() || *end) refuse(path, line, "'" + f[k] + "' is not a number");
  }
  return v;
}

}  // namespace
}  // namespace detail::asmt

AsmtTimeSeries read_asmt_time_series(const std::string& text, const std::string& path) {
  using detail::asmt::fields, detail::asmt::row_values;
  AsmtTimeSeries out;
  std::size_t at = 0;
  bool inside = false;
  AsmtPartSeries* part = nullptr;
  for (int line = 1; at < text.size(); ++line) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    const std::string s = text.substr(at, end - at);
    at = end + 1;
    if (!inside) {
      inside = s.rfind("TimeSeries", 0) == 0;
      continue;
    }
    const std::vector<std::string> f = fields(s);
    if (f.empty()) continue;
    if (f[0] == "Time") {
      if (f.size() < 2) detail::asmt::refuse(path, line, "the TimeSeries Time row has no values");
      out.time = row_values(f, f.size() - 2, path, line);  // (its `Input` stands where rows hold the input's value)
    } else if (f[0].rfind("PartSeries ", 0) == 0) {
      const std::string p = f[0].substr(f[0].find_last_of('/') + 1);
      out.parts.push_back(AsmtPartSeries{p, {}, {}});
      part = &out.parts.back();
    } else if (f[0].find("Series ") != std::string::npos) {
      part = nullptr;  // the assembly's, joints' and motions' rows are not read
    } else if (part && f[0] != "Number") {
      part->labels.push_back(f[0]);
      part->columns.push_back(row_values(f, out.time.size(), path, line));
    }
  }
  return out;
}

}  // namespace phiq
