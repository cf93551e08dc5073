// A phiq result against an `.asmt` file's TimeSeries (phiq/import_asmt.hpp, asmt_comparison()): the result's
// bodies' coordinates turned into the quantities OndselSolver stores (reference point, Bryant angles, their rates in
// the world frame), and its reactions and efforts into the forces it stores (on marker I's part, about marker I's
// origin, world axes), so that compare_csv() compares them column by column with the file's own rows.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include "import/asmt_model.hpp"
#include "phiq/import_asmt.hpp"
#include "phiq/scene.hpp"
#include "phiq/types.hpp"
#include "scene/read_scene_file.hpp"

namespace phiq {

namespace detail::asmt {
namespace {  // (in detail::asmt: a unity build may join this file with others' anonymous helpers)

constexpr const char* kPositionRows[] = {"X", "Y", "Z", "Bryantx", "Bryanty", "Bryantz"};
constexpr const char* kVelocityRows[] = {"VX", "VY", "VZ", "OmegaX", "OmegaY", "OmegaZ"};
constexpr const char* kAccelerationRows[] = {"AX", "AY", "AZ", "AlphaX", "AlphaY", "AlphaZ"};
constexpr const char* kBodyCoordinates[] = {"_x", "_y", "_z", "_e0", "_e1", "_e2", "_e3"};

// The column of a coordinate's value (suffix ""), rate (".v") or second rate (".a") in the result, under either
// naming `phiq run --names` writes; nullopt when the result has none.
std::optional<std::size_t> result_column(const std::map<std::string, std::size_t>& index, const std::string& coordinate,
                                         const std::string& rate) {
  for (const std::string& name : {coordinate + rate, rate.empty() ? coordinate : coordinate + "__" + rate.substr(1)})
    if (auto it = index.find(name); it != index.end()) return it->second;
  return std::nullopt;
}

// The world-frame map of Euler parameters' rates to angular velocity: ω = 2 E(e) ė, and α = 2 E(e) ë (Ė ė = 0).
Eigen::Matrix<double, 3, 4> world_rate_map(const Eigen::Vector4d& e) {
  Eigen::Matrix<double, 3, 4> E;
  E << -e(1), e(0), -e(3), e(2), -e(2), e(3), e(0), -e(1), -e(3), -e(2), e(1), e(0);
  return 2.0 * E;
}

// The Bryant angles (R = Rx(a) Ry(b) Rz(c)) of the rotation of Euler parameters e.
Eigen::Vector3d bryant_angles(const Eigen::Vector4d& e) {
  const Eigen::Matrix3d R = Eigen::Quaterniond(e(0), e(1), e(2), e(3)).normalized().toRotationMatrix();
  return {std::atan2(-R(1, 2), R(2, 2)), std::asin(std::clamp(R(0, 2), -1.0, 1.0)), std::atan2(-R(0, 1), R(0, 0))};
}

// `angle` moved by whole turns to lie nearest `stored` (a turn is no difference between two placements).
double nearest_turn(double angle, double stored) {
  if (!std::isfinite(angle) || !std::isfinite(stored)) return angle;
  const double turn = 2.0 * std::numbers::pi;
  return angle + turn * std::round((stored - angle) / turn);
}

constexpr const char* kForceRows[] = {"FXonI", "FYonI", "FZonI", "TXonI", "TYonI", "TZonI"};
constexpr const char* kReactionColumns[] = {".Fx", ".Fy", ".Fz", ".Mx", ".My", ".Mz"};

// A joint's or motion's forces: the stored rows, and where the result holds what they are computed from.
struct ForceColumns {
  const ForceSite* site = nullptr;
  std::vector<const std::vector<double>*> stored;  // FXonI ... TZonI
  std::vector<std::size_t> values;                 // the reaction's six columns, or the effort's one
  std::optional<std::size_t> e[4];                 // marker I's body's Euler parameters (none on the ground)
};

// The stored forces the result can be compared with, as ForceColumns; what it cannot, with why, to `left_out`.
std::vector<ForceColumns> force_columns(const Assembly& a, const AsmtTimeSeries& series,
                                        const std::map<std::string, std::size_t>& index, const std::string& result,
                                        std::vector<std::string>& left_out) {
  std::vector<ForceColumns> out;
  std::vector<std::string> missing;
  const bool mass = std::any_of(a.parts.begin(), a.parts.end(), [](const Part& p) { return p.mass > 0.0; });
  if (!series.items.empty() && !mass)
    left_out.push_back("forces (FXonI ... TZonI): no part of " + a.path + " has mass: phiq computes no force for it");
  for (const AsmtItemSeries& item : series.items) {
    if (!mass) break;
    const auto site = std::find_if(a.force_sites.begin(), a.force_sites.end(),
                                   [&](const ForceSite& f) { return f.item == item.name && f.type == item.type; });
    if (site == a.force_sites.end())
      throw SceneError(a.path + ": the TimeSeries names " + item.type + " '" + item.name +
                       "', which the assembly has not");
    if (!site->why_not.empty()) {
      left_out.push_back("forces of " + item.type + " '" + item.name + "' (FXonI ... TZonI): " + site->why_not);
      continue;
    }
    ForceColumns fc;
    fc.site = &*site;
    for (const char* label : kForceRows) {
      const auto at = std::find(item.labels.begin(), item.labels.end(), label);
      if (at == item.labels.end())
        throw SceneError(a.path + ": the TimeSeries of " + item.type + " '" + item.name + "' has no row " + label);
      fc.stored.push_back(&item.columns[static_cast<std::size_t>(at - item.labels.begin())]);
    }
    const bool joint = item.type.find("Motion") == std::string::npos;
    for (const char* c : kReactionColumns) {
      const auto v = result_column(index, site->name, joint ? c : ".effort");
      if (v) fc.values.push_back(*v);
      if (!joint) break;
    }
    if (fc.values.size() != (joint ? 6u : 1u)) {
      missing.push_back(site->name + (joint ? ".Fx" : ".effort"));
      continue;
    }
    for (int i = 0; i < 4 && site->body != "ground"; ++i) {
      fc.e[i] = result_column(index, site->body + kBodyCoordinates[3 + i], "");
      if (!fc.e[i])
        throw Error(result + ": no column '" + site->body + kBodyCoordinates[3 + i] + "' for marker I of '" +
                    item.name + "' of " + a.path + " (compare a result of `phiq run` of that file)");
    }
    out.push_back(std::move(fc));
  }
  if (!missing.empty()) {
    std::string names;
    for (std::size_t k = 0; k < missing.size() && k < 3; ++k) names += (k ? ", " : "") + missing[k];
    left_out.push_back("forces (FXonI ... TZonI) of " + std::to_string(missing.size()) +
                       " joints and motions: " + result + " has no " + names + (missing.size() > 3 ? ", ..." : "") +
                       " (`phiq run --forces`, or a scene whose output has `efforts: all, reactions: all`)");
  }
  return out;
}

// The force on marker I's part and the moment about marker I's origin (world axes) of one row of the result.
void append_forces(const ForceColumns& fc, const std::vector<double>& r, std::vector<double>& row) {
  const ForceSite& site = *fc.site;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (site.body != "ground")
    R = Eigen::Quaterniond(r[*fc.e[0]], r[*fc.e[1]], r[*fc.e[2]], r[*fc.e[3]]).normalized().toRotationMatrix();
  const Eigen::Vector3d z = R * site.marker.R.col(2);  // marker I's z in the world
  Eigen::Vector3d F = Eigen::Vector3d::Zero(), M = Eigen::Vector3d::Zero();
  if (site.type == "RotationalMotion") {  // τ turns J about z_I: −τ z_I on I
    M = -r[fc.values[0]] * z;
  } else if (site.type == "TranslationalMotion") {  // τ pushes J along z_I; J's origin is on I's z axis
    F = -r[fc.values[0]] * z;
  } else {  // on side 1 about its point, marker I's origin + offset z_I; on side 2 when I is on the ground
    const double sign = site.body == "ground" ? -1.0 : 1.0;
    for (int i = 0; i < 3; ++i) F(i) = sign * r[fc.values[static_cast<std::size_t>(i)]];
    for (int i = 0; i < 3; ++i) M(i) = sign * r[fc.values[static_cast<std::size_t>(3 + i)]];
    M += (site.offset * z).cross(F);
  }
  row.insert(row.end(), F.data(), F.data() + 3);
  row.insert(row.end(), M.data(), M.data() + 3);
}

// One part's seven coordinates in the result: their columns of values, rates and second rates.
struct PartColumns {
  std::size_t q[7];
  std::optional<std::size_t> v[7], a[7];
};

}  // namespace
}  // namespace detail::asmt

AsmtComparison asmt_comparison(const CsvTable& result, const std::string& asmt_path) {
  using namespace detail::asmt;
  const std::string text = detail::scene::read_scene_file(asmt_path, SceneLimits{});
  const AsmtTimeSeries series = read_asmt_time_series(text, asmt_path);
  if (series.time.empty() || series.parts.empty())
    throw SceneError(asmt_path + ": no TimeSeries of parts to compare with (OndselSolver stores one after a run)");
  Assembly model = read_assembly(text, asmt_path);
  (void)write_scene(model);  // names the bodies, constraints and drivers as the result's columns do
  std::map<std::string, std::string> body_of;
  for (const auto& [part, body] : model.bodies) body_of[part] = body;
  std::map<std::string, std::size_t> index;
  for (std::size_t c = 0; c < result.columns.size(); ++c) index[result.columns[c]] = c;

  // which parts, and which of their rates, the result holds: rates are compared only when every part has them
  std::vector<PartColumns> columns;
  bool velocities = true, accelerations = true;
  for (const AsmtPartSeries& part : series.parts) {
    const auto body = body_of.find(part.name);
    if (body == body_of.end())
      throw SceneError(asmt_path + ": the TimeSeries names part '" + part.name + "', which the assembly has not");
    PartColumns pc;
    for (int k = 0; k < 7; ++k) {
      const std::string coordinate = body->second + kBodyCoordinates[k];
      const auto q = result_column(index, coordinate, "");
      if (!q)
        throw Error(result.path + ": no column '" + coordinate + "' for part '" + part.name + "' of " + asmt_path +
                    " (compare a result of `phiq run` of that file)");
      pc.q[k] = *q, pc.v[k] = result_column(index, coordinate, ".v");
      pc.a[k] = result_column(index, coordinate, ".a");
      velocities = velocities && pc.v[k], accelerations = accelerations && pc.a[k];
    }
    columns.push_back(pc);
  }
  std::vector<const char*> rows(std::begin(kPositionRows), std::end(kPositionRows));
  AsmtComparison out;
  if (velocities)
    rows.insert(rows.end(), std::begin(kVelocityRows), std::end(kVelocityRows));
  else
    out.left_out.push_back("velocities (VX ... OmegaZ): " + result.path +
                           " has none (a scene whose output has `velocities: true`)");
  if (accelerations)
    rows.insert(rows.end(), std::begin(kAccelerationRows), std::end(kAccelerationRows));
  else
    out.left_out.push_back("accelerations (AX ... AlphaZ): " + result.path +
                           " has none (a scene whose output has `accelerations: true`)");

  // the stored rows, by label; the columns of both tables alike
  std::vector<std::vector<const std::vector<double>*>> stored(series.parts.size());
  out.series.path = asmt_path, out.result.path = result.path;
  out.series.columns = out.result.columns = {"t"};
  for (std::size_t p = 0; p < series.parts.size(); ++p) {
    const AsmtPartSeries& part = series.parts[p];
    for (const char* label : rows) {
      std::size_t at = 0;
      while (at < part.labels.size() && part.labels[at] != label) ++at;
      if (at == part.labels.size())
        throw SceneError(asmt_path + ": the TimeSeries of part '" + part.name + "' has no row " + label);
      stored[p].push_back(&part.columns[at]);
      out.series.columns.push_back(part.name + "." + label);
    }
  }
  out.result.columns = out.series.columns;
  for (std::size_t k = 0; k < series.time.size(); ++k) {
    std::vector<double> row = {series.time[k]};
    for (const auto& part : stored)
      for (const std::vector<double>* values : part) row.push_back((*values)[k]);
    out.series.rows.push_back(std::move(row));
  }

  const auto it_t = index.find("t");
  for (std::size_t k = 0; k < result.rows.size(); ++k) {
    const std::vector<double>& r = result.rows[k];
    std::vector<double> row = {it_t == index.end() ? std::nan("") : r[it_t->second]};
    for (std::size_t p = 0; p < columns.size(); ++p) {
      const PartColumns& pc = columns[p];
      auto vec4 = [&](const std::optional<std::size_t>* c, int from) {
        Eigen::Vector4d e;
        for (int i = 0; i < 4; ++i) e(i) = r[*c[from + i]];
        return e;
      };
      Eigen::Vector4d e;
      for (int i = 0; i < 4; ++i) e(i) = r[pc.q[3 + i]];
      const Eigen::Vector3d angles = bryant_angles(e);
      for (int i = 0; i < 3; ++i) row.push_back(r[pc.q[i]]);
      for (int i = 0; i < 3; ++i)
        row.push_back(k < series.time.size() ? nearest_turn(angles(i), (*stored[p][3 + i])[k]) : angles(i));
      const Eigen::Matrix<double, 3, 4> map = world_rate_map(e);
      if (velocities) {
        for (int i = 0; i < 3; ++i) row.push_back(r[*pc.v[i]]);
        const Eigen::Vector3d omega = map * vec4(pc.v, 3);
        row.insert(row.end(), omega.data(), omega.data() + 3);
      }
      if (accelerations) {
        for (int i = 0; i < 3; ++i) row.push_back(r[*pc.a[i]]);
        const Eigen::Vector3d alpha = map * vec4(pc.a, 3);
        row.insert(row.end(), alpha.data(), alpha.data() + 3);
      }
    }
    out.result.rows.push_back(std::move(row));
  }

  // the joints' and motions' forces, where the result has them
  for (const ForceColumns& fc : force_columns(model, series, index, result.path, out.left_out)) {
    for (const char* label : kForceRows) out.series.columns.push_back(fc.site->item + "." + label);
    for (std::size_t k = 0; k < out.series.rows.size(); ++k)
      for (const std::vector<double>* values : fc.stored) out.series.rows[k].push_back((*values)[k]);
    for (std::size_t k = 0; k < out.result.rows.size(); ++k) append_forces(fc, result.rows[k], out.result.rows[k]);
  }
  out.result.columns = out.series.columns;
  return out;
}

}  // namespace phiq
