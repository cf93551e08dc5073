// add_generalized_forces() and constraint_multipliers() (phiq/inverse_dynamics.hpp).
#include "phiq/inverse_dynamics.hpp"

#include <algorithm>
#include <bit>
#include <climits>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>

#include "phiq/applied_loads.hpp"
#include "phiq/constraint_block.hpp"
#include "phiq/kinds/distance.hpp"
#include "phiq/kinds/registry.hpp"
#include "phiq/part_motion.hpp"
#include "solve/friction_losses.hpp"
#include "solve/part_forces.hpp"
#include "solve/factorisation.hpp"

namespace phiq {

namespace {

using kin3::V3;

// R I Rᵀ v: the inertia about the centre, turned into world axes, times v.
V3 world_inertia_times(const RotationMatrix& r, const std::array<double, 9>& I, V3 v) {
  const double b[3] = {r[0] * v.x + r[3] * v.y + r[6] * v.z, r[1] * v.x + r[4] * v.y + r[7] * v.z,
                       r[2] * v.x + r[5] * v.y + r[8] * v.z};  // Rᵀ v
  double c[3];
  for (int i = 0; i < 3; ++i) c[i] = I[3 * i] * b[0] + I[3 * i + 1] * b[1] + I[3 * i + 2] * b[2];
  return {r[0] * c[0] + r[1] * c[1] + r[2] * c[2], r[3] * c[0] + r[4] * c[1] + r[5] * c[2],
          r[6] * c[0] + r[7] * c[1] + r[8] * c[2]};
}

// Q_k += ∂r_c/∂q_k · F + ∂θ/∂q_k · M for a planar frame, slot by slot: a body's (x, y, ψ), or an origin point and
// an x direction (θ its angle, ∂θ/∂d = (−d_y, d_x)/|d|²), as part_jacobian()'s closed form has them but without
// gathering the frame's coordinates (what a sweep's efforts spent most of Q's assembly in). `c` is the centre from
// the origin. False for the other frames.
bool add_planar_virtual_work(const PartFrame& f, const double* q, V3 c, V3 force, V3 moment, Eigen::VectorXd& Q) {
  auto add = [&](const Slot& s, double v) {
    if (s.is_coordinate()) Q(s.coord()) += v;
  };
  const double turn = c.x * force.y - c.y * force.x + moment.z;  // (c × F + M)_z, what a change of angle works on
  if (f.kind == PartFrameKind::kPlanarBody) {
    add(f.planar.x, force.x), add(f.planar.y, force.y), add(f.planar.psi, turn);
    return true;
  }
  if (f.kind != PartFrameKind::kPoints || f.spatial_frame) return false;
  const Slot* o = f.origin.r;
  const Slot* x = f.x_toward.r;
  double dx = x[0].of(q), dy = x[1].of(q);
  if (f.x_is_point) dx -= o[0].of(q), dy -= o[1].of(q);
  const double d2 = dx * dx + dy * dy, along_x = -dy / d2 * turn, along_y = dx / d2 * turn;
  add(o[0], force.x), add(o[1], force.y), add(o[2], force.z);
  add(x[0], along_x), add(x[1], along_y);
  if (f.x_is_point) add(o[0], -along_x), add(o[1], -along_y);
  return true;
}

// A rigid bar's force (part_forces.hpp): its weight less its constant mass matrix times q̈, at its two points (its
// origin's z is a constant: fz is the weight's z). Always inlined into PartForces::add(), where nfourbar 10⁴'s
// 2·10⁴ parts take it at every row.
[[gnu::always_inline]] inline void bar_force(const detail::MassivePart& p, const double* qdd, V3 gravity,
                                             detail::PlanarForce& f) {
  auto accel = [&](const Slot& s) { return s.is_coordinate() && qdd ? qdd[s.coord()] : 0.0; };
  const Slot *o = p.frame.slots, *x = o + 3;
  detail::bar_force_at(p, detail::bar_weight(p, gravity), accel(o[0]), accel(o[1]), accel(x[0]), accel(x[1]), f);
}

// The force of a part on a planar frame from the frame's motion in scalars (parts/planar_motion.hpp): what
// part_motion(), PartMotion::point(), the inertia's moment and add_planar_virtual_work() compute, without their
// terms that are products with the zeros of a rotation about z and of ω, α along z. Those terms are ±0 (every factor
// is finite), and a ±0 changes a sum only in the sign of a zero, which Q, summed from +0, never keeps: Q is the same
// to the bit, at a fraction of the cost (a sweep's efforts spent most of their time here, 2·10⁴ parts a row at 10⁴
// loops). False for a direction of zero length: the general path's NaN.
bool planar_part_force(const detail::MassivePart& p, const double* q, const double* qd, const double* qdd, V3 gravity,
                       detail::PlanarForce& f) {
  if (p.frame.bar) {
    bar_force(p, qdd, gravity, f);
    return true;
  }
  detail::PlanarMotion m;
  if (!detail::planar_motion(p.frame, q, qd, qdd, m)) return false;
  const double c = m.cos, sn = m.sin, w = m.omega, a = m.alpha, mass = p.mass;
  // the centre from the origin, as Pose::apply() and the difference round it; its acceleration a + α × r + ω × ω × r
  const double rx = (m.at.x + c * p.cx - sn * p.cy) - m.at.x, ry = (m.at.y + sn * p.cx + c * p.cy) - m.at.y;
  const double acx = (m.acceleration.x - a * ry) - w * (w * rx), acy = (m.acceleration.y + a * rx) - w * (w * ry);
  f.fx = mass * (gravity.x - acx), f.fy = mass * (gravity.y - acy), f.fz = mass * (gravity.z - m.acceleration.z);
  f.turn = (rx * f.fy - ry * f.fx) - p.izz * a;  // (r × F)_z − I_zz α
  if (!p.frame.body) f.along_x = -m.dy / m.d2 * f.turn, f.along_y = m.dx / m.d2 * f.turn;
  f.valid = true;
  return true;
}

// Q of one part with mass from its motion and Jacobian: any frame. Not inlined into add_massive_part(): its stack frame
// and set-up (a PartMotion, a 3×3 rotation) were paid by every part of a sweep's Q, nearly all of them on planar
// frames that never reach it.
[[gnu::noinline]] void add_general_part(const Part& p, V3 gravity, const double* q, const double* qd, const double* qdd,
                                        double t, Eigen::VectorXd& Q) {
  const PartMotion m = part_motion(p.frame, q, qd, qdd, t);
  const V3 c = m.pose.apply(p.mass.center) - m.pose.at;  // the centre from the origin, world axes
  const auto [vc, ac] = m.point(p.mass.center);
  (void)vc;
  // the resultant force at the centre and the moment about it
  const V3 force = p.mass.mass * (gravity - ac);
  const V3 moment = -1.0 * (world_inertia_times(m.pose.rotation, p.mass.inertia, m.alpha) +
                            kin3::cross(m.omega, world_inertia_times(m.pose.rotation, p.mass.inertia, m.omega)));
  if (add_planar_virtual_work(p.frame, q, c, force, moment, Q)) return;
  thread_local PartJacobian j;  // its vectors' capacity kept from row to row
  part_jacobian(p.frame, q, t, j);
  for (std::size_t i = 0; i < j.coordinates.size(); ++i) {
    const V3 dc = j.d_origin[i] + kin3::cross(j.d_angle[i], c);  // ∂r_c/∂q_k
    Q(j.coordinates[i]) += kin3::dot(dc, force) + kin3::dot(j.d_angle[i], moment);
  }
}

}  // namespace

void detail::add_massive_part(const Part& p, const MassivePart& massive, V3 gravity, const double* q, const double* qd,
                              const double* qdd, double t, Eigen::VectorXd& Q, PlanarForce* planar) {
  if (massive.planar) {
    detail::PlanarForce f;
    if (planar_part_force(massive, q, qd, qdd, gravity, f)) {
      detail::add_planar_force(massive.frame, f, Q);
      if (planar) *planar = f;
      return;
    }
    if (planar) planar->valid = false;
  }
  add_general_part(p, gravity, q, qd, qdd, t, Q);
}

detail::MassivePart detail::massive_part(const Part& p, std::size_t index, double bar_length) {
  MassivePart m;
  m.planar = planar_frame(p.frame, m.frame);
  m.mass = p.mass.mass, m.cx = p.mass.center.x, m.cy = p.mass.center.y, m.izz = p.mass.inertia[8];
  m.part = index;
  if (m.planar && !m.frame.body && m.frame.x_is_point && !m.frame.slots[2].is_coordinate() && bar_length > 0.0) {
    const double a = m.cx / bar_length, b = m.cy / bar_length, j = m.izz / (bar_length * bar_length);
    m.frame.bar = true;
    m.m_o = m.mass * (1.0 - a), m.m_x = m.mass * a, m.m_b = m.mass * b;
    m.oo = m.mass * ((1.0 - a) * (1.0 - a) + b * b) + j;
    m.xx = m.mass * (a * a + b * b) + j;
    m.ox = m.mass * (a * (1.0 - a) - b * b) - j;
  }
  return m;
}

namespace {

// A point's x, y slots as BarLengths' key half.
std::array<std::uint64_t, 2> slot_bits(const Slot& x, const Slot& y) {
  return {std::bit_cast<std::uint64_t>(x), std::bit_cast<std::uint64_t>(y)};
}

}  // namespace

detail::BarLengths::BarLengths(const Model& model) {
  if (!model.solve_rows().empty()) return;
  for (std::size_t c = 0; c < model.constraints().size(); ++c) {
    const auto [block, i] = model.constraint_block(static_cast<Index>(c));
    const auto* distances = dynamic_cast<const TypedBlock<DistanceSpec>*>(block);
    if (!distances) continue;
    const DistanceSpec& d = distances->spec(i);
    const auto a = slot_bits(d.a.x, d.a.y), b = slot_bits(d.b.x, d.b.y);
    bar_[{a[0], a[1], b[0], b[1]}] = bar_[{b[0], b[1], a[0], a[1]}] = Bar{d.length, c};
  }
}

const detail::BarLengths::Bar* detail::BarLengths::find(const PartFrame& f) const {
  if (bar_.empty() || f.kind != PartFrameKind::kPoints || f.spatial_frame || !f.x_is_point) return nullptr;
  const auto o = slot_bits(f.origin.r[0], f.origin.r[1]), x = slot_bits(f.x_toward.r[0], f.x_toward.r[1]);
  const auto it = bar_.find({o[0], o[1], x[0], x[1]});
  return it == bar_.end() ? nullptr : &it->second;
}

void add_generalized_forces(const std::vector<Part>& parts, const Loads& loads, const double* q, const double* qd,
                            const double* qdd, double t, Eigen::VectorXd& Q) {
  for (std::size_t i = 0; i < parts.size(); ++i)
    if (detail::has_mass(parts[i]))
      detail::add_massive_part(parts[i], detail::massive_part(parts[i], i), loads.gravity, q, qd, qdd, t, Q);
  if (loads.applied) add_applied_forces(*loads.applied, q, qd, qdd, t, Q);
}

detail::PartForces::PartForces(const std::vector<Part>& parts, const Model& model, bool rigid_bars,
                               std::vector<char> planar_read)
    : planar_read_(std::move(planar_read)) {
  const BarLengths bars = rigid_bars ? BarLengths(model) : BarLengths();
  // (32-bit indices; a model too large for them keeps its bars as MassiveParts, the same forces)
  const bool compact = model.num_coordinates() <= INT32_MAX && parts.size() <= UINT32_MAX;
  struct Entry {
    std::int32_t row, col;
    double value;
  };
  std::vector<Entry> entries;                                        // M's, each bar's in turn
  std::vector<std::array<double, 2>> weight;                         // w per coordinate (sized at the first bar)
  std::vector<char> reached;                                         // the coordinates a bar's row reaches
  std::map<std::array<std::uint64_t, 7>, std::uint32_t> mass_index;  // a BarMass's bits → its index
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!has_mass(parts[i])) continue;
    const MassivePart m = massive_part(parts[i], i, bars.of(parts[i].frame));
    if (!m.frame.bar || !compact) {
      massive_.push_back(m);
      continue;
    }
    std::int32_t at[5];
    for (int k = 0; k < 5; ++k) at[k] = static_cast<std::int32_t>(m.frame.slots[k].coord());  // (−1: a constant)
    // bar_force_at()'s rows (its origin's x, y, then its x point's x, y: fx, fy, along_x, along_y), each w · g − M · q̈,
    // read off the force itself: w's columns its weight under a unit gravity along x and along y, M's column j its
    // force at the unit acceleration of its j-th point coordinate, negated (the force is linear in both)
    const std::int32_t rows[4] = {at[0], at[1], at[3], at[4]};
    auto row_values = [](const PlanarForce& f) { return std::array<double, 4>{f.fx, f.fy, f.along_x, f.along_y}; };
    auto weight_values = [](const BarWeight& w) { return std::array<double, 4>{w.fx, w.fy, w.along_x, w.along_y}; };
    const std::array<double, 4> wx = weight_values(bar_weight(m, {1.0, 0.0, 0.0})),
                                wy = weight_values(bar_weight(m, {0.0, 1.0, 0.0}));
    std::array<std::array<double, 4>, 4> column;  // column[j][r]: −M[rows[r], rows[j]]
    for (int j = 0; j < 4; ++j) {
      double a[4] = {0.0, 0.0, 0.0, 0.0};
      a[j] = 1.0;
      PlanarForce f;
      bar_force_at(m, BarWeight{}, a[0], a[1], a[2], a[3], f);
      column[static_cast<std::size_t>(j)] = row_values(f);
    }
    for (std::size_t r = 0; r < 4; ++r) {
      if (rows[r] < 0) continue;
      if (weight.empty()) weight.assign(static_cast<std::size_t>(model.num_coordinates()), {0.0, 0.0});
      if (reached.empty()) reached.assign(weight.size(), 0);
      auto& sum = weight[static_cast<std::size_t>(rows[r])];
      sum[0] += wx[r], sum[1] += wy[r];
      reached[static_cast<std::size_t>(rows[r])] = 1;
      for (std::size_t j = 0; j < 4; ++j)
        if (rows[j] >= 0 && column[j][r] != 0.0) entries.push_back({rows[r], rows[j], -column[j][r]});
    }
    const std::int32_t oz = at[2];
    if (oz >= 0) bar_wz_.emplace_back(oz, bar_weight(m, {0.0, 0.0, 1.0}).fz);
    if (!planar_read_.empty() && !planar_read_[i]) continue;
    const BarMass mass{m.m_o, m.m_x, m.m_b, m.oo, m.xx, m.ox, m.mass};
    const std::array<std::uint64_t, 7> key{
        std::bit_cast<std::uint64_t>(mass.m_o), std::bit_cast<std::uint64_t>(mass.m_x),
        std::bit_cast<std::uint64_t>(mass.m_b), std::bit_cast<std::uint64_t>(mass.oo),
        std::bit_cast<std::uint64_t>(mass.xx),  std::bit_cast<std::uint64_t>(mass.ox),
        std::bit_cast<std::uint64_t>(mass.mass)};
    const auto [it, added] = mass_index.try_emplace(key, static_cast<std::uint32_t>(bar_masses_.size()));
    if (added) bar_masses_.push_back(mass);
    BarTerm b;
    std::copy(at, at + 5, b.at);
    b.mass = it->second, b.part = static_cast<std::uint32_t>(m.part);
    read_bars_.push_back(b);
  }
  // M's rows in the coordinates' order, each entry once (the bars' shares summed in the bars' order), its zeros
  // dropped
  std::stable_sort(entries.begin(), entries.end(),
                   [](const Entry& a, const Entry& b) { return a.row != b.row ? a.row < b.row : a.col < b.col; });
  std::size_t e = 0;
  for (std::size_t row = 0; row < reached.size(); ++row) {
    if (!reached[row]) continue;
    for (; e < entries.size() && entries[e].row == static_cast<std::int32_t>(row);) {
      double v = 0.0;
      const std::int32_t col = entries[e].col;
      for (; e < entries.size() && entries[e].row == static_cast<std::int32_t>(row) && entries[e].col == col; ++e)
        v += entries[e].value;
      if (v != 0.0) bar_cols_.push_back(col), bar_mass_.push_back(v);
    }
    bar_rows_.push_back(
        {static_cast<std::int32_t>(row), static_cast<std::uint32_t>(bar_cols_.size()), weight[row][0], weight[row][1]});
  }
}

void detail::PartForces::add(const std::vector<Part>& parts, const Loads& loads, const double* q, const double* qd,
                             const double* qdd, double t, Eigen::VectorXd& Q, PlanarForce* planar) const {
  const V3 g = loads.gravity;
  // (a planar force no one reads is not written: at nfourbar 10⁴ the couplers' are half a megabyte a row)
  auto kept = [&](std::size_t part) { return planar && (planar_read_.empty() || planar_read_[part]); };
  for (const MassivePart& m : massive_)
    add_massive_part(parts[m.part], m, g, q, qd, qdd, t, Q, kept(m.part) ? planar + m.part : nullptr);
  double* const sums = Q.data();
  std::uint32_t e = 0;
  for (const BarRow& r : bar_rows_) {
    double s = r.wx * g.x + r.wy * g.y;
    if (qdd)
      for (; e < r.end; ++e) s -= bar_mass_[e] * qdd[bar_cols_[e]];
    sums[r.coordinate] += s;
    e = r.end;
  }
  for (const auto& [c, wz] : bar_wz_) sums[c] += wz * g.z;
  if (planar && !read_bars_.empty()) {
    thread_local std::vector<BarWeight> weights;  // each BarMass's weight under g (its capacity kept from row to row)
    weights.resize(bar_masses_.size());
    for (std::size_t k = 0; k < bar_masses_.size(); ++k) weights[k] = bar_weight(bar_masses_[k], g);
    auto accel = [&](std::int32_t i) { return i >= 0 && qdd ? qdd[i] : 0.0; };
    for (const BarTerm& b : read_bars_)
      bar_force_at(bar_masses_[b.mass], weights[b.mass], accel(b.at[0]), accel(b.at[1]), accel(b.at[3]), accel(b.at[4]),
                   planar[b.part]);
  }
  if (loads.applied) add_applied_forces(*loads.applied, q, qd, qdd, t, Q);
}

SolveStatus constraint_multipliers(const Model& model, double t, Workspace& ws, const Eigen::VectorXd& Q,
                                   Eigen::VectorXd& lambda, std::string* message) {
  std::string why;
  auto failed = [&](SolveStatus st) {
    if (message) *message = why;
    return st;
  };
  if (!ws.lu) return why = "constraint_multipliers: the model has no square solve", failed(SolveStatus::kNotSquare);
  if (Q.size() != model.num_coordinates())
    throw Error("constraint_multipliers: Q has " + std::to_string(Q.size()) + " entries, the model " +
                std::to_string(model.num_coordinates()) + " coordinates");
  double rcond = 0.0;
  const SolveStatus st = detail::ensure_factorized(model, t, ws, &rcond, &why);
  if (st != SolveStatus::kSuccess) return failed(st);
  Eigen::VectorXd kept;
  if (!multipliers_with_factors(model, *ws.lu, Q, kept, lambda))
    return why = ws.lu->last_message(), failed(SolveStatus::kLinearSolverFailed);
  return SolveStatus::kSuccess;
}

bool multipliers_with_factors(const Model& model, SparseLuNumeric& lu, const Eigen::VectorXd& Q, Eigen::VectorXd& kept,
                              Eigen::VectorXd& lambda) {
  const std::vector<Index>& rows = model.solve_rows();
  if (rows.empty()) {  // every row kept: λ straight from the solve
    lambda.resize(model.num_equations());
    return lu.solve_transposed(Q.data(), lambda.data());
  }
  kept.resize(static_cast<Index>(rows.size()));
  if (!lu.solve_transposed(Q.data(), kept.data())) return false;
  lambda.setZero(model.num_equations());
  for (std::size_t i = 0; i < rows.size(); ++i) lambda(rows[i]) = kept(static_cast<Index>(i));
  return true;
}

bool has_effort(const ConstraintInfo& c) { return c.depends_on_time || is_transmission_kind(c.kind); }

std::vector<Index> rheonomic_constraints(const Model& model) {
  std::vector<Index> out;
  for (std::size_t c = 0; c < model.constraints().size(); ++c)
    if (model.constraints()[c].depends_on_time) out.push_back(static_cast<Index>(c));
  return out;
}

struct DriverEfforts::Impl {
  const Model& model;
  const std::vector<Part>& parts;
  const Loads& loads;
  OutputEfforts natural;                         // the natural joints a bearing may name, with their parts and loads
  std::optional<detail::FrictionLosses> losses;  // the loads' losses that read λ, set up once
  Eigen::VectorXd Q, lambda, kept;
  std::vector<Index> drivers;  // rheonomic_constraints(model): the efforts' rows, found once
};

DriverEfforts::DriverEfforts(const Model& model, const std::vector<Part>& parts, const Loads& loads,
                             std::shared_ptr<const NaturalJoints> natural)
    : impl_(new Impl{model, parts, loads, {}, {}, {}, {}, {}, rheonomic_constraints(model)}) {
  if (!detail::FrictionLosses::any(loads.applied.get())) return;
  if (natural) {  // (a natural point's reaction reads its bodies' parts and loads)
    impl_->natural.natural = std::move(natural);
    impl_->natural.parts = std::make_shared<const std::vector<Part>>(parts);
    impl_->natural.loads = std::make_shared<const Loads>(loads);
  }
  impl_->losses.emplace(model, *loads.applied, impl_->natural.natural ? &impl_->natural : nullptr);
}

DriverEfforts::~DriverEfforts() = default;

SolveStatus DriverEfforts::operator()(double t, Workspace& ws, std::vector<double>& efforts, std::string* message) {
  const Model& model = impl_->model;
  Eigen::VectorXd &Q = impl_->Q, &lambda = impl_->lambda;
  Q.setZero(model.num_coordinates());
  add_generalized_forces(impl_->parts, impl_->loads, ws.q.data(), ws.qd.data(), ws.qdd.data(), t, Q);
  efforts.clear();
  if (!Q.allFinite()) {
    if (message) {
      *message = nonfinite_force_source(impl_->parts, impl_->loads, model.num_coordinates(), ws.q.data(), ws.qd.data(),
                                        ws.qdd.data(), t);
      if (message->empty()) *message = "the parts' and loads' forces, each finite, overflow doubles in their sum";
    }
    return SolveStatus::kNonFinite;
  }
  const SolveStatus st = constraint_multipliers(model, t, ws, Q, lambda, message);
  if (st != SolveStatus::kSuccess) return st;
  if (!lambda.allFinite()) {
    if (message) *message = "the multipliers are not finite (an overflow of doubles)";
    return SolveStatus::kNonFinite;
  }
  if (impl_->losses) {  // (ensure_factorized() gave ws.lu the factors at q)
    detail::FrictionLosses& losses = *impl_->losses;
    const double* qd = ws.qd.size() == model.num_coordinates() ? ws.qd.data() : nullptr;  // (none: at rest)
    const double* qdd = ws.qdd.size() == model.num_coordinates() ? ws.qdd.data() : nullptr;
    if (!losses.solve(model, *ws.lu, ws.q.data(), qd, qdd, t, Q, lambda, impl_->kept))
      return losses.failure(*ws.lu, message);
  }
  for (Index c : impl_->drivers) efforts.push_back(-lambda(model.constraints()[static_cast<std::size_t>(c)].first_row));
  return st;
}

SolveStatus driver_efforts(const Model& model, const std::vector<Part>& parts, const Loads& loads, double t,
                           Workspace& ws, std::vector<double>& efforts, std::string* message,
                           std::shared_ptr<const NaturalJoints> natural) {
  return DriverEfforts(model, parts, loads, std::move(natural))(t, ws, efforts, message);
}

}  // namespace phiq
