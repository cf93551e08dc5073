// `phiq animate --forces` (force_arrows.hpp): the efforts' and reactions' columns at the kept rows, each at
// its joint's point.
#include "force_arrows.hpp"

#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <string_view>

#include "phiq/natural_joints.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// A constraint's block and index in it.
struct Held {
  const ConstraintBlock* block = nullptr;
  std::size_t index = 0;
};

std::vector<Held> constraint_blocks(const Model& model) {
  std::vector<Held> out(model.constraints().size());
  for (const auto& b : model.blocks())
    for (std::size_t i = 0; i < b->size(); ++i)
      out[static_cast<std::size_t>(model.constraint_of_row(b->first_row(i)))] = {b.get(), i};
  return out;
}

// The coordinates each constraint reads, from Φq's pattern.
std::vector<std::vector<Index>> coordinates_read(const Model& model) {
  std::vector<std::vector<Index>> out(model.constraints().size());
  const CscPattern& p = model.jacobian_pattern();
  for (Index j = 0; j < p.cols; ++j)
    for (Index k = p.col_ptr[static_cast<std::size_t>(j)]; k < p.col_ptr[static_cast<std::size_t>(j) + 1]; ++k) {
      auto& c = out[static_cast<std::size_t>(model.constraint_of_row(p.row_idx[static_cast<std::size_t>(k)]))];
      if (c.empty() || c.back() != j) c.push_back(j);
    }
  return out;
}

// Where a driver's effort is drawn: the first joint with a point (model order) that shares a coordinate with it,
// else with a constraint that shares one with it; none: nullopt.
std::optional<Index> effort_anchor(const Model& model, Index driver, const std::vector<Held>& held,
                                   const std::vector<std::vector<Index>>& reads) {
  const std::size_t nc = model.constraints().size();
  std::vector<char> coordinate(static_cast<std::size_t>(model.num_coordinates()), 0);
  for (Index j : reads[static_cast<std::size_t>(driver)]) coordinate[static_cast<std::size_t>(j)] = 1;
  for (int hop = 0; hop < 2; ++hop) {
    std::vector<std::size_t> sharing;
    for (std::size_t c = 0; c < nc; ++c)
      for (Index j : reads[c])
        if (coordinate[static_cast<std::size_t>(j)]) {
          if (held[c].block && held[c].block->has_reaction_site()) return static_cast<Index>(c);
          sharing.push_back(c);
          break;
        }
    for (std::size_t c : sharing)
      for (Index j : reads[c]) coordinate[static_cast<std::size_t>(j)] = 1;
  }
  return std::nullopt;
}

// A value of the table as JSON: null where it is not a finite number (a singular row's NaN), drawn as nothing.
nlohmann::json value(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

}  // namespace

nlohmann::json force_arrows(const Scene& scene, const CsvTable& table, const std::vector<std::size_t>& rows,
                            const std::vector<Eigen::VectorXd>& q, const std::string& result, double scale) {
  const Model& model = *scene.model;
  const OutputEfforts& e = scene.sweep.efforts;
  if (!e.active())
    throw Error(scene.path +
                ": --forces draws the efforts and reactions the scene writes, and it writes none "
                "(output: {efforts: all} or {reactions: all})");
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
  auto column = [&](const std::string& name) {
    const auto it = col.find(name);
    if (it == col.end())
      throw Error(result + ": no column '" + name + "', which --forces draws (the scene's output.efforts and " +
                  "output.reactions): not a result of " + scene.path + " as it is");
    return it->second;
  };
  const std::vector<Held> held = constraint_blocks(model);
  const std::size_t time = column("t");
  const bool spatial = scene.dimension == 3;
  nlohmann::json arrows = nlohmann::json::array(), unplaced = nlohmann::json::array();
  // one arrow: its joint's point at every kept row, and force / moment columns (3 each; −1: a zero component)
  // site: a constraint's index, or −1 − j for natural joint j (its point)
  auto add = [&](const std::string& name, const char* kind, Index site, const std::array<long, 3>& force,
                 const std::array<long, 3>& moment) {
    nlohmann::json at = nlohmann::json::array(), f = nlohmann::json::array(), m = nlohmann::json::array();
    for (std::size_t k = 0; k < rows.size(); ++k) {
      ReactionSite rs;
      if (site < 0) {  // a natural joint: its point, and its body's axes (written along them in joint axes)
        rs = natural_reaction_site(*e.natural, static_cast<std::size_t>(-1 - site), q[k].data(),
                                   table.rows[rows[k]][time]);
        for (double x : {rs.point.x, rs.point.y, rs.point.z}) at.push_back(x);
      } else {
        const Held& h = held[static_cast<std::size_t>(site)];
        h.block->reaction_site(h.index, q[k].data(), rs);
        for (double x : {rs.point.x, rs.point.y, rs.point.z}) at.push_back(x);
      }
      // a reaction written along the joint's axes (output.reaction_axes: joint) is drawn in world axes
      const bool turn = std::string_view(kind) == "reaction" && e.reactions_in_joint_axes;
      for (const std::array<long, 3>* columns : {&force, &moment}) {
        kin3::V3 v;
        for (int i = 0; i < 3; ++i) {
          const long c = (*columns)[static_cast<std::size_t>(i)];
          (i == 0 ? v.x : i == 1 ? v.y : v.z) = c < 0 ? 0.0 : table.rows[rows[k]][static_cast<std::size_t>(c)];
        }
        if (turn) v = v.x * rs.axes[0] + v.y * rs.axes[1] + v.z * rs.axes[2];
        for (double x : {v.x, v.y, v.z}) (columns == &force ? f : m).push_back(value(x));
      }
    }
    arrows.push_back({{"name", name}, {"kind", kind}, {"at", at}, {"force", f}, {"moment", m}});
  };
  for (const OutputReaction& r : e.reactions) {
    const std::string name = e.reaction_name(model, r);
    auto c = [&](const char* s) { return static_cast<long>(column(name + s)); };
    const Index site = r.natural >= 0 ? -1 - r.natural : r.constraint;
    if (r.spatial)
      add(name, "reaction", site, {c(".Fx"), c(".Fy"), c(".Fz")}, {c(".Mx"), c(".My"), c(".Mz")});
    else
      add(name, "reaction", site, {c(".Fx"), c(".Fy"), -1}, {-1, -1, c(".Mz")});
  }
  const std::vector<std::vector<Index>> reads =
      e.constraints.empty() ? std::vector<std::vector<Index>>{} : coordinates_read(model);
  for (Index d : e.constraints) {
    const ConstraintInfo& info = model.constraints()[static_cast<std::size_t>(d)];
    const long c = static_cast<long>(column(info.name + ".effort"));
    const std::optional<Index> site =
        spatial || model.row_unit(info.first_row) != Unit::kAngle ? std::nullopt : effort_anchor(model, d, held, reads);
    if (!site) {
      unplaced.push_back(info.name);
      continue;
    }
    add(info.name, "effort", *site, {-1, -1, -1}, {-1, -1, c});
  }
  return {{"scale", scale}, {"arrows", arrows}, {"unplaced", unplaced}};
}

}  // namespace phiq::tools
