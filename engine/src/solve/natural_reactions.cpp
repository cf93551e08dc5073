// JointReactions at natural coordinates' joints (phiq/natural_joints.hpp): each body's parts and own constraints'
// entries found once at set-up, and at every row a joint's force from its body's balance at the point.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "phiq/constraint_block.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/joint_reactions.hpp"
#include "phiq/natural_joints.hpp"
#include "phiq/part_motion.hpp"
#include "solve/part_forces.hpp"

namespace phiq {

namespace {

// Counts turned into the offsets of a flat list: first[k] = Σ count[< k] (count sits at first[1 …]).
void counts_to_offsets(std::vector<std::size_t>& first) {
  for (std::size_t k = 1; k < first.size(); ++k) first[k] += first[k - 1];
}

bool same_bits(double a, double b) { return a == b && std::signbit(a) == std::signbit(b); }

// Whether `own` (a natural body's part, its constant components promoted to coordinates n + k of value
// promoted[k]) has the force of `whole` (the same part as the whole model's Q takes it), bit for bit: the same
// mass, centre and inertia, and frames whose slots are the same or a constant and its promoted copy, which
// planar_motion() reads alike (the value from q; rate and acceleration 0, as JointReactions' q̇, q̈ hold there).
bool same_planar_force(const detail::MassivePart& whole, const detail::MassivePart& own,
                       const std::vector<double>& promoted, Index n) {
  if (!whole.planar || !own.planar || whole.frame.body != own.frame.body ||
      whole.frame.x_is_point != own.frame.x_is_point || whole.frame.bar != own.frame.bar)
    return false;
  if (!same_bits(whole.mass, own.mass) || !same_bits(whole.cx, own.cx) || !same_bits(whole.cy, own.cy) ||
      !same_bits(whole.izz, own.izz))
    return false;
  for (int k = 0; k < 5; ++k) {
    const Slot a = whole.frame.slots[k], b = own.frame.slots[k];
    if (a == b) continue;
    if (a.is_coordinate() || !b.is_coordinate() || b.coord() < n ||
        b.coord() - n >= static_cast<Index>(promoted.size()) ||
        !same_bits(a.value(), promoted[static_cast<std::size_t>(b.coord() - n)]))
      return false;
  }
  return true;
}

}  // namespace

void JointReactions::find_body_parts(const Model& model, const OutputEfforts& efforts, const detail::BarLengths& bars,
                                     std::vector<BarForm>& forms) {
  const std::vector<NaturalBody>& bodies = set_->natural->bodies;
  set_->body_parts.assign(bodies.size(), {});
  forms.assign(bodies.size(), {});
  if (!efforts.parts || !efforts.loads) return;
  const std::vector<Part>& parts = *efforts.parts;
  const kin3::V3 g = efforts.loads->gravity;
  // A body's part among the efforts' parts: at its own index when they are the parts it was found among, else by
  // name (a scene's efforts keep the parts with mass only: a massless part before it shifts every index).
  std::unordered_map<std::string_view, std::size_t> by_name;
  std::vector<Part> own_parts;  // a body's (natural_body_parts(): its storage reused)
  auto part_of = [&](const NaturalBody& body) {
    if (body.part < parts.size() && parts[body.part].name == body.name) return body.part;
    if (by_name.empty())
      for (std::size_t i = 0; i < parts.size(); ++i) by_name.emplace(parts[i].name, i);
    const auto it = by_name.find(body.name);
    return it == by_name.end() ? BodyPart::kNone : it->second;
  };
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    const NaturalBody& body = bodies[b];
    const kin3::V3 own_g = body.loads.gravity;
    const double bar = bars.of(body.frame);  // (its frame before promotion: the model's slots)
    set_->body_parts[b].bar_length = bar;
    const std::size_t index = part_of(body);
    natural_body_parts(body, own_parts);
    if (own_parts.size() != 1 || index == BodyPart::kNone || !detail::has_mass(own_parts[0]) ||
        !detail::has_mass(parts[index]) || !same_bits(g.x, own_g.x) || !same_bits(g.y, own_g.y) ||
        !same_bits(g.z, own_g.z))
      continue;
    const detail::MassivePart own = detail::massive_part(own_parts[0], 0, bar);
    const detail::MassivePart whole = detail::massive_part(parts[index], index, bars.of(parts[index].frame));
    if (!same_planar_force(whole, own, set_->natural->promoted, model.num_coordinates()) || own.frame.body) continue;
    BodyPart& bp = set_->body_parts[b];
    bp.part = index, bp.x_is_point = own.frame.x_is_point, bp.applied = body.loads.applied.get();
    std::copy(own.frame.slots, own.frame.slots + 5, bp.slots);
    if ((forms[b].bar = whole.frame.bar)) {  // the numbers and weight the whole model's Q takes (PartForces)
      const detail::BarWeight w = detail::bar_weight(whole, g);
      for (int k = 0; k < 4; ++k) forms[b].numbers[k] = detail::bar_number(whole, k);
      for (int f = 0; f < 6; ++f) forms[b].weights[f] = detail::bar_weight_share(w, f);
    }
  }
}

void JointReactions::size_natural_scratch() {
  const Index n = static_cast<Index>(g_.size()), extra = static_cast<Index>(set_->natural->promoted.size());
  qx_.setZero(n + extra), qdx_.setZero(n + extra), qddx_.setZero(n + extra), qb_.setZero(n + extra);
  for (Index k = 0; k < extra; ++k) qx_(n + k) = set_->natural->promoted[static_cast<std::size_t>(k)];
}

void JointReactions::add_natural(const Model& model, const OutputEfforts& efforts, bool rigid_bars) {
  set_->natural = efforts.natural;
  size_natural_scratch();
  const Index n = model.num_coordinates();
  const std::vector<NaturalBody>& bodies = set_->natural->bodies;
  const std::size_t nb = bodies.size(), nc = model.constraints().size();
  BodyRows& rows = set_->body_rows;
  // each body's point coordinates (the model's, sorted: `coords` from coords_first[b]), which coordinates are a
  // point's at all, and the columns the body's forces touch (its frame's coordinates, promoted ones included)
  std::vector<std::size_t> coords_first(nb + 1, 0);
  std::vector<Index> coords;
  std::vector<char> of_point(static_cast<std::size_t>(n), 0);
  rows.q_first.assign(nb + 1, 0);
  rows.q_columns.clear();
  std::vector<Index> frame_columns;  // (its capacity kept from body to body)
  for (std::size_t b = 0; b < nb; ++b) {
    const NaturalBody& body = bodies[b];
    frame_coordinates(body.frame, frame_columns);
    rows.q_columns.insert(rows.q_columns.end(), frame_columns.begin(), frame_columns.end());
    for (const Attachment3& p : body.points)
      for (const Slot& r : p.r)
        if (r.is_coordinate()) {
          rows.q_columns.push_back(r.coord());
          if (r.coord() < n) coords.push_back(r.coord()), of_point[static_cast<std::size_t>(r.coord())] = 1;
        }
    rows.q_columns.insert(rows.q_columns.end(), body.load_slots.begin(), body.load_slots.end());
    std::sort(coords.begin() + static_cast<std::ptrdiff_t>(coords_first[b]), coords.end());
    coords_first[b + 1] = coords.size(), rows.q_first[b + 1] = rows.q_columns.size();
  }
  // the coordinates each constraint reads (`all` from all_first[c]), from Φq's pattern: counted, then filled
  const CscPattern& pat = model.jacobian_pattern();
  std::vector<Index> last(nc), all;
  auto each_read = [&](auto&& visit) {  // visit(c, j) once per constraint c and column j it reads, j increasing
    std::fill(last.begin(), last.end(), Index{-1});
    for (Index j = 0; j < pat.cols; ++j)
      for (Index k = pat.col_ptr[static_cast<std::size_t>(j)]; k < pat.col_ptr[static_cast<std::size_t>(j) + 1]; ++k) {
        const auto c = static_cast<std::size_t>(model.constraint_of_row(pat.row_idx[static_cast<std::size_t>(k)]));
        if (last[c] != j) last[c] = j, visit(c, j);
      }
  };
  std::vector<std::size_t> all_first(nc + 1, 0);
  each_read([&](std::size_t c, Index) { ++all_first[c + 1]; });
  counts_to_offsets(all_first);
  all.resize(all_first[nc]);
  {
    std::vector<std::size_t> next(all_first.begin(), all_first.end() - 1);
    each_read([&](std::size_t c, Index j) { all[next[c]++] = j; });
  }
  // the bodies holding each point coordinate, in body order
  std::vector<std::size_t> bodies_first(static_cast<std::size_t>(n) + 1, 0), bodies_of(coords.size());
  for (Index c : coords) ++bodies_first[static_cast<std::size_t>(c) + 1];
  counts_to_offsets(bodies_first);
  {
    std::vector<std::size_t> next(bodies_first.begin(), bodies_first.end() - 1);
    for (std::size_t b = 0; b < nb; ++b)
      for (std::size_t k = coords_first[b]; k < coords_first[b + 1]; ++k)
        bodies_of[next[static_cast<std::size_t>(coords[k])]++] = b;
  }
  // a constraint is the body's whose points hold all the point coordinates it reads, the fewest of them: among
  // the bodies that hold its first
  std::vector<std::size_t> owner(nc, nb);
  for (std::size_t c = 0; c < nc; ++c) {
    const Index* read = all.data() + all_first[c];
    const Index* read_end = all.data() + all_first[c + 1];
    while (read != read_end && !of_point[static_cast<std::size_t>(*read)]) ++read;
    if (read == read_end) continue;  // no point coordinate
    std::size_t best = nb, best_size = 0;
    bool tie = false;
    const auto first = static_cast<std::size_t>(*read);
    for (std::size_t k = bodies_first[first]; k < bodies_first[first + 1]; ++k) {
      const std::size_t b = bodies_of[k];
      // whether the body's sorted coordinates include every point coordinate the constraint reads
      const Index* held = coords.data() + coords_first[b];
      const Index* held_end = coords.data() + coords_first[b + 1];
      bool includes = true;
      for (const Index* r = read; r != read_end && includes; ++r) {
        if (!of_point[static_cast<std::size_t>(*r)]) continue;
        while (held != held_end && *held < *r) ++held;
        includes = held != held_end && *held == *r;
      }
      if (!includes) continue;
      const std::size_t size = coords_first[b + 1] - coords_first[b];
      if (best == nb || size < best_size)
        best = b, best_size = size, tie = false;
      else if (size == best_size)
        tie = true;
    }
    if (best == nb || tie) continue;  // the joints' own: acts at the points bodies share
    owner[c] = best;
  }
  // the bodies sites report on: their own constraints' Jacobian entries, in the pattern's order (counted, then
  // filled), and those constraints as ranges of one block (the model lists a block's constraints in order)
  std::vector<char> reported(nb, 0);
  for (const NaturalSite& s : set_->natural_sites) reported[s.body] = 1;
  auto each_own_entry = [&](auto&& visit) {  // visit(b, entry)
    for (Index j = 0; j < pat.cols; ++j)
      for (Index k = pat.col_ptr[static_cast<std::size_t>(j)]; k < pat.col_ptr[static_cast<std::size_t>(j) + 1]; ++k) {
        const Index r = pat.row_idx[static_cast<std::size_t>(k)];
        const std::size_t b = owner[static_cast<std::size_t>(model.constraint_of_row(r))];
        if (b != nb && reported[b]) visit(b, OwnEntry{k, r, j});
      }
  };
  rows.entries_first.assign(nb + 1, 0);
  each_own_entry([&](std::size_t b, const OwnEntry&) { ++rows.entries_first[b + 1]; });
  counts_to_offsets(rows.entries_first);
  rows.entries.resize(rows.entries_first[nb]);
  {
    std::vector<std::size_t> next(rows.entries_first.begin(), rows.entries_first.end() - 1);
    each_own_entry([&](std::size_t b, const OwnEntry& e) { rows.entries[next[b]++] = e; });
  }
  rows.runs.clear();
  for (std::size_t c = 0; c < nc; ++c) {
    if (owner[c] == nb || !reported[owner[c]]) continue;
    const auto [block, i] = model.constraint_block(static_cast<Index>(c));
    if (!rows.runs.empty() && rows.runs.back().block == block && rows.runs.back().end == i)
      ++rows.runs.back().end;
    else
      rows.runs.push_back({block, i, i + 1});
  }
  number_own_entries(model);
  // A rigid bar's Q differs from its frame's by a multiple of its own row, which its body's reactions take back only
  // where that row is the body's (not the joints', as when another body holds the same coordinates: a second part
  // on the bar's two points, two bars from fixed points to one point): else no bar takes that form, in Q either
  // (rigid_bars())
  detail::BarLengths bars = rigid_bars ? detail::BarLengths(model) : detail::BarLengths();
  for (std::size_t b = 0; b < nb && rigid_bars; ++b) {
    const detail::BarLengths::Bar* bar = bars.find(bodies[b].frame);
    rigid_bars = !bar || !natural_body_has_mass(bodies[b]) || owner[bar->constraint] == b;
  }
  set_->rigid_bars = rigid_bars;
  if (!rigid_bars) bars = detail::BarLengths();  // (as the sweep's Q, detail::PartForces, then takes them: none)
  std::vector<BarForm> forms;
  find_body_parts(model, efforts, bars, forms);
  find_flat_sites(model, forms);
  // the bodies whose sites a sweep's row takes by the general path keep their parts (the others build them where
  // they are read: a flat site whose part's force Q did not compute)
  set_->body_parts_kept.resize(nb);
  for (const NaturalSite& s : set_->natural_sites)
    if (!s.flat && set_->body_parts_kept[s.body].empty())
      natural_body_parts(bodies[s.body], set_->body_parts_kept[s.body]);
}

std::vector<char> JointReactions::planar_parts_read(std::size_t parts) const {
  std::vector<char> read(parts, 0);
  for (std::size_t k = 0; k < set_->natural_sites.size(); ++k) {
    const NaturalSite& s = set_->natural_sites[k];
    // (a rigid bar's simple site sums its force itself: evaluate() does so without joint axes)
    if (k < set_->simple_sites.size() && set_->simple_sites[k].bar && !set_->joint_axes) continue;
    if (const std::size_t p = set_->body_parts[s.body].part; p < parts) read[p] = 1;
  }
  return read;
}

detail::PlanarFrame JointReactions::BodyPart::frame() const {
  detail::PlanarFrame f;
  std::copy(slots, slots + 5, f.slots);
  f.body = false, f.x_is_point = x_is_point, f.bar = bar_length > 0.0;
  return f;
}

void JointReactions::body_forces(std::size_t b, double t, const detail::PlanarForce* planar) {
  const BodyPart& part = set_->body_parts[b];
  if (planar && part.part != BodyPart::kNone && planar[part.part].valid) {
    // the whole model's Q computed the part's force at this row: added at the promoted frame's slots, as
    // add_generalized_forces() of the body's part adds it
    detail::add_planar_force(part.frame(), planar[part.part], qb_);
    if (part.applied) add_applied_forces(*part.applied, qx_.data(), qdx_.data(), qddx_.data(), t, qb_);
    return;
  }
  const NaturalBody& body = set_->natural->bodies[b];
  const std::vector<Part>* parts = &set_->body_parts_kept[b];
  if (parts->empty() && natural_body_has_mass(body)) natural_body_parts(body, body_part_), parts = &body_part_;
  if (planar && part.bar_length > 0.0 && parts->size() == 1) {
    // a rigid bar whose force the sweep's Q took in its constant mass matrix's form (not found among its parts):
    // the same form, which λ was solved with
    const Part& p = (*parts)[0];
    detail::add_massive_part(p, detail::massive_part(p, 0, part.bar_length), body.loads.gravity, qx_.data(),
                             qdx_.data(), qddx_.data(), t, qb_);
    if (body.loads.applied) add_applied_forces(*body.loads.applied, qx_.data(), qdx_.data(), qddx_.data(), t, qb_);
    return;
  }
  add_generalized_forces(*parts, body.loads, qx_.data(), qdx_.data(), qddx_.data(), t, qb_);
}

void JointReactions::number_own_entries(const Model& model) {
  BodyRows& rows = set_->body_rows;
  const Index nnz = model.jacobian_pattern().nnz();
  std::vector<EntryIndex> own_of_slot(static_cast<std::size_t>(nnz), -1);
  EntryIndex own = 0;
  for (OwnEntry& e : rows.entries) {
    EntryIndex& k = own_of_slot[static_cast<std::size_t>(e.slot)];
    if (k < 0) k = own++;
    e.slot = k;
  }
  const std::vector<EntryIndex>& model_slots = model.slot_of_entry();
  rows.own_slot_of_entry.assign(model_slots.size(), 0);  // (an entry of no own constraint is never evaluated)
  for (std::size_t e = 0; e < model_slots.size(); ++e)
    rows.own_slot_of_entry[e] = std::max(own_of_slot[static_cast<std::size_t>(model_slots[e])], EntryIndex{0});
  rows.slot_of_entry = rows.own_slot_of_entry.data();
  rows.overwrite = static_cast<Index>(model_slots.size()) == nnz;
  own_values_.assign(static_cast<std::size_t>(own), 0.0);
}

void JointReactions::evaluate_own_jacobian(const double* q, double t, const Along* along) {
  const BodyRows& rows = set_->body_rows;
  if (rows.runs.empty()) return;
  if (!rows.overwrite) std::fill(own_values_.begin(), own_values_.end(), 0.0);  // (entries that share a slot add)
  for (const OwnRun& r : rows.runs) {
    if (!along || along->own.empty()) {
      r.block->jacobian(r.begin, r.end, q, t, rows.slot_of_entry, own_values_.data(), rows.overwrite);
      continue;
    }
    for (std::size_t i = r.begin; i < r.end; ++i) {  // (a copy keeps its entries' places in the pattern)
      const auto o = std::find_if(along->own.begin(), along->own.end(),
                                  [&](const Along::Own& x) { return x.block == r.block && x.index == i; });
      const ConstraintBlock& b = o == along->own.end() ? *r.block : *o->at.block;
      const std::size_t at = o == along->own.end() ? i : o->at.index;
      b.jacobian(at, at + 1, q, t, rows.slot_of_entry, own_values_.data(), rows.overwrite);
    }
  }
}

JointReactions::Along JointReactions::along(const std::vector<BlockAt>& listed,
                                            const std::vector<std::pair<Index, BlockAt>>& own,
                                            const Model& model) const {
  Along out;
  for (const auto& [c, at] : own) {
    if (!at.block) continue;
    const auto [block, index] = model.constraint_block(c);
    out.own.push_back({block, index, at});
  }
  if (listed.empty()) return out;
  out.sites.assign(set_->sites.size(), BlockAt{});
  for (std::size_t k = 0; k < listed.size() && k < set_->order.size(); ++k)
    if (!set_->order[k].first) out.sites[set_->order[k].second] = listed[k];
  return out;
}

std::vector<Index> JointReactions::own_constraints(const Model& model) const {
  std::vector<Index> out;
  for (const OwnRun& r : set_->body_rows.runs)
    for (std::size_t i = r.begin; i < r.end; ++i) out.push_back(model.constraint_of_row(r.block->first_row(i)));
  return out;
}

void JointReactions::natural_force_rows(std::size_t k, std::vector<Index>& rows, std::vector<double>& d) const {
  rows.clear(), d.clear();
  const auto [natural, at] = set_->order.at(k);
  if (!natural || set_->natural->spatial)
    throw Error("JointReactions::natural_force_rows: not a planar natural joint (phiq bug)");
  const NaturalSite& s = set_->natural_sites[at];
  const BodyRows& own = set_->body_rows;
  const Index n = static_cast<Index>(g_.size());
  const NaturalBody& body = set_->natural->bodies[s.body];
  // R_k = Σ own entries in column at[k] × λ_row (a moving component), or −Σ those in the body's points' moving
  // k-columns (a fixed one: translation invariance), less Q_b, which λ does not move
  for (std::size_t e = own.entries_first[s.body]; e < own.entries_first[s.body + 1]; ++e) {
    const OwnEntry& entry = own.entries[e];
    double v[2] = {0.0, 0.0};
    for (int c = 0; c < 2; ++c) {
      if (s.at[c] < n) {
        if (entry.column == s.at[c]) v[c] = own_values_[static_cast<std::size_t>(entry.slot)];
        continue;
      }
      for (const Attachment3& p : body.points)
        if (p.r[c].coord() < n && entry.column == p.r[c].coord())
          v[c] -= own_values_[static_cast<std::size_t>(entry.slot)];
    }
    if (v[0] == 0.0 && v[1] == 0.0) continue;
    const auto it = std::find(rows.begin(), rows.end(), entry.row);
    const std::size_t i = static_cast<std::size_t>(it - rows.begin());
    if (it == rows.end()) rows.push_back(entry.row), d.push_back(0.0), d.push_back(0.0);
    d[2 * i] += v[0], d[2 * i + 1] += v[1];
  }
}

void JointReactions::add_body_constraint_forces(std::size_t b, const Eigen::VectorXd& lambda) {
  const BodyRows& rows = set_->body_rows;
  for (std::size_t k = rows.entries_first[b]; k < rows.entries_first[b + 1]; ++k) {
    const OwnEntry& e = rows.entries[k];
    g_[static_cast<std::size_t>(e.column)] += own_values_[static_cast<std::size_t>(e.slot)] * lambda(e.row);
  }
}

void JointReactions::clear_body_constraint_forces(std::size_t b) {
  const BodyRows& rows = set_->body_rows;
  for (std::size_t k = rows.entries_first[b]; k < rows.entries_first[b + 1]; ++k)
    g_[static_cast<std::size_t>(rows.entries[k].column)] = 0.0;
}

ReactionSite natural_reaction_site(const NaturalJoints& joints, std::size_t j, const double* q, double t) {
  const NaturalJoint& joint = joints.joints[j];
  ReactionSite rs;
  rs.point = {joint.point.r[0].of(q), joint.point.r[1].of(q), joint.point.r[2].of(q)};
  const Pose pose = part_pose(joints.bodies[joint.bodies.front()].frame, q, t);
  for (int k = 0; k < 3; ++k) rs.axes[k] = {pose.rotation[k], pose.rotation[3 + k], pose.rotation[6 + k]};
  return rs;
}

// A natural joint's force (world axes) along its body's axes, where the output asks (natural_reaction_site()).
void JointReactions::turn_natural(const NaturalSite& s, const double* q, double t, double* force) const {
  const ReactionSite rs = natural_reaction_site(*set_->natural, s.joint, q, t);
  const kin3::V3 f{force[0], force[1], set_->natural->spatial ? force[2] : 0.0};
  for (int k = 0; k < (set_->natural->spatial ? 3 : 2); ++k) force[k] = kin3::dot(rs.axes[k], f);
}

void JointReactions::evaluate_natural(const NaturalSite& s, RowMotion& row, double t, const Eigen::VectorXd& lambda,
                                      const detail::PlanarForce* planar, double*& out) {
  if (s.flat && evaluate_flat(s, row.q, t, lambda, planar, out)) {
    out += 3;
    return;
  }
  const BodyRows& rows = set_->body_rows;
  const Index n = static_cast<Index>(g_.size());
  if (!row.extended) {
    qx_.head(n) = Eigen::Map<const Eigen::VectorXd>(row.q, n);
    qdx_.head(n) = Eigen::Map<const Eigen::VectorXd>(row.qd, n);
    qddx_.head(n) = Eigen::Map<const Eigen::VectorXd>(row.qdd, n);
    for (const NaturalJoints::Mirror& m : set_->natural->mirrors) {
      const Index at = n + static_cast<Index>(m.slot);
      qx_(at) = row.q[m.coordinate], qdx_(at) = row.qd[m.coordinate], qddx_(at) = row.qdd[m.coordinate];
    }
    for (const NaturalJoints::FarPoint& f : set_->natural->far_points) {
      const PartMotion motion = part_motion(f.frame, row.q, row.qd, row.qdd, t);
      const kin3::V3 p = motion.pose.apply(f.at);
      const auto [v, a] = motion.point(f.at);
      const double values[3][3] = {{p.x, p.y, p.z}, {v.x, v.y, v.z}, {a.x, a.y, a.z}};
      for (int k = 0; k < (set_->natural->spatial ? 3 : 2); ++k) {
        const Index at = n + static_cast<Index>(f.slot) + k;
        qx_(at) = values[0][k], qdx_(at) = values[1][k], qddx_(at) = values[2][k];
      }
    }
    row.extended = true;
  }
  add_body_constraint_forces(s.body, lambda);
  body_forces(s.body, t, planar);
  double force[3] = {0.0, 0.0, 0.0};
  for (int k = 0; k < (set_->natural->spatial ? 3 : 2); ++k) {
    const Index at = s.at[k];
    if (at < n) {  // R = Σ_c (Φq,cᵀ λ_c)(P) − Q_b(P)
      force[k] = g_[static_cast<std::size_t>(at)] - qb_(at);
      continue;
    }
    // a constant component: ∂Φ_c/∂P_k = −Σ over the body's moving points' k-components (translation invariance)
    const NaturalBody& body = set_->natural->bodies[s.body];
    const Attachment3& p = body.points[s.point];
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
  if (set_->joint_axes) turn_natural(s, row.q, t, force);
  if (set_->natural->spatial) {
    for (double v : {force[0], force[1], force[2], 0.0, 0.0, 0.0}) *out++ = v;
  } else {
    for (double v : {force[0], force[1], 0.0}) *out++ = v;
  }
  clear_body_constraint_forces(s.body);
  for (std::size_t k = rows.q_first[s.body]; k < rows.q_first[s.body + 1]; ++k) qb_(rows.q_columns[k]) = 0.0;
}

}  // namespace phiq
