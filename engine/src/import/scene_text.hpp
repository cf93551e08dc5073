// What the importers (asmt_scene.cpp, mechanism_scene.cpp) share to write a phiq scene's text: numbers, vectors and
// quoted strings as the scene reads them back, and names made from the file's that the scene accepts.
#pragma once

#include <Eigen/Dense>
#include <cctype>
#include <set>
#include <string>

#include "phiq/scene.hpp"
#include "phiq/text.hpp"

namespace phiq::detail {

// The shortest text that reads back as v (−0 as 0).
inline std::string scene_number(double v) { return shortest_unsigned_zero(v); }
inline std::string scene_vector(const Eigen::Vector3d& v) {
  return "[" + scene_number(v.x()) + ", " + scene_number(v.y()) + ", " + scene_number(v.z()) + "]";
}
// A one-line YAML string in double quotes.
inline std::string yaml_quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : single_line(s)) out += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}

// The `output` section an import writes when asked (ImportOptions::rates, ::forces; "" when neither is): rates are
// velocities and accelerations; forces the efforts of every driver when the scene has drivers, and the reactions of
// every joint that has one when it has such `joints`. Throws SceneError "PATH: --forces: ..." when forces are asked
// of a model without `mass` (every force would be zero) or with neither drivers nor joints.
inline std::string import_output_section(const std::string& path, bool rates, bool forces, bool drivers, bool joints,
                                         bool mass) {
  if (forces && !mass) throw SceneError(path + ": --forces: no part has mass: every force would be zero");
  if (forces && !drivers && !joints)
    throw SceneError(path + ": --forces: the model has no driver and no joint with a reaction");
  std::string fields;
  if (rates) fields += "velocities: true, accelerations: true";
  if (forces && drivers) fields += std::string(fields.empty() ? "" : ", ") + "efforts: all";
  if (forces && joints) fields += std::string(fields.empty() ? "" : ", ") + "reactions: all";
  return fields.empty() ? "" : "output: {" + fields + "}\n";
}

// phiq names (letters, digits, `_`) made from the file's, unique across the scene: what a name cannot hold becomes
// `_`, a name taken gets `_2`, `_3`, ...; a body's name reserves its coordinates' names (NAME_x, ..., NAME_e3).
class SceneNames {
 public:
  std::string make(const std::string& raw, bool body = false) {
    std::string base;
    for (char c : raw) base += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    if (base.empty() || std::isdigit(static_cast<unsigned char>(base[0]))) base = "n_" + base;
    std::string lower;
    for (char c : base) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    static const std::set<std::string> reserved = {"t",   "pi", "ground", "null", "true", "false",
                                                   "yes", "no", "on",     "off",  "y",    "n"};
    if (reserved.count(lower)) base += "_";  // phiq's names, and YAML's words for null and booleans
    std::string name = base;
    for (int k = 2; taken(name, body); ++k) name = base + "_" + std::to_string(k);
    used_.insert(name);
    if (body)
      for (const char* s : kCoordinates) used_.insert(name + s);
    return name;
  }

 private:
  static constexpr const char* kCoordinates[] = {"_x", "_y", "_z", "_e0", "_e1", "_e2", "_e3"};
  bool taken(const std::string& n, bool body) const {
    if (used_.count(n)) return true;
    if (body)
      for (const char* s : kCoordinates)
        if (used_.count(n + s)) return true;
    return false;
  }
  std::set<std::string> used_;
};

}  // namespace phiq::detail
