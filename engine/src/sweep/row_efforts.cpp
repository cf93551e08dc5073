// Sweeper::row_efforts(): a written row's driver efforts and powers (OutputPlan::efforts), by inverse dynamics with
// the row's own factors of Φq (phiq/inverse_dynamics.hpp).
#include <algorithm>
#include <cmath>
#include <limits>

#include "phiq/effort_sensitivity.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/joint_reactions.hpp"
#include "phiq/parts.hpp"
#include "sweep/sweeper.hpp"

namespace phiq::detail {

bool Sweeper::row_efforts() {
  const OutputEfforts& e = opt_.efforts;
  const std::size_t n = e.constraints.size();
  auto not_defined = [&] {
    std::fill(outputs_.efforts.begin(), outputs_.efforts.end(), std::numeric_limits<double>::quiet_NaN());
    return true;
  };
  // At a singular position the multipliers are not unique and a driver's effort may be unbounded: NaN, which the
  // row's bifurcation warning explains, rather than a huge number from a nearly singular solve.
  if (singular_.at_row) return not_defined();
  Workspace* w = row_factors();
  if (!w) return not_defined();
  const double t = current_.t;
  effort_work_.q.setZero(model_.num_coordinates());
  effort_work_.forces->add(*e.parts, *e.loads, current_.q.data(), current_.qd.data(), current_.qdd.data(), t,
                           effort_work_.q, effort_work_.planar.empty() ? nullptr : effort_work_.planar.data());
  if (!multipliers_with_factors(model_, *w->lu, effort_work_.q, effort_work_.kept, effort_work_.lambda))
    return not_defined();
  ++ws_->counters.effort_solves;
  // A regular position with finite q, q̇, q̈ whose forces or multipliers are not finite: masses, inertias or loads
  // so large that their products overflow (a gravity of 1e308). NaN there would pass for a singular position's.
  if (!effort_work_.q.allFinite() || !effort_work_.lambda.allFinite()) {
    not_defined();  // (a Stepper, which delivers the row whatever, then reads NaN, not the last row's values)
    if (effort_work_.q.allFinite())
      return fail(SolveStatus::kNonFinite,
                  "efforts: the multipliers of the parts' forces are not finite (an overflow: "
                  "masses, inertias or loads too large for doubles)");
    // the part or load that made Q not finite, named (evaluated once more, alone: this row ends the sweep)
    std::string why = nonfinite_force_source(*e.parts, *e.loads, model_.num_coordinates(), current_.q.data(),
                                             current_.qd.data(), current_.qdd.data(), t);
    if (why.empty()) {
      Index j = 0;
      while (j + 1 < effort_work_.q.size() && std::isfinite(effort_work_.q(j))) ++j;
      why = "the force of the parts' masses and loads along '" +
            model_.coordinate_names()[static_cast<std::size_t>(j)] +
            "' is not finite (an overflow: their sum too large for doubles)";
    }
    return fail(SolveStatus::kNonFinite, "efforts: " + why);
  }
  if (effort_work_.losses) {  // the bearings' friction and the gears' losses, from the multipliers they change
    FrictionLosses& losses = *effort_work_.losses;
    const bool settled = losses.solve(model_, *w->lu, current_.q.data(), current_.qd.data(), current_.qdd.data(), t,
                                      effort_work_.q, effort_work_.lambda, effort_work_.kept);
    ws_->counters.effort_solves += losses.solves();
    if (!settled) {
      if (!losses.failed_solve()) sum_.warnings.push_back({t, "friction_lock", losses.lock_message()});
      return not_defined();
    }
    double* out = outputs_.efforts.data() + e.losses_at();
    for (const OutputLoss& l : e.losses) {
      if (l.bearing) *out++ = losses.exerted(l.index);
      *out++ = losses.dissipated(l.index);
    }
  }
  // Φt at the drivers' rows only (a power reads no other; the whole model's is O(rows) at every row)
  effort_work_.phi_t.resize(model_.num_equations());
  const std::vector<ConstraintInfo>& cs = model_.constraints();
  for (const Index c : e.constraints) {
    const ConstraintInfo& info = cs[static_cast<std::size_t>(c)];
    effort_work_.phi_t.segment(info.first_row, info.rows).setZero();
    const auto [block, index] = model_.constraint_block(c);
    block->phi_t(index, index + 1, current_.q.data(), t, effort_work_.phi_t.data());
  }
  for (std::size_t i = 0; i < n; ++i) {
    const ConstraintInfo& c = cs[static_cast<std::size_t>(e.constraints[i])];
    double power = 0.0;
    for (Index r = c.first_row; r < c.first_row + c.rows; ++r) power += effort_work_.lambda(r) * effort_work_.phi_t(r);
    outputs_.efforts[i] = -effort_work_.lambda(c.first_row);
    outputs_.efforts[n + i] = power;
  }
  for (std::size_t i : effort_work_.dropped)
    outputs_.efforts[i] = outputs_.efforts[n + i] = std::numeric_limits<double>::quiet_NaN();
  // ∂τ/∂p with the multipliers before row_reactions() makes them the minimum-norm ones, and the row's direct
  // sensitivities (sweep_sensitivity_form()): after the reactions in outputs_.efforts
  if (n > 0 && !opt_.sensitivities.empty()) {
    double* out = outputs_.efforts.data() + e.size();
    effort_work_.sensitivity_scratch.losses = effort_work_.losses ? &*effort_work_.losses : nullptr;
    const EffortSensitivityLayout layout{n};
    if (!effort_sensitivities_with_factors(model_, e, opt_.sensitivities, t, current_.q.data(), current_.qd.data(),
                                           current_.qdd.data(), effort_work_.lambda, outputs_.sensitivities.data(),
                                           *w->lu, effort_work_.sensitivity_scratch, out))
      std::fill(out, outputs_.efforts.data() + outputs_.efforts.size(), std::numeric_limits<double>::quiet_NaN());
    else
      for (std::size_t i : effort_work_.dropped)
        for (std::size_t j = 0; j < opt_.sensitivities.size(); ++j)
          out[layout.offset(j, i)] = out[layout.power_offset(opt_.sensitivities.size(), j, i)] =
              std::numeric_limits<double>::quiet_NaN();
  }
  if (effort_work_.reactions) row_reactions(*w->lu);
  return true;
}

void Sweeper::row_reactions(SparseLuNumeric& lu) {
  const double t = current_.t;
  std::vector<Index> indeterminate;
  const bool note = !effort_work_.reactions_noted && t == opt_.t_begin;
  auto not_defined = [&] {
    std::fill(outputs_.efforts.begin() + 2 * static_cast<std::ptrdiff_t>(opt_.efforts.constraints.size()),
              outputs_.efforts.begin() + opt_.efforts.size(), std::numeric_limits<double>::quiet_NaN());
  };
  if (!minimum_norm_multipliers(model_, lu, current_.q.data(), t, effort_work_.lambda, note ? &indeterminate : nullptr,
                                effort_work_.minimum_norm))
    return not_defined();
  // The bearings of gears carry their teeth's push (add_gear_mesh_forces()), from each mesh's share of the load: its
  // minimum-norm multiplier where meshes are redundant (the planets of an epicyclic train), not the share the rows
  // left in the solve would give it (all of it to some, none to the others).
  if (!opt_.efforts.meshes.empty()) {
    effort_work_.mesh_q.setZero(model_.num_coordinates());
    MeshFindings& found = effort_work_.mesh_findings;
    found.working.clear(), found.slack.clear(), found.unplaced.clear();
    add_gear_mesh_forces(model_, opt_.efforts.meshes, current_.q.data(), effort_work_.lambda, effort_work_.mesh_q,
                         current_.qd.data(), &found, &effort_work_.mesh_jacobian);
    warn_meshes(found, note);
    if (!effort_work_.mesh_q.isZero(0.0)) {  // (meshes that push nothing here, all of them unloaded: no solve)
      if (!multipliers_with_factors(model_, lu, effort_work_.mesh_q, effort_work_.kept, effort_work_.mesh_lambda))
        return not_defined();
      ++ws_->counters.effort_solves;
      effort_work_.lambda += effort_work_.mesh_lambda;
    }
  }
  // the natural bodies' weight and inertia as Q took them at this row (row_efforts())
  effort_work_.reactions->evaluate(current_.q.data(), current_.qd.data(), current_.qdd.data(), t, effort_work_.lambda,
                                   outputs_.efforts.data() + 2 * opt_.efforts.constraints.size(),
                                   effort_work_.planar.empty() ? nullptr : effort_work_.planar.data());
  if (!note) return;
  effort_work_.reactions_noted = true;
  std::string names, meshes;
  auto listed = [&](Index c) {
    return std::find(indeterminate.begin(), indeterminate.end(), c) != indeterminate.end();
  };
  auto name = [&](std::string& list, Index c) {
    list += (list.empty() ? "'" : ", '") + model_.constraints()[static_cast<std::size_t>(c)].name + "'";
  };
  for (const OutputReaction& r : opt_.efforts.reactions)
    if (r.natural < 0 && listed(r.constraint)) name(names, r.constraint);
  for (const OutputMesh& m : opt_.efforts.meshes)
    if (listed(m.constraint)) name(meshes, m.constraint);
  if (!names.empty() || !meshes.empty())
    sum_.warnings.push_back(
        {t, "indeterminate",
         (names.empty() ? "" : "the reactions of " + names) + (names.empty() || meshes.empty() ? "" : " and ") +
             (meshes.empty() ? "" : "the shares of the load of the gears " + meshes + " (and so their bearings')") +
             " are statically indeterminate (redundant constraints): the minimum-norm ones are written"});
}

void Sweeper::warn_meshes(const MeshFindings& found, bool first_row) {
  const double t = current_.t;
  auto name = [&](Index c) { return "'" + model_.constraints()[static_cast<std::size_t>(c)].name + "'"; };
  // at every row (once_per_stretch() joins the rows that follow): a mesh at rest does no work, so a gear wrongly
  // carried shows only once it turns
  if (!found.working.empty()) {  // the first one
    const Index c = found.working[0];
    const auto m = std::find_if(opt_.efforts.meshes.begin(), opt_.efforts.meshes.end(),
                                [&](const OutputMesh& o) { return o.constraint == c; });
    sum_.warnings.push_back(
        {t, "gear_centres",
         m->mesh.belt ? "the strands of " + name(c) +
                            " do work in the motion: its bodies' reference points are not pulley centres held at "
                            "their distance, so its bearings' loads are not its strands'"
                      : "the teeth of " + name(c) +
                            " do work in the motion: its bodies' reference points are not gear centres that its "
                            "carrier holds (a gear on a moving arm names the arm as its carrier), so its bearings' "
                            "loads are not its teeth's"});
  }
  if (!found.slack.empty())
    sum_.warnings.push_back({t, "belt_slack",
                             name(found.slack[0]) +
                                 " goes slack: its torque needs its strands' tensions to differ by more than twice its "
                                 "tension, so it would slip (its bearings' loads are written with its slack strand "
                                 "pushing)"});
  if (!first_row) return;  // the rest is told at the sweep's first row, as the indeterminate joints are
  for (const OutputMesh& m : opt_.efforts.meshes)
    if (!m.unloaded.empty())
      sum_.warnings.push_back({t, "unloaded_bearings",
                               "the bearings of " + name(m.constraint) + " carry none of its " +
                                   (m.mesh.belt ? "strands' pull: " : "teeth's push: ") + m.unloaded});
  for (const auto& [c, why] : found.unplaced)
    sum_.warnings.push_back(
        {t, "unloaded_bearings", "the bearings of " + name(c) + " carry none of its teeth's push: " + why});
}

bool Sweeper::same_sweep(const Sweeper* like) const { return like && &like->model_ == &model_ && &like->opt_ == &opt_; }

std::optional<JointReactions> Sweeper::written_reactions(const Sweeper* like) const {
  if (opt_.efforts.reactions.empty()) return std::nullopt;
  if (same_sweep(like) && like->effort_work_.reactions)
    return JointReactions::with_set_up_of(*like->effort_work_.reactions);
  return JointReactions(model_, opt_.efforts, rigid_bars());
}

std::vector<std::size_t> Sweeper::dropped_efforts() const {
  // A driver whose row was dropped as redundant shares its load with the equations it repeats: not its own.
  std::vector<std::size_t> out;
  const std::vector<Index>& cs = opt_.efforts.constraints;
  for (std::size_t i = 0; i < cs.size(); ++i) {
    const ConstraintInfo& c = model_.constraints()[static_cast<std::size_t>(cs[i])];
    for (Index r : model_.dropped_rows())
      if (r >= c.first_row && r < c.first_row + c.rows) {
        out.push_back(i);
        break;
      }
  }
  return out;
}

}  // namespace phiq::detail
