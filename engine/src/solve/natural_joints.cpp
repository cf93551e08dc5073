// find_natural_joints() (phiq/natural_joints.hpp): the bodies of natural coordinates, the points they share, and
// their parts and loads with each constant point component made a coordinate of its own.
#include "phiq/natural_joints.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <limits>

#include "phiq/constraint_block.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/joint_reactions.hpp"

namespace phiq {

namespace {

// The frame's points: the origin, and x and y toward when they are points (a vector has no place to act).
std::vector<Attachment3*> frame_points(PartFrame& f) {
  std::vector<Attachment3*> out{&f.origin};
  if (f.x_is_point) out.push_back(&f.x_toward);
  if (f.spatial_frame && f.y_is_point) out.push_back(&f.y_toward);
  return out;
}

// A point's slots as a key: per component whether it is a coordinate, and its index or value.
std::array<double, 6> point_key(const Attachment3& a) {
  std::array<double, 6> k{};
  for (int i = 0; i < 3; ++i)
    k[2 * i] = a.r[i].is_coordinate() ? 1.0 : 0.0,
          k[2 * i + 1] = a.r[i].is_coordinate() ? static_cast<double>(a.r[i].coord()) : a.r[i].value();
  return k;
}

bool moves(const PartFrame& f) {
  std::vector<Index> c;
  frame_coordinates(f, c);
  return !c.empty();
}

}  // namespace

NaturalJoints find_natural_joints(const std::vector<Part>& parts, const Loads& loads,
                                  const std::vector<std::pair<std::string, Attachment3>>& points, Index coordinates,
                                  bool spatial) {
  NaturalJoints out;
  out.spatial = spatial;
  const int dimension = spatial ? 3 : 2;
  for (const Part& p : parts) {
    if (p.frame.kind != PartFrameKind::kPoints || !moves(p.frame)) continue;
    NaturalBody b;
    b.name = p.name;
    b.frame = p.frame;
    PartFrame promoted = p.frame;
    // each constant component of a point a coordinate of its own, past the model's (its value in `promoted`)
    for (Attachment3* a : frame_points(promoted)) {
      for (int k = 0; k < dimension; ++k)
        if (!a->r[k].is_coordinate()) {
          const double v = a->r[k].value();
          a->r[k] = Slot::coordinate(coordinates + static_cast<Index>(out.promoted.size()));
          out.promoted.push_back(v);
        }
      b.points.push_back(*a);
    }
    if (p.mass_source != MassSource::kNone && p.mass.mass > 0.0) {
      b.parts.push_back(p);
      b.parts.back().shapes.clear();
      b.parts.back().frame = promoted;
    }
    b.loads.gravity = loads.gravity;
    if (loads.applied) {
      auto own = std::make_shared<AppliedLoads>();
      for (const AppliedForce& f : loads.applied->forces)
        if (f.part == p.name) own->forces.push_back(f), own->forces.back().frame = promoted;
      for (const AppliedTorque& f : loads.applied->torques)
        if (f.part == p.name) own->torques.push_back(f), own->torques.back().frame = promoted;
      for (const LinearSpring& s : loads.applied->springs) {
        const bool a = s.a.part == p.name, c = s.b.part == p.name;
        const bool other_fixed = (a && (c || s.b.part == "ground")) || (c && s.a.part == "ground");
        if (!other_fixed) continue;  // a spring to another body: counted in the joints' reactions
        own->springs.push_back(s);
        if (a) own->springs.back().a.frame = promoted;
        if (c) own->springs.back().b.frame = promoted;
      }
      if (!own->empty()) b.loads.applied = std::move(own);
    }
    out.bodies.push_back(std::move(b));
  }
  std::map<std::array<double, 6>, std::vector<std::size_t>> held_by;  // a frame's point → its bodies, in order
  for (std::size_t b = 0; b < out.bodies.size(); ++b) {
    PartFrame f = out.bodies[b].frame;
    for (Attachment3* a : frame_points(f)) {
      std::vector<std::size_t>& bodies = held_by[point_key(*a)];
      if (bodies.empty() || bodies.back() != b) bodies.push_back(b);
    }
  }
  for (const auto& [name, point] : points) {
    const auto it = held_by.find(point_key(point));
    if (it == held_by.end()) continue;
    NaturalJoint j;
    j.name = name, j.point = point, j.bodies = it->second;
    bool held = false;  // by ground, in a component
    for (int k = 0; k < dimension; ++k) held = held || !point.r[k].is_coordinate();
    if (j.bodies.size() >= 2 || (j.bodies.size() == 1 && held)) out.joints.push_back(std::move(j));
  }
  return out;
}

void JointReactions::add_natural(const Model& model, const OutputEfforts& efforts) {
  natural_ = efforts.natural;
  const Index n = model.num_coordinates(), extra = static_cast<Index>(natural_->promoted.size());
  qx_.setZero(n + extra), qdx_.setZero(n + extra), qddx_.setZero(n + extra), qb_.setZero(n + extra);
  for (Index k = 0; k < extra; ++k) qx_(n + k) = natural_->promoted[static_cast<std::size_t>(k)];
  // each body's point coordinates (the model's), and which coordinates are a point's at all
  const std::size_t nb = natural_->bodies.size();
  std::vector<std::vector<Index>> coords(nb);
  std::vector<bool> of_point(static_cast<std::size_t>(n), false);
  body_rows_.assign(nb, {});
  for (std::size_t b = 0; b < nb; ++b) {
    const NaturalBody& body = natural_->bodies[b];
    std::vector<Index>& q_columns = body_rows_[b].q_columns;
    frame_coordinates(body.frame, q_columns);
    for (const Attachment3& p : body.points)
      for (const Slot& r : p.r)
        if (r.is_coordinate()) {
          q_columns.push_back(r.coord());
          if (r.coord() < n) coords[b].push_back(r.coord()), of_point[static_cast<std::size_t>(r.coord())] = true;
        }
    std::sort(coords[b].begin(), coords[b].end());
  }
  // the point coordinates each constraint reads
  std::vector<std::vector<Index>> reads(model.constraints().size()), all(model.constraints().size());
  const CscPattern& pat = model.jacobian_pattern();
  for (Index j = 0; j < pat.cols; ++j)
    for (Index k = pat.col_ptr[static_cast<std::size_t>(j)]; k < pat.col_ptr[static_cast<std::size_t>(j) + 1]; ++k) {
      const auto c = static_cast<std::size_t>(model.constraint_of_row(pat.row_idx[static_cast<std::size_t>(k)]));
      if (all[c].empty() || all[c].back() != j) {
        all[c].push_back(j);
        if (of_point[static_cast<std::size_t>(j)]) reads[c].push_back(j);
      }
    }
  // a constraint is the body's whose points hold all the point coordinates it reads, the fewest of them: among
  // the bodies that hold its first
  std::vector<std::vector<std::size_t>> bodies_of(static_cast<std::size_t>(n));
  for (std::size_t b = 0; b < nb; ++b)
    for (Index c : coords[b]) bodies_of[static_cast<std::size_t>(c)].push_back(b);
  for (std::size_t c = 0; c < reads.size(); ++c) {
    if (reads[c].empty()) continue;
    std::size_t best = nb, best_size = 0;
    bool tie = false;
    for (std::size_t b : bodies_of[static_cast<std::size_t>(reads[c].front())]) {
      if (!std::includes(coords[b].begin(), coords[b].end(), reads[c].begin(), reads[c].end())) continue;
      if (best == nb || coords[b].size() < best_size)
        best = b, best_size = coords[b].size(), tie = false;
      else if (coords[b].size() == best_size)
        tie = true;
    }
    if (best == nb || tie) continue;  // the joints' own: acts at the points bodies share
    body_rows_[best].constraints.push_back(model.constraint_block(static_cast<Index>(c)));
    body_rows_[best].g_columns.insert(body_rows_[best].g_columns.end(), all[c].begin(), all[c].end());
  }
}

void JointReactions::evaluate_natural(const NaturalSite& s, double t, const Eigen::VectorXd& lambda, double*& out) {
  const NaturalBody& body = natural_->bodies[s.body];
  const BodyRows& rows = body_rows_[s.body];
  const Index n = static_cast<Index>(g_.size());
  for (const auto& [block, i] : rows.constraints)
    block->add_transposed_product(i, qx_.data(), t, lambda.data(), g_.data());
  add_generalized_forces(body.parts, body.loads, qx_.data(), qdx_.data(), qddx_.data(), t, qb_);
  const Attachment3& p = body.points[s.point];
  double force[3] = {0.0, 0.0, 0.0};
  for (int k = 0; k < (natural_->spatial ? 3 : 2); ++k) {
    const Index at = p.r[k].coord();
    if (at < n) {  // R = Σ_c (Φq,cᵀ λ_c)(P) − Q_b(P)
      force[k] = g_[static_cast<std::size_t>(at)] - qb_(at);
      continue;
    }
    // a constant component: ∂Φ_c/∂P_k = −Σ over the body's moving points' k-components (translation invariance)
    double moving = 0.0;
    bool shared = false;  // another point of the body constant along k: the load's split between them is open
    for (const Attachment3& o : body.points) {
      const Index c = o.r[k].coord();
      if (c < n)
        moving += g_[static_cast<std::size_t>(c)];
      else if (&o != &p)
        shared = true;
    }
    force[k] = shared ? std::numeric_limits<double>::quiet_NaN() : -moving - qb_(at);
  }
  if (natural_->spatial) {
    for (double v : {force[0], force[1], force[2], 0.0, 0.0, 0.0}) *out++ = v;
  } else {
    for (double v : {force[0], force[1], 0.0}) *out++ = v;
  }
  for (Index j : rows.g_columns) g_[static_cast<std::size_t>(j)] = 0.0;
  for (Index j : rows.q_columns) qb_(j) = 0.0;
}

}  // namespace phiq
