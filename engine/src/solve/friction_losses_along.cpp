// detail::FrictionLosses (solve/friction_losses.hpp) in the efforts' sensitivities: the adjoint of the losses'
// solve, and their forces' rate at fixed λ along the motion and along a design parameter, with the bearings' joints
// as the models along the parameter hold them.
#include <algorithm>
#include <cmath>
#include <string_view>

#include "phiq/constraint_block.hpp"
#include "phiq/kinds/spatial_gear.hpp"
#include "phiq/model.hpp"
#include "phiq/natural_joints.hpp"
#include "phiq/sensitivity.hpp"
#include "solve/friction_losses.hpp"
#include "solve/models_along.hpp"  // kShift
#include "solve/natural_frame_points.hpp"

namespace phiq::detail {

bool FrictionLosses::adjoint(SparseLuNumeric& lu, Eigen::VectorXd& w) {
  const std::size_t nb = set_->bearings.size();
  // the joints whose geometry is kept per unit multiplier: all the bearings', or the others than natural points'
  JointReactions* kept = natural_ ? (kept_reactions_ ? &*kept_reactions_ : nullptr)
                                  : (reactions_ ? &*reactions_ : nullptr);  // (none: gear losses alone)
  if (!adjoint_ready_) {  // ∂m_i/∂λ over each bearing's joint's rows: the row's, the same for every driver row
    load_rows_.assign(6 * nb, 0.0);
    natural_load_rows_.resize(nb);
    if (natural_ && kept) kept->keep_geometry(q_, t_);
    double d[6];
    for (std::size_t i = 0; i < nb; ++i) {
      const Bearing& b = set_->bearings[i];
      const double mu = b.spring->bearing->coefficient;
      bearing_load_gradient(*b.spring->bearing, values_.data() + b.at, b.spatial, d);
      natural_load_rows_[i].clear();
      if (b.constraint < 0) {  // its force's rows, world axes: f_k = a_k · F in its body's axes a_k
        const int j = set_->joints.reactions[i].natural;
        const ReactionSite rs = natural_reaction_site(*set_->joints.natural, static_cast<std::size_t>(j), q_, t_);
        const double gx = d[0] * rs.axes[0].x + d[1] * rs.axes[1].x, gy = d[0] * rs.axes[0].y + d[1] * rs.axes[1].y;
        reactions_->natural_force_rows(i, force_rows_, force_row_values_);
        for (std::size_t r = 0; r < force_rows_.size(); ++r)
          natural_load_rows_[i].emplace_back(force_rows_[r],
                                             mu * (gx * force_row_values_[2 * r] + gy * force_row_values_[2 * r + 1]));
        continue;
      }
      const auto& per_row = kept->kept_per_row(set_->bearings[i].kept);
      for (Index j = 0; j < per_row.cols(); ++j) {
        double g = 0.0;
        for (int v = 0; v < 6; ++v) g += d[v] * per_row(v, j);
        load_rows_[6 * i + static_cast<std::size_t>(j)] = mu * g;
      }
    }
    adjoint_ready_ = true;
  }
  w0_ = w;
  adjoint_rhs_.resize(w.size());
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    // (∂Q_f/∂λ)ᵀ w̃ = Σ_i ∂m_i/∂λ (u_iᵀ w̃), over the rows of each loss's joint or mesh
    adjoint_rhs_.setZero();
    for (std::size_t i = 0; i < nb; ++i) {
      const double dir = friction_direction(rates_[i]);
      const std::vector<Index>& c = torsional_coordinates(*set_->bearings[i].spring);
      double along = 0.0;  // u_iᵀ w̃, u_i = −dir ∇θ_i
      for (std::size_t k = 0; k < c.size(); ++k) along -= dir * gradients_[i][k] * w(c[k]);
      if (along == 0.0) continue;
      if (set_->bearings[i].constraint < 0) {
        for (const auto& [row, value] : natural_load_rows_[i]) adjoint_rhs_(row) += along * value;
        continue;
      }
      const std::size_t k = set_->bearings[i].kept;
      const Index first = kept->kept_first_row(k), rows = kept->kept_per_row(k).cols();
      for (Index j = 0; j < rows; ++j)
        adjoint_rhs_(first + j) += along * load_rows_[6 * i + static_cast<std::size_t>(j)];
    }
    for (std::size_t j = 0; j < set_->meshes.size(); ++j) {
      const Mesh& mesh = set_->meshes[j];
      const MeshState& state = mesh_states_[j];
      if (state.driven < 0) continue;
      const double dir = friction_direction(state.rate[state.driven]);
      double along = 0.0;
      if (mesh.member[state.driven].is_coordinate()) along -= dir * w(mesh.member[state.driven].coord());
      if (mesh.carrier.is_coordinate()) along += dir * w(mesh.carrier.coord());
      // m = (1 − η) |e|, e = −c λ_row (c: 1 for member 0, k for member 1)
      const double c = state.driven == 0 ? 1.0 : mesh.k;
      adjoint_rhs_(mesh.row) -= along * (1.0 - mesh.eta[state.driven]) * state.effort_sign * c;
    }
    if (adjoint_rhs_.isZero(0.0)) return w = w0_, true;  // (no loss turns: w̃ = w)
    adjoint_step_.resize(w.size());
    if (!lu.solve(adjoint_rhs_.data(), adjoint_step_.data())) return false;
    double change = 0.0, scale = 0.0;
    for (Index k = 0; k < w.size(); ++k) {
      const double next = w0_(k) + adjoint_step_(k);
      change = std::max(change, std::abs(next - w(k))), scale = std::max(scale, std::abs(next));
      w(k) = next;
    }
    if (change <= 1e-14 * scale) return true;
  }
  return false;
}

void FrictionLosses::frozen_forces(const double* q, const double* qd, const double* qdd, double t,
                                   const Eigen::VectorXd& lambda, const AppliedLoads* data, const JointsAlong* joints,
                                   std::size_t k, Eigen::VectorXd& out) {
  out.setZero(q_f_.size());
  const JointReactions::Along* along = joints ? &joints->along[k] : nullptr;
  if (natural_) {  // (a natural point's reaction reads its bodies' motion, as the models along p hold them)
    frozen_values_.resize(values_.size());
    JointReactions& r = joints && joints->natural[k] ? *joints->natural[k] : *reactions_;
    r.evaluate(q, qd, qdd, t, lambda, frozen_values_.data(), nullptr, true, along);
  } else if (reactions_) {
    frozen_values_.resize(values_.size());
    reactions_->evaluate(q, t, lambda, frozen_values_.data(), along);
  }
  std::size_t in_data = 0;  // the next torsional spring of `data` to look at
  for (std::size_t i = 0; i < set_->bearings.size(); ++i) {
    const Bearing& b = set_->bearings[i];
    const TorsionalSpring* s = b.spring;
    if (data) {  // the same bearing in the data along p: the i-th spring with one
      while (in_data < data->torsional_springs.size() && !data->torsional_springs[in_data].bearing) ++in_data;
      if (in_data == data->torsional_springs.size())
        throw Error("the loads along a parameter lost a bearing (phiq bug)");
      s = &data->torsional_springs[in_data++];
    }
    const double dir = friction_direction(rates_[i]);
    if (dir == 0.0) continue;
    const double m = s->bearing->coefficient * bearing_load(*s->bearing, frozen_values_.data() + b.at, b.spatial);
    angle_rate(*s, q, nullptr, t, frozen_gradient_);
    const std::vector<Index>& c = torsional_coordinates(*s);
    for (std::size_t k = 0; k < c.size(); ++k) out(c[k]) -= m * dir * frozen_gradient_[k];
  }
  for (std::size_t j = 0; j < set_->meshes.size(); ++j) {
    const Mesh& mesh = set_->meshes[j];
    const MeshState& state = mesh_states_[j];
    if (state.driven < 0) continue;
    double eta = mesh.eta[state.driven], ratio = mesh.k;
    const MeshAlong* along =
        joints && !joints->meshes[k].empty() && joints->meshes[k][j].moved ? &joints->meshes[k][j] : nullptr;
    if (data || along) {  // (a worm's efficiencies read its lead and pressure angles)
      const GearLoss& l = data ? data->gear_losses.at(j) : *mesh.loss;
      const double mu = l.friction, c = along ? along->cos_pressure : mesh.cos_pressure,
                   tl = along ? along->tan_lead : mesh.tan_lead;
      if (along) ratio = along->k;
      eta = l.friction > 0.0 ? (state.driven == 1 ? (c - mu * tl) / (c + mu / tl) : (c - mu / tl) / (c + mu * tl))
                             : (state.driven == 1 ? l.efficiency : l.reverse_efficiency);
    }
    const double effort = (state.driven == 0 ? 1.0 : ratio) * lambda(mesh.row);
    const double m = (1.0 - eta) * std::abs(effort) * friction_direction(state.rate[state.driven]);
    if (mesh.member[state.driven].is_coordinate()) out(mesh.member[state.driven].coord()) -= m;
    if (mesh.carrier.is_coordinate()) out(mesh.carrier.coord()) += m;
  }
}

void FrictionLosses::force_rate(const double* q, double t, const Eigen::VectorXd& lambda, const Eigen::VectorXd& v,
                                double e, const std::array<const AppliedLoads*, 4>& along, const JointsAlong* joints,
                                const std::array<Eigen::VectorXd, 4>* moved, double h, Eigen::VectorXd& out,
                                const double* sd, const double* sdd) {
  const Index n = q_f_.size();
  const Eigen::Map<const Eigen::VectorXd> qv(q, n);
  if (natural_ && (!sd || !sdd || !qd_ || !qdd_))
    throw Error("FrictionLosses::force_rate: a natural point's bearing reads q̇, q̈ and their rates (phiq bug)");
  for (std::size_t k = 0; k < 4; ++k) {
    qk_ = qv + (kShift[k] * e) * v;
    if (natural_) {
      qdk_ = Eigen::Map<const Eigen::VectorXd>(qd_, n) + (kShift[k] * e) * Eigen::Map<const Eigen::VectorXd>(sd, n);
      qddk_ = Eigen::Map<const Eigen::VectorXd>(qdd_, n) + (kShift[k] * e) * Eigen::Map<const Eigen::VectorXd>(sdd, n);
    }
    frozen_forces(qk_.data(), natural_ ? qdk_.data() : qd_, natural_ ? qddk_.data() : qdd_, t, lambda, nullptr, nullptr,
                  k, forces_[k]);
  }
  out = ((forces_[0] - forces_[3]) + 8.0 * (forces_[2] - forces_[1])) / (12.0 * e);
  if (std::none_of(along.begin(), along.end(), [](const AppliedLoads* a) { return a != nullptr; }) && !moved && !joints)
    return;
  for (std::size_t k = 0; k < 4; ++k)
    frozen_forces(moved ? (*moved)[k].data() : q, qd_, qdd_, t, lambda, along[k], joints, k, forces_[k]);
  out += ((forces_[0] - forces_[3]) + 8.0 * (forces_[2] - forces_[1])) / (12.0 * h);
}

std::string FrictionLosses::sensitivity_refusal(const Model& model, const OutputSensitivity& p) const {
  const std::string with = "the efforts' sensitivities to '" + p.name + "' with ";
  if (!p.reach) return {};
  JointsAlong joints;
  const std::string who = find_joints_along(model, p, joints, false);
  return who.empty() ? who
                     : with + who + ": '" + p.name +
                           "' moves a constraint whose data the losses' derivative cannot move along it (an "
                           "expression's, a law's or a curve's; ask them without it)";
}

const FrictionLosses::JointsAlong* FrictionLosses::joints_along(const Model& model, const OutputSensitivity& p) {
  auto found = [](const JointsAlong& j) {
    return j.at[0].empty() && j.meshes[0].empty() && !j.natural[0] ? nullptr : &j;
  };
  for (const JointsAlong& j : joints_along_)
    if (j.reach == p.reach.get()) return found(j);
  JointsAlong& j = joints_along_.emplace_back();
  j.reach = p.reach.get();
  if (const std::string who = find_joints_along(model, p, j); !who.empty())
    throw Error(sensitivity_refusal(model, p));  // (the sweep refused it at its start: not reached)
  return found(j);
}

bool FrictionLosses::constraint_along(const Model& model, const OutputSensitivity& p, Index c,
                                      std::array<JointReactions::BlockAt, 4>& at, JointsAlong& out) const {
  const ParameterReach& reach = *p.reach;
  const ReachedConstraints* kept = p.reached && p.reached->reach.get() == &reach ? p.reached.get() : nullptr;
  const auto& blocks = model.blocks();
  const auto [block, index] = model.constraint_block(c);
  std::size_t bi = 0;
  while (bi < blocks.size() && blocks[bi].get() != block) ++bi;
  std::size_t j = 0;  // its span
  while (j < reach.spans.size() &&
         !(reach.spans[j].block == bi && reach.spans[j].begin <= index && index < reach.spans[j].end))
    ++j;
  if (reach.everything || j == reach.spans.size()) return false;
  const std::size_t in_span = index - reach.spans[j].begin;
  for (std::size_t k = 0; k < 4; ++k) {
    if (kept && kept->rates[j]) {  // its copies' data's rates: the constraint moved along them
      out.owned.push_back(block->data_moved(index, *kept->rates[j], in_span, kShift[k] * p.step));
      if (!out.owned.back()) return false;
      at[k] = {out.owned.back().get(), 0};
    } else if (kept && kept->along[k][j] && in_span < kept->along[k][j]->size()) {  // its copies
      at[k] = {kept->along[k][j].get(), in_span};
    } else if (!kept && p.models[k]) {  // the models themselves
      at[k] = {p.models[k]->blocks()[bi].get(), index};
    } else {
      return false;
    }
  }
  return true;
}

std::string FrictionLosses::find_joints_along(const Model& model, const OutputSensitivity& p, JointsAlong& out,
                                              bool build) const {
  const std::vector<Index>& reached = p.reach->rows;
  auto touched = [&](Index first, Index rows) {
    const auto it = std::lower_bound(reached.begin(), reached.end(), first);
    return it != reached.end() && *it < first + rows;
  };
  std::array<JointReactions::BlockAt, 4> at;
  const std::size_t nb = set_->bearings.size(), nm = set_->meshes.size();
  for (std::size_t i = 0; i < nb; ++i) {
    const Bearing& b = set_->bearings[i];
    if (b.constraint < 0) continue;  // (a natural point's: natural_along())
    const ConstraintInfo& c = model.constraints()[static_cast<std::size_t>(b.constraint)];
    // a planar journal's load is its force's size, which its multipliers alone give: no geometry read along p
    const std::string_view kind = c.kind;
    const bool planar_journal = !b.spatial && !b.spring->bearing->slide && (kind == "pin" || kind == "revolute");
    if (planar_journal || !touched(c.first_row, c.rows)) continue;
    if (!constraint_along(model, p, b.constraint, at, out)) return "the bearing of '" + c.name + "'";
    if (out.at[0].empty())
      for (auto& a : out.at) a.assign(nb, {});
    for (std::size_t k = 0; k < 4; ++k) out.at[k][i] = at[k];
  }
  for (std::size_t j = 0; j < nm; ++j) {
    const Mesh& m = set_->meshes[j];
    if (!touched(m.row, 1)) continue;
    const std::string who = "the gear losses of '" + m.loss->gear + "'";
    if (!constraint_along(model, p, model.find_constraint(m.loss->gear), at, out)) return who;
    if (out.meshes[0].empty())
      for (auto& a : out.meshes) a.assign(nm, {});
    for (std::size_t k = 0; k < 4; ++k) {
      MeshAlong& to = out.meshes[k][j];
      to.moved = true;
      if (GearMesh g; at[k].block->gear_mesh(at[k].index, g)) {
        to.k = g.k, to.tan_lead = m.tan_lead, to.cos_pressure = m.cos_pressure;
      } else if (SpatialMesh sm; at[k].block->spatial_mesh(at[k].index, sm)) {
        to.k = sm.k, to.cos_pressure = m.cos_pressure, to.tan_lead = m.tan_lead;
        if (m.loss->friction > 0.0)  // a worm's (FrictionLosses' constructor)
          to.tan_lead = sm.r2 / (std::abs(sm.k) * sm.r1), to.cos_pressure = std::cos(sm.pressure_angle);
      } else {
        return who;
      }
    }
  }
  if (natural_) return natural_along(model, p, out, build);
  if (!out.at[0].empty())
    for (std::size_t k = 0; k < 4; ++k) out.along[k] = reactions_->along(out.at[k], {}, model);
  return {};
}

std::string FrictionLosses::natural_along(const Model& model, const OutputSensitivity& p, JointsAlong& out,
                                          bool build) const {
  const OutputEfforts& joints = set_->joints;
  const NaturalJoints& natural = *joints.natural;
  const std::vector<Part>& parts = *joints.parts;  // (with mass only)
  // the bodies' own constraints in the four models, where p reaches them
  std::array<std::vector<std::pair<Index, JointReactions::BlockAt>>, 4> own;
  std::array<JointReactions::BlockAt, 4> at;
  const std::vector<Index>& reached = p.reach->rows;
  for (const Index c : reactions_->own_constraints(model)) {
    const ConstraintInfo& info = model.constraints()[static_cast<std::size_t>(c)];
    const auto it = std::lower_bound(reached.begin(), reached.end(), info.first_row);
    if (it == reached.end() || *it >= info.first_row + info.rows) continue;
    if (!constraint_along(model, p, c, at, out))
      return "the bearings at natural points (their bodies' '" + info.name + "')";
    for (std::size_t k = 0; k < 4; ++k) own[k].emplace_back(c, at[k]);
  }
  for (std::size_t k = 0; k < 4; ++k) {
    // the bodies in their order, each with its part as the scene along p holds it (the efforts' parts have mass: a
    // massless body keeps its frame), their loads there, and their joints at the same places of their frames (a
    // fixed pivot's constant moved with p)
    const std::vector<Part>& along = p.parts_along[k] ? *p.parts_along[k] : parts;
    auto bodies = std::make_shared<std::vector<Part>>();
    bodies->reserve(natural.bodies.size());
    for (const NaturalBody& b : natural.bodies) {
      const auto it = std::find_if(along.begin(), along.end(), [&](const Part& x) { return x.name == b.name; });
      if (it != along.end()) {
        bodies->push_back(*it);
      } else {
        bodies->emplace_back().name = b.name;
        bodies->back().frame = b.frame;
      }
    }
    const std::shared_ptr<const Loads> loads = p.loads_along[k] ? p.loads_along[k] : joints.loads;
    std::vector<std::pair<std::string, Attachment3>> points;
    for (const NaturalJoint& j : natural.joints) {
      const std::size_t b = j.bodies.front();
      const auto here = frame_points(natural.bodies[b].frame), there = frame_points(std::as_const((*bodies)[b].frame));
      std::size_t m = 0;
      while (m < here.size() && !(here[m]->r[0] == j.point.r[0] && here[m]->r[1] == j.point.r[1])) ++m;
      if (m == here.size() || there.size() != here.size()) return "the bearing at natural point '" + j.name + "'";
      points.emplace_back(j.name, *there[m]);
    }
    auto found = std::make_shared<const NaturalJoints>(
        find_natural_joints(*bodies, *loads, points, model.num_coordinates(), natural.spatial));
    bool same = found->joints.size() == natural.joints.size() && found->bodies.size() == natural.bodies.size();
    for (std::size_t j = 0; same && j < natural.joints.size(); ++j)
      same = found->joints[j].bodies == natural.joints[j].bodies;
    if (!same) return "the bearings at natural points (their bodies change with it)";
    if (!build) continue;  // (a check: the balances are built where they are read)
    OutputEfforts e = joints;
    e.parts = bodies, e.loads = loads, e.natural = found;
    out.natural[k] = std::make_shared<JointReactions>(model, e);
    out.along[k] = out.natural[k]->along(out.at[k], own[k], model);
  }
  return {};
}

}  // namespace phiq::detail
