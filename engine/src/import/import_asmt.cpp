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

AsmtImport import_asmt(const std::string& text, const std::string& path, const ImportOptions& options) {
  detail::asmt::Assembly a = detail::asmt::read_assembly(text, path);
  AsmtImport out;
  out.parts = static_cast<int>(a.parts.size());
  out.joints = static_cast<int>(a.joints.size());
  out.motions = static_cast<int>(a.motions.size());
  out.yaml = detail::asmt::write_scene(a, options);
  out.skipped = std::move(a.skipped);
  out.bodies = std::move(a.bodies);
  return out;
}

AsmtImport import_asmt_file(const std::string& path, const ImportOptions& options) {
  return import_asmt(detail::scene::read_scene_file(path, SceneLimits{}), path, options);
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

// Where `Series` ends the first word of a series' heading ("PartSeries /Asm/NAME"; OndselSolver's joints write a tab
// before the path: "RevoluteJointSeries\t/Asm/NAME"), npos on another line.
std::size_t series_word(const std::vector<std::string>& f) {
  const std::size_t word = f[0].find("Series ");
  if (word != std::string::npos) return word;
  const bool tabbed = f.size() > 1 && f[0].size() > 6 && f[0].compare(f[0].size() - 6, 6, "Series") == 0;
  return tabbed && f[1].rfind('/', 0) == 0 ? f[0].size() - 6 : std::string::npos;
}

}  // namespace
}  // namespace detail::asmt

AsmtTimeSeries read_asmt_time_series(const std::string& text, const std::string& path) {
  using detail::asmt::fields, detail::asmt::row_values, detail::asmt::series_word;
  AsmtTimeSeries out;
  std::size_t at = 0;
  bool inside = false;
  std::vector<std::string>* labels = nullptr;  // of the part, joint or motion whose rows follow
  std::vector<std::vector<double>>* columns = nullptr;
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
    } else if (const std::size_t word = series_word(f); word != std::string::npos) {
      const std::string type = f[0].substr(0, word);
      const std::string& whole = f[0].size() > word + 6 ? f[0] : f[1];
      const std::string name = whole.substr(whole.find_last_of('/') + 1);
      labels = nullptr, columns = nullptr;  // the assembly's rows are not read
      if (type == "Part") {
        out.parts.push_back(AsmtPartSeries{name, {}, {}});
        labels = &out.parts.back().labels, columns = &out.parts.back().columns;
      } else if (type != "Assembly") {
        out.items.push_back(AsmtItemSeries{type, name, {}, {}});
        labels = &out.items.back().labels, columns = &out.items.back().columns;
      }
    } else if (labels && f[0] != "Number") {
      labels->push_back(f[0]);
      columns->push_back(row_values(f, out.time.size(), path, line));
    }
  }
  return out;
}

}  // namespace phiq
