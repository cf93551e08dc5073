// The report of `phiq sweep-accuracy` written out: one CSV row per setting, or the JSON document (format 2) with
// the scene, the reference and the notes (sweep_accuracy.hpp).
#include <nlohmann/json.hpp>

#include <cmath>

#include "accuracy_text.hpp"
#include "sweep_accuracy.hpp"

namespace phiq::tools {

namespace {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

using detail::newton_name;
using detail::significant_or_empty;

std::string accuracy_csv(const AccuracyReport& r) {
  std::string s =
      "scene,reference,tolerance,steps,predictor,newton,linear_solver,err_q,err_v,err_a,iterations_per_step,"
      "factorizations_per_step,us_per_step,status,default\n";
  const std::string scene = csv_field(r.scene_name.empty() ? r.scene_path : r.scene_name);
  for (const AccuracyRow& row : r.rows) {
    const AccuracySetting& st = row.setting;
    s += scene + "," + csv_field(r.reference_kind) + "," + shortest(st.tolerance) + "," + std::to_string(st.steps) +
         "," + to_string(st.predictor) + "," + newton_name(st.newton) + "," + to_string(st.linear_solver) + "," +
         significant_or_empty(row.err_q, 6) + "," + significant_or_empty(row.err_v, 6) + "," +
         significant_or_empty(row.err_a, 6) + "," + significant_or_empty(row.iterations_per_step, 6) + "," +
         significant_or_empty(row.factorizations_per_step, 6) + "," + significant_or_empty(row.us_per_step, 4) + "," +
         csv_field(row.status) + "," + (row.is_default ? "1" : "0") + "\n";
  }
  return s;
}

std::string accuracy_json(const AccuracyReport& r) {
  auto number = [](double v) { return std::isnan(v) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(v); };
  auto setting = [](const AccuracySetting& s) {
    return nlohmann::ordered_json{{"tolerance", s.tolerance},
                                  {"steps", s.steps},
                                  {"predictor", to_string(s.predictor)},
                                  {"newton", newton_name(s.newton)},
                                  {"linear_solver", to_string(s.linear_solver)}};
  };
  nlohmann::ordered_json j;
  j["format"] = kSweepAccuracyJsonFormat;
  j["phiq"] = version();
  j["host"] = {{"name", r.host}, {"cpu", r.cpu}};
  j["scene"] = r.scene_path;
  j["name"] = r.scene_name;
  j["status"] = r.status;
  j["message"] = r.message;
  if (r.status != "success") {  // nothing was measured: no reference, no settings to report
    j["notes"] = r.notes;
    j["rows"] = nlohmann::ordered_json::array();
    return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
  }
  j["reference"] = r.reference;
  j["coordinates"] = r.coordinates;
  j["length_scale"] = r.length_scale;
  j["scene_default"] = setting(r.scene_default);
  j["notes"] = r.notes;
  j["rows"] = nlohmann::ordered_json::array();
  for (const AccuracyRow& row : r.rows) {
    nlohmann::ordered_json o = setting(row.setting);
    o["err_q"] = number(row.err_q);
    o["err_v"] = number(row.err_v);
    o["err_a"] = number(row.err_a);
    o["iterations_per_step"] = number(row.iterations_per_step);
    o["factorizations_per_step"] = number(row.factorizations_per_step);
    o["us_per_step"] = number(row.us_per_step);
    o["status"] = row.status;
    o["default"] = row.is_default;
    j["rows"].push_back(o);
  }
  // a scene path or name that is not UTF-8 gets U+FFFD for its invalid bytes: the measurements are never lost to it
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

}  // namespace phiq::tools
