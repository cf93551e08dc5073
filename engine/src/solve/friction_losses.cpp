// detail::FrictionLosses (solve/friction_losses.hpp): a bearing's friction from its joint's reaction and a mesh's
// losses from its multiplier, solved with the multipliers they change.
#include "solve/friction_losses.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>

#include "phiq/constraint_block.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/kinds/reaction_site.hpp"
#include "phiq/kinds/spatial_gear.hpp"
#include "phiq/model.hpp"
#include "phiq/natural_joints.hpp"
#include "phiq/part_motion.hpp"
#include "phiq/text.hpp"
#include "solve/models_along.hpp"  // kShift

namespace phiq::detail {

namespace {

// Why a spatial pair's friction cannot be a worm's, at the model's placement: its axes must cross at a right angle
// without meeting (a worm's, or crossed helical gears' at 90°), which the lead-angle formula assumes; empty when
// they do. (A pair's shafts stand in its housings, so their angle is the housings' at any placement.)
std::string not_a_worm(const SpatialMesh& g, const Eigen::VectorXd& q) {
  using kin3::V3;
  auto axis_of = [&](const JointSide3& side, V3& point, V3& axis) {
    PartFrame f;
    f.kind = PartFrameKind::kSpatialBody, f.spatial = side.frame;
    const Pose pose = part_pose(f, q.data(), 0.0);
    point = pose.apply(side.at);
    axis = pose.apply(side.axis) - pose.at;
    axis = (1.0 / kin3::norm(axis)) * axis;
  };
  V3 a1, z1, a2, z2;
  axis_of(g.a1, a1, z1), axis_of(g.a2, a2, z2);
  if (!(std::abs(kin3::dot(z1, z2)) <= 1e-6)) return "its shafts are not at a right angle";
  const double gap = std::abs(kin3::dot(a2 - a1, kin3::cross(z1, z2)));  // (|z1 × z2| = 1)
  if (!(gap > 1e-6 * (g.r1 + g.r2))) return "its axes meet (a bevel pair: give its efficiencies)";
  return {};
}

// The natural joint bearing spring `s` names (a point two bodies' frames share, efforts->natural's), else −1 (a
// constraint, or nothing: check() says which); `of_point` the natural bodies' point coordinates, found here once.
// Throws phiq::Error for one in space (a point has no axis to split its load along) or whose angle reads the points
// (its moment would not say which bodies it turns).
int natural_bearing(const Model& model, const TorsionalSpring& s, const OutputEfforts* efforts,
                    std::vector<char>& of_point) {
  if (model.find_constraint(s.bearing->joint) >= 0 || !efforts || !efforts->natural) return -1;
  const NaturalJoints& natural = *efforts->natural;
  const auto it = std::find_if(natural.joints.begin(), natural.joints.end(),
                               [&](const NaturalJoint& j) { return j.name == s.bearing->joint; });
  if (it == natural.joints.end()) return -1;
  const std::string who = "torsional spring '" + s.name + "': bearing at natural point '" + s.bearing->joint + "'";
  if (natural.spatial)
    throw Error(who + ": a point carries no axis in space to split its load along (join the bodies by a revolute)");
  if (of_point.empty()) of_point = point_coordinates(natural, model.num_coordinates());  // (once: every bearing's)
  for (const Index c : torsional_coordinates(s))
    if (of_point[static_cast<std::size_t>(c)])
      throw Error(who +
                  ": its angle reads the points, so its moment does not say which bodies it turns (give the "
                  "angle coordinates, as segment_angle constraints do)");
  return static_cast<int>(it - natural.joints.begin());
}

}  // namespace

double bearing_load(const BearingFriction& b, const double* f, bool spatial) {
  const double across = std::hypot(f[0], f[1]), along = spatial ? std::abs(f[2]) : 0.0;
  if (b.slide) {  // |F_r| + |M| / a: its tilt, Mz in the plane, the whole moment in space
    const double tilt = b.moment_arm > 0.0 ? (spatial ? std::hypot(f[3], f[4], f[5]) : std::abs(f[2])) : 0.0;
    return across + (tilt > 0.0 ? tilt / b.moment_arm : 0.0);
  }
  const double bending = b.moment_arm > 0.0 && spatial ? std::hypot(f[3], f[4]) / b.moment_arm : 0.0;
  return b.radius * (across + bending) + b.thrust_radius * along;
}

void bearing_load_gradient(const BearingFriction& b, const double* f, bool spatial, double* d) {
  std::fill(d, d + 6, 0.0);
  const double across = std::hypot(f[0], f[1]), scale = b.slide ? 1.0 : b.radius;
  if (across > 0.0) d[0] = scale * f[0] / across, d[1] = scale * f[1] / across;
  if (b.slide && b.moment_arm > 0.0 && !spatial) d[2] = friction_direction(f[2]) / b.moment_arm;
  if (b.slide || !spatial) {
    const double tilt = b.slide && spatial && b.moment_arm > 0.0 ? std::hypot(f[3], f[4], f[5]) : 0.0;
    if (tilt > 0.0)
      for (int k = 3; k < 6; ++k) d[k] = f[k] / (b.moment_arm * tilt);
    return;
  }
  d[2] = b.thrust_radius * friction_direction(f[2]);
  const double bending = b.moment_arm > 0.0 ? std::hypot(f[3], f[4]) : 0.0;
  if (bending > 0.0)
    d[3] = b.radius * f[3] / (b.moment_arm * bending), d[4] = b.radius * f[4] / (b.moment_arm * bending);
}

bool FrictionLosses::carries(std::string_view kind) {
  return kind == "pin" || kind == "revolute" || kind == "cylindrical" || kind == "prismatic";
}

bool FrictionLosses::transmits(std::string_view kind) {
  return kind == "gear" || kind == "rack_pinion" || kind == "belt" || kind == "spatial_gear";
}

bool FrictionLosses::any(const AppliedLoads* loads) {
  return loads &&
         (!loads->gear_losses.empty() || std::any_of(loads->torsional_springs.begin(), loads->torsional_springs.end(),
                                                     [](const TorsionalSpring& s) { return s.bearing.has_value(); }));
}

Index FrictionLosses::check(const Model& model, const TorsionalSpring& s) {
  const std::string who = "torsional spring '" + s.name + "': bearing joint '" + s.bearing->joint + "'";
  const Index c = model.find_constraint(s.bearing->joint);
  if (c < 0)
    throw Error(who +
                " is not a constraint of the model, nor a point two parts' frames of points share (a natural "
                "joint of the scene's)");
  const std::string_view kind = model.constraints()[static_cast<std::size_t>(c)].kind;
  if (!carries(kind) || reaction_width(model, c) == 0)
    throw Error(who + " is a " + std::string(kind) +
                ": a bearing is a pin, revolute, cylindrical or prismatic joint (whose reaction loads it)");
  if (s.bearing->slide ? kind != "prismatic" && kind != "cylindrical" : kind == "prismatic")
    throw Error(
        who + " is a " + std::string(kind) + ": its friction is " +
        (s.bearing->slide ? "a journal's moment, not a slide's force" : "a slide's force, not a journal's moment"));
  return c;
}

void FrictionLosses::check_model(const Model& model, const std::string& who, bool bearing) {
  if (!model.dropped_rows().empty())
    throw Error(who +
                ": a loss that reads the multipliers (a bearing's reaction, a mesh's share) is statically "
                "indeterminate where constraints are redundant (the model dropped " +
                std::to_string(model.dropped_rows().size()) + " redundant rows)");
  if (!bearing) return;
  for (std::size_t c = 0; c < model.constraints().size(); ++c) {
    const auto [block, index] = model.constraint_block(static_cast<Index>(c));
    if (GearMesh g; block->gear_mesh(index, g))
      throw Error(who + ": a bearing's friction reads its joint's reaction, which leaves out the push of '" +
                  model.constraints()[c].name + "''s " + (g.belt ? "strands" : "teeth") +
                  " on its bearings (bearings' friction in a geared model is not computed)");
  }
}

bool FrictionLosses::at_points(const Model& model, const AppliedLoads* loads) {
  return loads &&
         std::any_of(loads->torsional_springs.begin(), loads->torsional_springs.end(), [&](const TorsionalSpring& s) {
           return s.bearing && model.find_constraint(s.bearing->joint) < 0;
         });
}

FrictionLosses::FrictionLosses(const Model& model, const AppliedLoads& loads, const OutputEfforts* efforts) {
  auto up = std::make_shared<SetUp>();
  OutputEfforts joints;
  joints.reactions_in_joint_axes = true;  // (a spatial joint's z is its axis: F_a its z, F_r across)
  std::size_t at = 0;
  std::vector<char> of_point;  // the natural bodies' point coordinates, found at the first natural bearing
  for (const TorsionalSpring& s : loads.torsional_springs) {
    if (!s.bearing) continue;
    if (const int j = natural_bearing(model, s, efforts, of_point); j >= 0) {  // a point two bodies share (planar)
      joints.reactions.push_back({-1, false, j});
      up->bearings.push_back({&s, -1, s.bearing->joint, at, false});
      at += 3, natural_ = true;
      continue;
    }
    const Index c = check(model, s);
    const bool spatial = reaction_width(model, c) == 6;
    joints.reactions.push_back({c, spatial});
    up->bearings.push_back({&s, c, {}, at, spatial});
    at += spatial ? 6 : 3;
  }
  for (const GearLoss& l : loads.gear_losses) {
    const std::string who = "gear loss of '" + l.gear + "'";
    const Index c = model.find_constraint(l.gear);
    if (c < 0) throw Error(who + ": not a constraint of the model");
    const ConstraintInfo& info = model.constraints()[static_cast<std::size_t>(c)];
    if (!transmits(info.kind) || !(l.efficiency > 0.0 && l.efficiency <= 1.0) ||
        !(l.reverse_efficiency <= 1.0 && std::isfinite(l.reverse_efficiency)) || !(l.friction >= 0.0))
      throw Error(who + ": a " + std::string(info.kind) +
                  ", or an efficiency outside (0, 1] (a reverse one above 1), or a negative friction: the loss is a "
                  "gear's, rack's, belt's or spatial pair's");
    const auto [block, index] = model.constraint_block(c);
    Mesh m;
    m.loss = &l, m.row = info.first_row + info.rows - 1;  // (the ratio row, a spatial pair's last)
    m.eta[1] = l.efficiency, m.eta[0] = l.reverse_efficiency;
    if (l.friction > 0.0 && std::string_view(info.kind) != "spatial_gear")
      throw Error(who + ": a friction coefficient gives a worm pair's efficiencies (a spatial_gear)");
    if (GearMesh g; block->gear_mesh(index, g)) {
      m.member[0] = g.first, m.member[1] = g.second, m.carrier = g.carrier, m.k = g.k;
    } else if (SpatialMesh sm; block->spatial_mesh(index, sm)) {
      m.member[0] = sm.theta1, m.member[1] = sm.theta2, m.carrier = Slot::constant(0.0), m.k = sm.k;
      if (l.friction > 0.0) {  // a worm pair's efficiencies from its lead angle and pressure angle (GearLoss)
        if (!(sm.r1 > 0.0 && sm.r2 > 0.0))
          throw Error(who + ": a friction coefficient needs the pair's pitch radii (`pitch_radii` or `radii`)");
        if (const std::string why = not_a_worm(sm, model.initial_positions()); !why.empty())
          throw Error(who + ": a friction coefficient gives a worm's efficiencies, but " + why);
        const double tan_lead = sm.r2 / (std::abs(sm.k) * sm.r1), c = std::cos(sm.pressure_angle), mu = l.friction;
        m.tan_lead = tan_lead, m.cos_pressure = c;
        m.eta[1] = (c - mu * tan_lead) / (c + mu / tan_lead);
        m.eta[0] = (c - mu / tan_lead) / (c + mu * tan_lead);
        if (!(m.eta[1] > 0.0))
          throw Error(who + ": with friction " + shortest(mu) + " the worm cannot drive its wheel (lead angle " +
                      significant(std::atan(tan_lead) * 180.0 / M_PI, 4) + "°): its efficiency would be " +
                      significant(m.eta[1], 4));
      }
    } else {
      throw Error(who + ": its " + std::string(info.kind) + " states no mesh (phiq bug)");
    }
    up->meshes.push_back(m);
  }
  if (up->bearings.empty() && up->meshes.empty()) return;
  check_model(model,
              up->bearings.empty() ? "gear loss of '" + up->meshes[0].loss->gear + "'"
                                   : "torsional spring '" + up->bearings[0].spring->name + "'",
              !up->bearings.empty());
  if (natural_) joints.parts = efforts->parts, joints.loads = efforts->loads, joints.natural = efforts->natural;
  if (!up->bearings.empty()) reactions_.emplace(model, joints);
  for (std::size_t i = 0, k = 0; i < up->bearings.size(); ++i) {
    up->bearings[i].kept = natural_ ? k : i;
    k += up->bearings[i].constraint >= 0 ? 1 : 0;
  }
  if (natural_) {  // (the efforts' sensitivities' adjoint keeps the other bearings' joints' geometry apart)
    OutputEfforts others;
    others.reactions_in_joint_axes = true;
    for (const OutputReaction& r : joints.reactions)
      if (r.natural < 0) others.reactions.push_back(r);
    if (!others.reactions.empty()) kept_reactions_.emplace(model, others);
  }
  up->joints = std::move(joints);
  set_ = std::move(up);
  size_scratch();
}

FrictionLosses::FrictionLosses(const FrictionLosses& other, SetUpOnly) : set_(other.set_), natural_(other.natural_) {
  if (other.reactions_) reactions_.emplace(JointReactions::with_set_up_of(*other.reactions_));
  if (other.kept_reactions_) kept_reactions_.emplace(JointReactions::with_set_up_of(*other.kept_reactions_));
  size_scratch();
}

void FrictionLosses::size_scratch() {
  if (reactions_) values_.assign(static_cast<std::size_t>(reactions_->size()), 0.0);
  moments_.assign(set_->bearings.size() + set_->meshes.size(), 0.0), next_ = moments_;
  rates_.assign(set_->bearings.size(), 0.0);
  gradients_.resize(set_->bearings.size());
  mesh_states_.assign(set_->meshes.size(), MeshState{});
}

void FrictionLosses::moments_at(const double* q, double t, const Eigen::VectorXd& lambda, std::vector<double>& m) {
  if (natural_)  // (a natural point's reaction reads its bodies' motion: evaluated whole)
    reactions_->evaluate(q, qd_, qdd_, t, lambda, values_.data());
  else if (reactions_)
    reactions_->evaluate_kept(q, t, lambda, values_.data());
  for (std::size_t i = 0; i < set_->bearings.size(); ++i) {
    const BearingFriction& b = *set_->bearings[i].spring->bearing;
    const double* f = values_.data() + set_->bearings[i].at;
    m[i] = b.coefficient * bearing_load(b, f, set_->bearings[i].spatial);
  }
  for (std::size_t j = 0; j < set_->meshes.size(); ++j) {
    // the row's effort on each member, −∂row/∂θ_i λ, and its power relative to the carrier: the driven member's > 0
    const Mesh& mesh = set_->meshes[j];
    MeshState& state = mesh_states_[j];
    const double effort[2] = {-lambda(mesh.row), -mesh.k * lambda(mesh.row)};
    state.driven = effort[0] * state.rate[0] > 0.0 ? 0 : effort[1] * state.rate[1] > 0.0 ? 1 : -1;
    state.effort_sign = state.driven < 0 ? 0.0 : friction_direction(effort[state.driven]);
    m[set_->bearings.size() + j] =
        state.driven < 0 ? 0.0 : (1.0 - mesh.eta[state.driven]) * std::abs(effort[state.driven]);
  }
}

bool FrictionLosses::solve(const Model& model, SparseLuNumeric& lu, const double* q, const double* qd,
                           const double* qdd, double t, Eigen::VectorXd& Q, Eigen::VectorXd& lambda,
                           Eigen::VectorXd& kept) {
  solves_ = 0, passes_ = 0, failed_solve_ = false, worst_change_ = 0.0, ratio_ = 0.0;
  q_ = q, qd_ = qd, qdd_ = qdd, t_ = t, adjoint_ready_ = false;
  if (natural_ && (!qd || !qdd)) throw Error("FrictionLosses: a natural point's bearing reads q̇ and q̈ (phiq bug)");
  for (std::size_t i = 0; i < set_->bearings.size(); ++i)
    rates_[i] = angle_rate(*set_->bearings[i].spring, q, qd, t, gradients_[i]);
  auto rate = [&](const Slot& s) { return s.is_coordinate() && qd ? qd[s.coord()] : 0.0; };
  for (std::size_t j = 0; j < set_->meshes.size(); ++j)
    for (int i = 0; i < 2; ++i)
      mesh_states_[j].rate[i] = rate(set_->meshes[j].member[i]) - rate(set_->meshes[j].carrier);
  lambda0_ = lambda;
  if (reactions_ && !natural_) reactions_->keep_geometry(q, t);  // (the passes' reactions differ in λ alone)
  moments_at(q, t, lambda, moments_);
  q_f_.resize(Q.size());
  double first_change = 0.0;
  int growing = 0;  // passes in a row whose change grew
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    // Q_f of the moments, against each θ̇ (none at rest)
    q_f_.setZero();
    for (std::size_t i = 0; i < set_->bearings.size(); ++i) {
      const double m = moments_[i] * friction_direction(rates_[i]);
      const std::vector<Index>& c = torsional_coordinates(*set_->bearings[i].spring);
      for (std::size_t k = 0; k < c.size(); ++k) q_f_(c[k]) -= m * gradients_[i][k];
    }
    for (std::size_t j = 0; j < set_->meshes.size(); ++j) {  // against the driven member's turn on the carrier
      const Mesh& mesh = set_->meshes[j];
      const MeshState& state = mesh_states_[j];
      if (state.driven < 0) continue;
      const double m = moments_[set_->bearings.size() + j] * friction_direction(state.rate[state.driven]);
      if (mesh.member[state.driven].is_coordinate()) q_f_(mesh.member[state.driven].coord()) -= m;
      if (mesh.carrier.is_coordinate()) q_f_(mesh.carrier.coord()) += m;
    }
    if (q_f_.isZero(0.0)) return true;  // (every bearing at rest or unloaded: λ0 stands)
    if (!multipliers_with_factors(model, lu, q_f_, kept, d_lambda_)) return failed_solve_ = true, false;
    ++solves_;
    lambda = lambda0_ + d_lambda_;
    moments_at(q, t, lambda, next_);
    // settled when no moment changes beyond rounding: λ is then the multipliers of the moments it was solved with
    double change = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < moments_.size(); ++i) {
      const double d = std::abs(next_[i] - moments_[i]);
      if (d > change) change = d, worst_ = i;
      scale = std::max(scale, std::abs(next_[i]));
    }
    passes_ = pass + 1;
    if (change <= 1e-13 * scale) {
      Q += q_f_;
      return true;
    }
    if (pass == 0) first_change = change;
    // The pass's contraction ρ: below 1 near the solution it makes the solution unique (the friction takes more of
    // its own load than it adds) and the passes reach it; at 1 or more there is none or several (a jam, or
    // Painlevé's indeterminacy), which the passes cannot settle on, and which is told as such.
    if (pass > 0) ratio_ = change / worst_change_, growing = ratio_ >= 1.0 ? growing + 1 : 0;
    worst_change_ = change;
    if (growing >= 3 || !(change <= 1e3 * first_change)) break;  // not settling (or not finite): it will not
    std::swap(moments_, next_);
  }
  Q += q_f_;
  return false;
}

double FrictionLosses::exerted(std::size_t i) const {
  const std::size_t nb = set_->bearings.size();
  if (i < nb) return moments_[i] * std::abs(friction_direction(rates_[i]));
  const MeshState& state = mesh_states_[i - nb];
  return state.driven < 0 ? 0.0 : moments_[i] * std::abs(friction_direction(state.rate[state.driven]));
}

double FrictionLosses::dissipated(std::size_t i) const {
  const std::size_t nb = set_->bearings.size();
  if (i < nb) return moments_[i] * std::abs(rates_[i]);
  const MeshState& state = mesh_states_[i - nb];
  return state.driven < 0 ? 0.0 : moments_[i] * std::abs(state.rate[state.driven]);
}

std::string FrictionLosses::name(std::size_t i) const {
  if (i >= set_->bearings.size())
    return "the meshing loss of '" + set_->meshes[i - set_->bearings.size()].loss->gear + "'";
  const TorsionalSpring& s = *set_->bearings[i].spring;
  return "the friction of bearing '" + s.bearing->joint + "' (torsional spring '" + s.name + "')";
}

SolveStatus FrictionLosses::failure(const SparseLuNumeric& lu, std::string* message) const {
  if (message) *message = failed_solve_ ? lu.last_message() : lock_message();
  return failed_solve_ ? SolveStatus::kLinearSolverFailed : SolveStatus::kNotConverged;
}

std::string FrictionLosses::lock_message() const {
  return name(worst_) + " adds to its own load " +
         (ratio_ >= 1.0 ? "as much as it takes or more (a pass multiplies its change by " + significant(ratio_, 3) +
                              "): the mechanism jams (self-locking) or its friction is not determined"
                        : "almost as much as it takes (a pass multiplies its change by " + significant(ratio_, 3) +
                              ", not settled in " + std::to_string(passes_) +
                              " passes): the mechanism is at the edge of self-locking") +
         "; no effort is written here";
}

}  // namespace phiq::detail
