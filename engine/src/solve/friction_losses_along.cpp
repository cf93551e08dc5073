// detail::FrictionLosses (solve/friction_losses.hpp) in the efforts' sensitivities: the adjoint of the losses'
// solve, and their forces' rate at fixed λ along the motion and along a design parameter, with the bearings' joints
// as the models along the parameter hold them.
#include <algorithm>
#include <cmath>
#include <string_view>

#include "phiq/constraint_block.hpp"
#include "phiq/kinds/spatial_gear.hpp"
#include "phiq/model.hpp"
#include "phiq/sensitivity.hpp"
#include "solve/friction_losses.hpp"
#include "solve/models_along.hpp"  // kShift

namespace phiq::detail {

bool FrictionLosses::adjoint(SparseLuNumeric& lu, Eigen::VectorXd& w) {
  const std::size_t nb = set_->bearings.size();
  if (!adjoint_ready_) {  // ∂m_i/∂λ over each bearing's joint's rows: the row's, the same for every driver row
    load_rows_.assign(6 * nb, 0.0);
    double d[6];
    for (std::size_t i = 0; i < nb; ++i) {
      const Bearing& b = set_->bearings[i];
      bearing_load_gradient(*b.spring->bearing, values_.data() + b.at, b.spatial, d);
      const auto& per_row = reactions_->kept_per_row(i);
      for (Index j = 0; j < per_row.cols(); ++j) {
        double g = 0.0;
        for (int v = 0; v < 6; ++v) g += d[v] * per_row(v, j);
        load_rows_[6 * i + static_cast<std::size_t>(j)] = b.spring->bearing->coefficient * g;
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
      const Index first = reactions_->kept_first_row(i), rows = reactions_->kept_per_row(i).cols();
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

void FrictionLosses::frozen_forces(const double* q, double t, const Eigen::VectorXd& lambda, const AppliedLoads* data,
                                   const JointsAlong* joints, std::size_t k, Eigen::VectorXd& out) {
  out.setZero(q_f_.size());
  if (reactions_) {
    frozen_values_.resize(values_.size());
    if (joints && !joints->at[k].empty())
      reactions_->evaluate_along(joints->at[k], q, t, lambda, frozen_values_.data());
    else
      reactions_->evaluate(q, t, lambda, frozen_values_.data());
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
                                const std::array<Eigen::VectorXd, 4>* moved, double h, Eigen::VectorXd& out) {
  const Index n = q_f_.size();
  const Eigen::Map<const Eigen::VectorXd> qv(q, n);
  for (std::size_t k = 0; k < 4; ++k) {
    qk_ = qv + (kShift[k] * e) * v;
    frozen_forces(qk_.data(), t, lambda, nullptr, nullptr, k, forces_[k]);
  }
  out = ((forces_[0] - forces_[3]) + 8.0 * (forces_[2] - forces_[1])) / (12.0 * e);
  if (std::none_of(along.begin(), along.end(), [](const AppliedLoads* a) { return a != nullptr; }) && !moved && !joints)
    return;
  for (std::size_t k = 0; k < 4; ++k)
    frozen_forces(moved ? (*moved)[k].data() : q, t, lambda, along[k], joints, k, forces_[k]);
  out += ((forces_[0] - forces_[3]) + 8.0 * (forces_[2] - forces_[1])) / (12.0 * h);
}

std::string FrictionLosses::sensitivity_refusal(const Model& model, const OutputSensitivity& p) const {
  const std::string with = "the efforts' sensitivities to '" + p.name + "' with ";
  for (const Bearing& b : set_->bearings)
    if (b.constraint < 0)
      return with + "the bearing at natural point '" + b.point +
             "': its reaction is its bodies' balance, not kept per multiplier as the losses' derivative reads it "
             "(ask them without the bearing, or join the bodies by a revolute)";
  if (!p.reach) return {};
  JointsAlong joints;
  const std::string who = find_joints_along(model, p, joints);
  return who.empty() ? who
                     : with + who + ": '" + p.name +
                           "' changes its joint or ratio, which the losses' derivative does not follow (ask them "
                           "without it)";
}

const FrictionLosses::JointsAlong* FrictionLosses::joints_along(const Model& model, const OutputSensitivity& p) {
  auto found = [](const JointsAlong& j) { return j.at[0].empty() && j.meshes[0].empty() ? nullptr : &j; };
  for (const JointsAlong& j : joints_along_)
    if (j.reach == p.reach.get()) return found(j);
  JointsAlong& j = joints_along_.emplace_back();
  j.reach = p.reach.get();
  if (const std::string who = find_joints_along(model, p, j); !who.empty())
    throw Error(sensitivity_refusal(model, p));  // (the sweep refused it at its start: not reached)
  return found(j);
}

std::string FrictionLosses::find_joints_along(const Model& model, const OutputSensitivity& p, JointsAlong& out) const {
  const ParameterReach& reach = *p.reach;
  const std::vector<Index>& reached = reach.rows;
  auto touched = [&](Index first, Index rows) {
    const auto it = std::lower_bound(reached.begin(), reached.end(), first);
    return it != reached.end() && *it < first + rows;
  };
  const ReachedConstraints* kept = p.reached && p.reached->reach.get() == &reach ? p.reached.get() : nullptr;
  const auto& blocks = model.blocks();
  // constraint c in the four models along p: their copies kept of its span, or the span's data moved along its
  // rates (ConstraintBlock::data_moved()), or the models themselves; false where none stands for it
  auto along_p = [&](Index c, std::array<JointReactions::BlockAt, 4>& at) {
    const auto found = model.constraint_block(c);  // (not a structured binding: the lambda below reads index)
    const ConstraintBlock* const block = found.first;
    const std::size_t index = found.second;
    std::size_t bi = 0;
    while (bi < blocks.size() && blocks[bi].get() != block) ++bi;
    const auto span = std::find_if(reach.spans.begin(), reach.spans.end(), [&](const ParameterReach::Span& s) {
      return s.block == bi && s.begin <= index && index < s.end;
    });
    if (reach.everything || span == reach.spans.end()) return false;
    const std::size_t j = static_cast<std::size_t>(span - reach.spans.begin()), in_span = index - span->begin;
    for (std::size_t k = 0; k < 4; ++k) {
      if (kept && kept->rates[j]) {
        out.owned.push_back(block->data_moved(index, *kept->rates[j], in_span, kShift[k] * p.step));
        if (!out.owned.back()) return false;
        at[k] = {out.owned.back().get(), 0};
      } else if (kept && kept->along[k][j] && in_span < kept->along[k][j]->size()) {
        at[k] = {kept->along[k][j].get(), in_span};
      } else if (!kept && p.models[k]) {
        at[k] = {p.models[k]->blocks()[bi].get(), index};
      } else {
        return false;
      }
    }
    return true;
  };
  std::array<JointReactions::BlockAt, 4> at;
  const std::size_t nb = set_->bearings.size(), nm = set_->meshes.size();
  for (std::size_t i = 0; i < nb; ++i) {
    const Bearing& b = set_->bearings[i];
    if (b.constraint < 0) return "the bearing at natural point '" + b.point + "'";
    const ConstraintInfo& c = model.constraints()[static_cast<std::size_t>(b.constraint)];
    // a planar journal's load is its force's size, which its multipliers alone give: no geometry read along p
    const std::string_view kind = c.kind;
    const bool planar_journal = !b.spatial && !b.spring->bearing->slide && (kind == "pin" || kind == "revolute");
    if (planar_journal || !touched(c.first_row, c.rows)) continue;
    if (!along_p(b.constraint, at)) return "the bearing of '" + c.name + "'";
    if (out.at[0].empty())
      for (auto& a : out.at) a.assign(nb, {});
    for (std::size_t k = 0; k < 4; ++k) out.at[k][i] = at[k];
  }
  for (std::size_t j = 0; j < nm; ++j) {
    const Mesh& m = set_->meshes[j];
    if (!touched(m.row, 1)) continue;
    const std::string who = "the gear losses of '" + m.loss->gear + "'";
    if (!along_p(model.find_constraint(m.loss->gear), at)) return who;
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
  return {};
}

}  // namespace phiq::detail
