// A phiq result against an `.asmt` file's TimeSeries (phiq/import_asmt.hpp, asmt_comparison()): the result's
// bodies' coordinates turned into the quantities OndselSolver stores (reference point, Bryant angles, their rates in
// the world frame), so that compare_csv() compares them column by column with the file's own rows.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

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
  const AsmtImport model = import_asmt(text, asmt_path);
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
  return out;
}

}  // namespace phiq
