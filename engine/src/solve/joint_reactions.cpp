// JointReactions and minimum_norm_multipliers() (phiq/joint_reactions.hpp).
#include "phiq/joint_reactions.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "phiq/constraint_block.hpp"
#include "phiq/part_motion.hpp"
#include "solve/minimum_norm.hpp"
#include "solve/part_forces.hpp"

namespace phiq {

namespace {

using kin3::V3;

PartFrame body_frame(const ReactionSite& s) {
  PartFrame f;
  f.kind = s.spatial ? PartFrameKind::kSpatialBody : PartFrameKind::kPlanarBody;
  f.planar = s.frame2;
  f.spatial = s.frame3;
  return f;
}
// A spatial body's frame (a shaft's or a housing's).
PartFrame body_frame(const Frame3& body) {
  ReactionSite s;
  s.spatial = true, s.frame3 = body;
  return body_frame(s);
}

// F at P on shaft 1, −F on shaft 2, λ on θ1 and k λ on θ2 (push_shafts()).
template <class Add>
const char* push_at(const SpatialMesh& g, const V3& p, const V3& force, double lambda, const double* q,
                    PartJacobian& jac, Add& add) {
  auto push = [&](const JointSide3& side, V3 on) {  // `on` at P
    if (!detail::frame_moves(side.frame)) return;
    const PartFrame frame = body_frame(side.frame);
    part_jacobian(frame, q, 0.0, jac);
    const V3 arm = p - part_pose(frame, q, 0.0).at;
    for (std::size_t k = 0; k < jac.coordinates.size(); ++k)
      add(jac.coordinates[k], dot(on, jac.d_origin[k] + cross(jac.d_angle[k], arm)));
  };
  push(g.b1, force), push(g.b2, -force);
  if (g.theta1.is_coordinate()) add(g.theta1.coord(), lambda);
  if (g.theta2.is_coordinate()) add(g.theta2.coord(), g.k * lambda);
  return nullptr;
}

// A spatial gear pair's push on its shafts (add_gear_mesh_forces()), through `add(j, v)` on coordinate j: null, or
// why it adds nothing. Each joint's side a gives its axis z_i through its point. The ratio row's λ turns the angles
// θ1, θ2 by τ1 = −λ and τ2 = −k λ; the teeth push shaft 1 at the pitch point P by F instead, whose moment about
// axis 1 is τ1, and shaft 2 by −F, whose moment about axis 2 is τ2: F at P on shaft 1, −F on shaft 2, λ on θ1 and
// k λ on θ2. Where the axes cross (bevel gears; z_i from the apex O toward its gear, so not `reversed`),
// P = O + (r2 z1 + r1 z2)/sin Σ, at r1 from axis 1 and r2 from axis 2, and F = f n + |f| tan α m1 (n = z1 × z2 /
// sin Σ, f = τ1/r1; m1 ⟂ OP in the axes' plane, toward axis 1, parts the gears). Where they do not (worms,
// crossed helical gears), P is on their common perpendicular ρ, r1 from axis 1 (the radii must span it), and F,
// frictionless, has the components along t1 = z1 × ρ and t2 = −z2 × ρ that give both moments, and tan α of its
// size along −ρ. Where they are parallel (spur and helical gears; internal where the pair turns its shafts the
// same way), P is on the line of centres, in the mid-plane mesh_offset along axis 1 from shaft 1's point: r1 from
// axis 1 toward axis 2, or away from it for an internal pinion, the radii found from the centre distance a and the
// ratio where only teeth are given (a/(1 + z2/z1), a/|z2/z1 − 1|). The tooth's normal force, frictionless, is
// F = f t − f tan ψ z1 + |f| tan α / cos ψ (∓ρ): t the way P moves on gear 1 turning about z1, ψ gear 1's helix
// angle (right-handed > 0: a tooth line along cos ψ z1 + sin ψ t, to which F is normal), α the normal pressure
// angle, parting the gears (on gear 1 toward its axis, or a ring's away from it).
template <class Add>
const char* push_shafts(const SpatialMesh& g, double lambda, const double* q, PartJacobian& jac, Add&& add) {
  auto axis_of = [&](const JointSide3& side, V3& point, V3& axis) {
    const Pose pose = part_pose(body_frame(side.frame), q, 0.0);
    point = pose.apply(side.at);
    axis = pose.apply(side.axis) - pose.at;
    axis = (1.0 / norm(axis)) * axis;
  };
  V3 a1, z1, a2, z2;
  axis_of(g.a1, a1, z1), axis_of(g.a2, a2, z2);
  const double cos_s = dot(z1, z2), sin_s = norm(cross(z1, z2));
  const double tan_a = std::tan(g.pressure_angle);
  V3 p, force;
  if (!(sin_s > 1e-9)) {
    const V3 o1 = part_pose(body_frame(g.b1.frame), q, 0.0).apply(g.b1.at) + g.mesh_offset * z1;
    const bool internal = parallel_pair_internal(cos_s, g.reversed);
    const double k = std::fabs(g.k);
    const ParallelPitch pitch = parallel_pitch(o1, z1, a2, internal, k);
    const double a = pitch.a;
    if (!(a > 0.0)) return "its parallel axes are one";
    double r1 = g.r1, r2 = g.r2;
    if (r1 == 0.0) {
      if (pitch.r1 == 0.0) return "it is an internal pair of equal gears";
      r1 = pitch.r1, r2 = pitch.r2;
    } else if (!(std::fabs(r2 / r1 - k) <= 1e-6 * k)) {
      return "its pitch_radii are not in its teeth's ratio, as parallel shafts' gears are";
    } else if (!(std::fabs((internal ? std::fabs(r2 - r1) : r1 + r2) - a) <= 1e-6 * a)) {
      return internal ? "its parallel axes do not stand the difference of its pitch radii apart (it is internal)"
                      : "its parallel axes do not stand its two pitch radii apart";
    }
    const V3 rho = pitch.rho;
    const double side = internal && r1 < r2 ? -1.0 : 1.0, f = -lambda / r1;
    p = o1 + (side * r1) * rho;
    force = (side * f) * cross(z1, rho) - (f * std::tan(g.helix_angle)) * z1 +
            (std::fabs(f) * tan_a / std::cos(g.helix_angle) * (internal ? 1.0 : -1.0)) * rho;
    return push_at(g, p, force, lambda, q, jac, add);
  }
  if (g.r1 == 0.0) return "its teeth do not place its pitch point (its radii or pitch_radii do)";
  const V3 w = a1 - a2;  // the closest points of the axes, a1 + s1 z1 and a2 + s2 z2
  const double d = dot(z1, w), e = dot(z2, w), s1 = (cos_s * e - d) / (sin_s * sin_s),
               s2 = (e - cos_s * d) / (sin_s * sin_s);
  const V3 o1 = a1 + s1 * z1, o2 = a2 + s2 * z2;
  const double gap = norm(o2 - o1);
  if (gap <= 1e-6 * (g.r1 + g.r2)) {
    if (g.reversed) return "it is reversed, so which shaft's axis points away from its gear is not told";
    const V3 apex = 0.5 * (o1 + o2);
    p = apex + (1.0 / sin_s) * (g.r2 * z1 + g.r1 * z2);
    const V3 n = (1.0 / sin_s) * cross(z1, z2), u = (1.0 / norm(p - apex)) * (p - apex);
    const V3 m1 = z1 - dot(z1, u) * u;
    const double f = -lambda / g.r1;
    force = f * n + (std::fabs(f) * tan_a / norm(m1)) * m1;
  } else {
    if (!(std::fabs(gap - (g.r1 + g.r2)) <= 1e-6 * gap))
      return "its axes neither cross nor stand its two pitch radii apart";
    const V3 rho = (1.0 / gap) * (o2 - o1), t1 = cross(z1, rho), t2 = cross(rho, z2);
    p = o1 + g.r1 * rho;
    const double c = dot(t1, t2), b1 = -lambda / g.r1, b2 = g.k * lambda / g.r2;  // F · t1, F · t2
    const V3 plane = ((b1 - c * b2) / (1.0 - c * c)) * t1 + ((b2 - c * b1) / (1.0 - c * c)) * t2;
    force = plane - (norm(plane) * tan_a) * rho;
  }
  return push_at(g, p, force, lambda, q, jac, add);
}

}  // namespace

int reaction_width(const Model& model, Index c) {
  const auto [b, i] = model.constraint_block(c);
  return b->states_reaction(i) ? b->reaction_width() : 0;
}

void JointReactions::add_site(const Model& model, Index c, std::vector<int>& site_of) {
  const auto [b, i] = model.constraint_block(c);
  const ConstraintInfo& info = model.constraints()[static_cast<std::size_t>(c)];
  if (!b->states_reaction(i))
    throw Error("constraint '" + info.name + "' (" + std::string(info.kind) +
                ") states no joint point: it has no reaction to write (joints between bodies have one)");
  Site s;
  s.block = b, s.index = i;
  s.spatial = b->reaction_width() == 6;
  s.first_row = info.first_row, s.rows = static_cast<int>(info.rows);
  set_->size += b->reaction_width();
  site_of[static_cast<std::size_t>(c)] = static_cast<int>(set_->sites.size());
  set_->order.push_back({false, set_->sites.size()});
  set_->sites.push_back(std::move(s));
}

void JointReactions::find_columns(const Model& model, const std::vector<int>& site_of) {
  // the coordinates each constraint reads, in one pass over Φq's pattern
  const CscPattern& p = model.jacobian_pattern();
  for (Index j = 0; j < p.cols; ++j)
    for (Index k = p.col_ptr[static_cast<std::size_t>(j)]; k < p.col_ptr[static_cast<std::size_t>(j) + 1]; ++k) {
      const int s = site_of[static_cast<std::size_t>(model.constraint_of_row(p.row_idx[static_cast<std::size_t>(k)]))];
      if (s >= 0 && (set_->sites[static_cast<std::size_t>(s)].columns.empty() ||
                     set_->sites[static_cast<std::size_t>(s)].columns.back() != j))
        set_->sites[static_cast<std::size_t>(s)].columns.push_back(j);
    }
}

JointReactions::JointReactions(const Model& model, std::vector<Index> constraints)
    : g_(static_cast<std::size_t>(model.num_coordinates()), 0.0) {
  std::vector<int> site_of(model.constraints().size(), -1);
  for (Index c : constraints) add_site(model, c, site_of);
  find_columns(model, site_of);
}

JointReactions::JointReactions(const Model& model, const OutputEfforts& efforts, bool rigid_bars)
    : g_(static_cast<std::size_t>(model.num_coordinates()), 0.0) {
  set_->joint_axes = efforts.reactions_in_joint_axes, set_->rigid_bars = rigid_bars;
  std::vector<int> site_of(model.constraints().size(), -1);
  set_->order.reserve(efforts.reactions.size());  // (not grown by doubling: 10⁴ sites at nfourbar 10⁴)
  set_->natural_sites.reserve(efforts.natural ? efforts.reactions.size() : 0);
  for (const OutputReaction& r : efforts.reactions) {
    if (r.natural < 0) {
      add_site(model, r.constraint, site_of);
      continue;
    }
    if (!efforts.natural || static_cast<std::size_t>(r.natural) >= efforts.natural->joints.size())
      throw Error("JointReactions: natural joint " + std::to_string(r.natural) + " is not one of the efforts'");
    NaturalSite s;
    s.joint = static_cast<std::size_t>(r.natural);
    const NaturalJoint& j = efforts.natural->joints[s.joint];
    if (j.bodies.empty()) throw Error("JointReactions: natural joint '" + j.name + "' has no body");
    s.body = j.bodies[0];
    const NaturalBody& body = efforts.natural->bodies[s.body];
    // the joint among the body's points: the one whose coordinate components are the joint's
    s.point = body.points.size();
    for (std::size_t k = 0; k < body.points.size() && s.point == body.points.size(); ++k) {
      bool same = true;
      for (int d = 0; d < (efforts.natural->spatial ? 3 : 2); ++d)
        if (j.point.r[d].is_coordinate())
          same = same && body.points[k].r[d] == j.point.r[d];
        else
          same = same && body.points[k].r[d].coord() >= model.num_coordinates();
      if (same) s.point = k;
    }
    if (s.point == body.points.size())
      throw Error("JointReactions: natural joint '" + j.name + "' is not a point of '" + body.name + "'");
    for (int d = 0; d < (efforts.natural->spatial ? 3 : 2); ++d) s.at[d] = body.points[s.point].r[d].coord();
    set_->size += efforts.natural->spatial ? 6 : 3;
    set_->order.push_back({true, set_->natural_sites.size()});
    set_->natural_sites.push_back(s);
  }
  find_columns(model, site_of);
  if (!set_->natural_sites.empty()) add_natural(model, efforts, rigid_bars);
}

JointReactions::JointReactions(const JointReactions& other, SetUpOnly)
    : set_(other.set_), g_(other.g_.size(), 0.0), own_values_(other.own_values_.size(), 0.0) {
  if (!set_->natural_sites.empty()) size_natural_scratch();
}

void JointReactions::evaluate(const double* q, double t, const Eigen::VectorXd& lambda, double* out,
                              const Along* along) {
  if (!set_->natural_sites.empty())
    throw Error("JointReactions::evaluate: natural joints read q̇ and q̈: give them (phiq bug)");
  for (std::size_t k = 0; k < set_->sites.size(); ++k)
    evaluate_site(set_->sites[k], q, t, lambda, out, along && !along->sites.empty() ? along->sites[k] : BlockAt{});
}

void JointReactions::evaluate(const double* q, const double* qd, const double* qdd, double t,
                              const Eigen::VectorXd& lambda, double* out, const detail::PlanarForce* planar,
                              bool sum_bars, const Along* along) {
  RowMotion row{q, qd, qdd, false};
  evaluate_own_jacobian(q, t, along);
  const bool simple = planar && !set_->joint_axes;  // (NaturalSite::simple's sums are in world axes)
  const SimpleSite* const simple_sites = set_->simple_sites.data();
  const std::size_t simple_count = set_->simple_sites.size();
  const BarSum* const bar_sums = set_->bar_sums.data();
  for (const auto& [natural, k] : set_->order) {
    if (!natural) {
      evaluate_site(set_->sites[k], q, t, lambda, out, along && !along->sites.empty() ? along->sites[k] : BlockAt{});
      continue;
    }
    const SimpleSite* e = simple && k < simple_count ? simple_sites + k : nullptr;
    // evaluate_flat()'s sums, each of one term, written out, with the value Q_b of field(c)
    auto write = [&](auto&& field) {
      for (int c = 0; c < 2; ++c) {
        const double v = field(c);
        double qb = 0.0, sum = 0.0;
        qb += (e->term[c] & 8) ? -v : v;
        sum += own_values_[e->slot[c]] * lambda(e->row[c]);
        out[c] = sum - qb;
      }
      out[2] = 0.0;
      out += 3;
    };
    if (e && e->bar && sum_bars && qdd) {  // a rigid bar's field summed here (SimpleSite): the same bits
      const BarSum& f = bar_sums[e->form];
      write([&](int c) {
        return f.weight[c] -
               ((f.m[c][0] * qdd[e->a[c][0]] + f.m[c][1] * qdd[e->a[c][1]]) + f.m[c][2] * qdd[e->a[c][2]]);
      });
      continue;
    }
    if (e && e->simple && planar[e->part].valid) {  // read off the part's PlanarForce
      write([&](int c) { return planar[e->part].*detail::kPlanarFields[e->term[c] & 7]; });
      continue;
    }
    evaluate_natural(set_->natural_sites[k], row, t, lambda, planar, out);
  }
}

void JointReactions::site_geometry(const Site& s, const double* q, double t, SiteGeometry& g, BlockAt at) const {
  if (at.block)
    at.block->reaction_site(at.index, q, g.site);
  else
    s.block->reaction_site(s.index, q, g.site);
  // The wrench (F, M_O) whose virtual work on the body is g there: J_bᵀ w = g over the body's coordinates, in
  // least squares (Euler parameters: 4 columns for 3 rotations, the fourth along e, on which no wrench works).
  const PartFrame frame = body_frame(g.site);
  part_jacobian(frame, q, t, g.jac);
  Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
  for (std::size_t k = 0; k < g.jac.coordinates.size(); ++k) {
    const V3 o = g.jac.d_origin[k], a = g.jac.d_angle[k];
    const Eigen::Matrix<double, 6, 1> col(o.x, o.y, o.z, a.x, a.y, a.z);
    normal += col * col.transpose();
  }
  // Directions no coordinate moves (a planar body's z, a natural point's rotation) get no component: their rows
  // of the normal equations are zero, set to w_i = 0 (fixed sizes: no allocation at a row).
  for (int i = 0; i < 6; ++i)
    if ((g.unmoved[i] = normal(i, i) == 0.0)) normal(i, i) = 1.0;
  g.identity = normal == Eigen::Matrix<double, 6, 6>::Identity();
  if (!g.identity) g.normal.compute(normal);
  g.origin = frame.kind == PartFrameKind::kPlanarBody  // (its origin alone: no rotation to find)
                 ? V3{frame.planar.x.of(q), frame.planar.y.of(q), 0.0}
                 : part_pose(frame, q, t).at;
}

void JointReactions::site_reaction(const Site& s, const SiteGeometry& g, const double* q, double t,
                                   const Eigen::VectorXd& lambda, double*& out, BlockAt at) {
  if (at.block)
    at.block->add_transposed_product(at.index, q, t, lambda.data(), g_.data());
  else
    s.block->add_transposed_product(s.index, q, t, lambda.data(), g_.data());  // Φq,cᵀ λ_c
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t k = 0; k < g.jac.coordinates.size(); ++k) {
    const V3 o = g.jac.d_origin[k], a = g.jac.d_angle[k];
    const Eigen::Matrix<double, 6, 1> col(o.x, o.y, o.z, a.x, a.y, a.z);
    rhs -= col * g_[static_cast<std::size_t>(g.jac.coordinates[k])];  // g = −Φq,cᵀ λ_c
  }
  for (int i = 0; i < 6; ++i)
    if (g.unmoved[i]) rhs(i) = 0.0;
  const Eigen::Matrix<double, 6, 1> w = g.identity ? rhs : Eigen::Matrix<double, 6, 1>(g.normal.solve(rhs));
  V3 force{w(0), w(1), w(2)};
  const V3 moment_o{w(3), w(4), w(5)};
  const ReactionSite& rs = g.site;
  V3 moment = moment_o + cross(g.origin - rs.point, force);
  if (set_->joint_axes) {  // the same force and moment, their components along the joint's own axes
    const V3 f = force, m = moment;
    force = {dot(rs.axes[0], f), dot(rs.axes[1], f), dot(rs.axes[2], f)};
    moment = {dot(rs.axes[0], m), dot(rs.axes[1], m), dot(rs.axes[2], m)};
  }
  if (s.spatial) {
    for (double v : {force.x, force.y, force.z, moment.x, moment.y, moment.z}) *out++ = v;
  } else {
    for (double v : {force.x, force.y, moment.z}) *out++ = v;
  }
  for (Index j : s.columns) g_[static_cast<std::size_t>(j)] = 0.0;
}

void JointReactions::evaluate_site(const Site& s, const double* q, double t, const Eigen::VectorXd& lambda,
                                   double*& out, BlockAt at) {
  site_geometry(s, q, t, geometry_, at);
  site_reaction(s, geometry_, q, t, lambda, out, at);
}

void JointReactions::keep_geometry(const double* q, double t) {
  if (!set_->natural_sites.empty())
    throw Error("JointReactions::keep_geometry: natural joints read q̇ and q̈: give them (phiq bug)");
  kept_.resize(set_->sites.size());
  Index rows = 0;
  for (const Site& s : set_->sites) rows = std::max(rows, s.first_row + s.rows);
  if (unit_.size() < rows) unit_.setZero(rows);
  for (std::size_t k = 0; k < set_->sites.size(); ++k) {
    const Site& s = set_->sites[k];
    SiteGeometry& g = kept_[k];
    site_geometry(s, q, t, g);
    if (s.rows > 6) throw Error("JointReactions::keep_geometry: a joint of more than 6 rows (phiq bug)");
    g.per_row.resize(6, s.rows);
    for (int j = 0; j < s.rows; ++j) {
      double values[6], *out = values;
      unit_(s.first_row + j) = 1.0;
      site_reaction(s, g, q, t, unit_, out);
      unit_(s.first_row + j) = 0.0;
      for (int v = 0; v < 6; ++v) g.per_row(v, j) = v < out - values ? values[v] : 0.0;
    }
  }
}

void JointReactions::evaluate_kept(const double* q, double t, const Eigen::VectorXd& lambda, double* out) {
  (void)q, (void)t;  // (the geometry's: keep_geometry()'s)
  if (kept_.size() != set_->sites.size())
    throw Error("JointReactions::evaluate_kept: no geometry kept (keep_geometry() first; phiq bug)");
  for (std::size_t k = 0; k < set_->sites.size(); ++k) {
    const Site& s = set_->sites[k];
    const SiteGeometry& g = kept_[k];
    const int width = s.spatial ? 6 : 3;
    for (int v = 0; v < width; ++v) {
      double sum = 0.0;
      for (int j = 0; j < s.rows; ++j) sum += g.per_row(v, j) * lambda(s.first_row + j);
      *out++ = sum;
    }
  }
}

void add_gear_mesh_forces(const Model& model, const std::vector<OutputMesh>& meshes, const double* q,
                          const Eigen::VectorXd& lambda, Eigen::VectorXd& dq, const double* qd, MeshFindings* found,
                          PartJacobian* scratch) {
  double power = 0.0, size = 0.0;  // a mesh's push's power along q̇, and the size of its terms
  auto add_at = [&](Index j, double v) {
    dq(j) += v;
    if (qd) power += v * qd[j], size += std::fabs(v * qd[j]);
  };
  auto add = [&](const Slot& s, double v) {
    if (s.is_coordinate()) add_at(s.coord(), v);
  };
  PartJacobian own;  // (spatial pairs only; empty, allocating nothing, unless a pair pushes without `scratch`)
  PartJacobian& jac = scratch ? *scratch : own;
  // a force on a member's centre; none on a fixed gear's (its frame is its carrier's: OutputMesh::fixed)
  auto add_to = [&](const OutputMesh& m, int member, double fx, double fy) {
    if (m.fixed == member) return;
    const Frame2& b = member == 0 ? m.first : m.second;
    add(b.x, fx), add(b.y, fy);
  };
  // A belt's strands along u∓ = c e ∓ s n (n = ẑ × e, s = (r1 ∓ r2)/d open or crossed, c = √(1 − s²)) leave
  // pulley 1 on its +n and −n sides; their tensions T∓ turn it by r1 (T₋ − T₊) = −λ, the row's torque on it, and
  // pull its centre by T₊ u₊ + T₋ u₋, pulley 2's by the opposite.
  auto pull = [&](const OutputMesh& m, double lambda_m, double ex, double ey, double d) {
    const GearMesh& b = m.mesh;
    const double s = (b.crossed ? b.r1 + b.r2 : b.r1 - b.r2) / d;
    if (!(std::fabs(s) < 1.0)) return;  // (overlapping pulleys: no strands)
    const double c = std::sqrt(1.0 - s * s), nx = -ey, ny = ex;
    const double difference = -lambda_m / b.r1;  // T₋ − T₊
    double upper = b.tension - 0.5 * difference, lower = b.tension + 0.5 * difference;
    if (b.chain)
      upper = b.tension + std::max(-difference, 0.0), lower = b.tension + std::max(difference, 0.0);
    else if (found && std::min(upper, lower) < 0.0)
      found->slack.push_back(m.constraint);
    const double fx = upper * (c * ex - s * nx) + lower * (c * ex + s * nx);
    const double fy = upper * (c * ey - s * ny) + lower * (c * ey + s * ny);
    add_to(m, 0, fx, fy), add_to(m, 1, -fx, -fy);
  };
  auto push = [&](const OutputMesh& m) {
    if (!m.unloaded.empty()) return;
    const Index row = model.constraints()[static_cast<std::size_t>(m.constraint)].first_row;
    const double lambda_m = lambda(row);
    if (m.spatial) {
      if (const char* why = push_shafts(*m.spatial, lambda(row + 2), q, jac, add_at); why && found)
        found->unplaced.push_back({m.constraint, why});
      return;
    }
    if (m.mesh.rack) {
      // the rack pushed by F = −λ e + s n at the pitch point P = c_p + k n (n = ẑ × e; its travel took −λ, and the
      // teeth part them by s = sign(k) |λ| tan α, away from the pinion's centre), the pinion by −F there (its angle
      // took −λ k, the moment of λ e about its centre): −F on the pinion's centre, s n on the rack across its travel,
      // and the moment of F about the rack's reference point on its angle
      const double ex = m.rack_axis == 0 ? 1.0 : 0.0, ey = 1.0 - ex, nx = -ey, ny = ex;
      const double px = m.second.x.of(q) - m.mesh.k * ey, py = m.second.y.of(q) + m.mesh.k * ex;
      const double apart = std::copysign(std::fabs(lambda_m) * std::tan(m.mesh.pressure_angle), m.mesh.k);
      const double fx = -lambda_m * ex + apart * nx, fy = -lambda_m * ey + apart * ny;  // on the rack at P
      add(m.second.x, -fx), add(m.second.y, -fy);
      add(m.first.x, apart * nx), add(m.first.y, apart * ny);  // (its travel took the rest)
      add(m.first.psi, (px - m.first.x.of(q)) * fy - (py - m.first.y.of(q)) * fx);
      return;
    }
    const double dx = m.second.x.of(q) - m.first.x.of(q), dy = m.second.y.of(q) - m.first.y.of(q);
    const double d = std::hypot(dx, dy);
    if (!(d > 0.0)) return;
    if (m.mesh.belt) return pull(m, lambda_m, dx / d, dy / d, d);
    const double f = -lambda_m * (1.0 + m.mesh.k) / d;
    // across the line of centres e they part the gears by |f| tan α: gear 1 toward its centre, away from its
    // pitch point (−e external; +e internal, k < 0, where it meshes on the side away from the ring's centre)
    const double apart = std::copysign(std::fabs(f) * std::tan(m.mesh.pressure_angle), -m.mesh.k);
    const double ex = dx / d, ey = dy / d, tx = -ey, ty = ex;
    add_to(m, 0, f * tx + apart * ex, f * ty + apart * ey);
    add_to(m, 1, -f * tx - apart * ex, -f * ty - apart * ey);
    add(m.mesh.carrier, f * d);
  };
  for (const OutputMesh& m : meshes) {
    power = size = 0.0;
    push(m);
    if (found && qd && !(std::fabs(power) <= 1e-6 * size)) found->working.push_back(m.constraint);
  }
}

bool detail::minimum_norm_multipliers(const Model& model, SparseLuNumeric& lu, const double* q, double t,
                                      Eigen::VectorXd& lambda, std::vector<Index>* indeterminate,
                                      MinimumNormScratch& sc) {
  const std::vector<Index>& dropped = model.dropped_rows();
  const std::vector<Index>& kept = model.solve_rows();
  if (dropped.empty()) return true;
  const Index m = model.num_equations(), n = model.num_coordinates();
  Eigen::MatrixXd& N = sc.directions;
  N.setZero(m, static_cast<Index>(dropped.size()));
  sc.unit.setZero(m);
  sc.gradient.resize(n), sc.alpha.resize(static_cast<Index>(kept.size()));
  for (std::size_t d = 0; d < dropped.size(); ++d) {
    const Index r = dropped[d];
    const auto [b, i] = model.constraint_block(model.constraint_of_row(r));
    sc.gradient.setZero();
    sc.unit(r) = 1.0;
    b->add_transposed_product(i, q, t, sc.unit.data(), sc.gradient.data());  // ∇Φ_r
    sc.unit(r) = 0.0;
    if (!lu.solve_transposed(sc.gradient.data(), sc.alpha.data())) return false;  // Φq,keptᵀ α = ∇Φ_r
    N(r, static_cast<Index>(d)) = 1.0;
    for (std::size_t k = 0; k < kept.size(); ++k) N(kept[k], static_cast<Index>(d)) = -sc.alpha(static_cast<Index>(k));
  }
  // λ − N (NᵀN)⁻¹ Nᵀ λ: the component of λ orthogonal to every direction it may move along
  sc.qr.compute(N);
  sc.step = sc.qr.solve(lambda);
  lambda -= N * sc.step;
  if (indeterminate) {
    const double big = N.cwiseAbs().maxCoeff();
    std::vector<bool> seen(model.constraints().size(), false);
    for (Index r = 0; r < m; ++r)
      if (N.row(r).cwiseAbs().maxCoeff() > 1e-9 * big)
        seen[static_cast<std::size_t>(model.constraint_of_row(r))] = true;
    for (std::size_t c = 0; c < seen.size(); ++c)
      if (seen[c]) indeterminate->push_back(static_cast<Index>(c));
  }
  return true;
}

bool minimum_norm_multipliers(const Model& model, SparseLuNumeric& lu, const double* q, double t,
                              Eigen::VectorXd& lambda, std::vector<Index>* indeterminate) {
  detail::MinimumNormScratch scratch;
  return detail::minimum_norm_multipliers(model, lu, q, t, lambda, indeterminate, scratch);
}

}  // namespace phiq
