// Internal: add_generalized_forces() (phiq/inverse_dynamics.hpp) for a sweep, whose efforts evaluate Q at every
// written row: the parts with mass gathered once, those on planar frames as the slots and the few numbers their
// forces read (~100 bytes each instead of a Part's kilobyte: at 2·10⁴ parts a row spent its time reading the Parts).
//
// A rigid bar (a planar frame from a natural point to another that a distance constraint of the model holds at its
// length L) takes the constant mass matrix of natural coordinates instead of its frame's motion: its centre
// r_G = (1 − a) r_o + a r_x + b R (r_x − r_o), a = c_x / L, b = c_y / L, R the quarter turn, is linear in its two
// points, and its kinetic energy ½ m |ṙ_G|² + ½ (I_zz / L²) |ṙ_x − ṙ_o|², so that its Q is m A_oᵀ g − M_o· r̈ at the
// origin and m A_xᵀ g − M_x· r̈ at x, with no division, root or velocity. On the bar's length it differs from the
// frame's motion's Q only by a multiple of the bar's own row of Φq (along the bar: what the length's equation
// carries): λ of every other row, hence every effort and every joint's reaction, is the same; the bar's own
// multiplier takes the difference. A sweep's Q assembles the bars' matrices and weights once, Q = w(g) − M q̈ over
// the coordinates they reach: one sparse product a row (bench/README.md). Not with ∂τ/∂p (PartForces'
// `rigid_bars`), where the model dropped redundant rows (BarLengths), nor, with natural joints' reactions, where a
// bar's row is not its body's (JointReactions::rigid_bars()). Without bars the same Q, bit for bit, as
// add_generalized_forces(); with them the same to rounding (the bars' shares summed per entry).
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "parts/planar_motion.hpp"
#include "phiq/parts.hpp"

namespace phiq {
class Model;
}

namespace phiq::detail {

// Four slots' bits, mixed (BarLengths' key).
struct SlotsHash {
  std::size_t operator()(const std::array<std::uint64_t, 4>& k) const {
    std::size_t h = 0;
    for (std::uint64_t v : k) h = h * 1000003u ^ std::hash<std::uint64_t>{}(v);
    return h;
  }
};

// A part with mass, as its generalized forces read it.
struct MassivePart {
  PlanarFrame frame;                      // its frame's slots, where `planar` (frame.bar: a rigid bar's)
  double mass = 0.0, cx = 0.0, cy = 0.0;  // its mass and its centre's x, y in its frame
  double izz = 0.0;                       // its inertia about z through the centre
  // A rigid bar's constant mass matrix (file comment): m (1 − a), m a, m b, and the scalar parts of M_oo, M_xx and
  // M_ox = ox I + m b R (M_xo = ox I − m b R)
  double m_o = 0.0, m_x = 0.0, m_b = 0.0, oo = 0.0, xx = 0.0, ox = 0.0;
  std::size_t part = 0;  // its index among the parts
  bool planar = false;   // on a planar frame (else the general path reads the Part)
};

// What a part on a planar frame adds to Q at its frame's slots (add_planar_force()): the force at its origin
// (fx, fy, fz), and the moment's share `turn` (a body's ψ) or its shares along x's target (along_x, along_y; taken
// off the origin too when x's target is a point). `valid` false where the frame's direction had zero length (the
// general path's NaN).
struct PlanarForce {
  double fx = 0.0, fy = 0.0, fz = 0.0, turn = 0.0, along_x = 0.0, along_y = 0.0;
  bool valid = false;
};

// PlanarForce's values by index, for for_each_planar_term() (below).
inline constexpr double PlanarForce::*kPlanarFields[6] = {&PlanarForce::fx,      &PlanarForce::fy,
                                                          &PlanarForce::fz,      &PlanarForce::turn,
                                                          &PlanarForce::along_x, &PlanarForce::along_y};

// Q += `force` at `frame`'s coordinate slots, in the order add_generalized_forces() adds them: the same sums, bit
// for bit, wherever the force was computed.
// Always inlined: Q's assembly calls it for each of 2·10⁴ parts a row (nfourbar 10⁴), where a call cost a third.
[[gnu::always_inline]] inline void add_planar_force(const PlanarFrame& frame, const PlanarForce& force,
                                                    Eigen::VectorXd& Q) {
  auto add = [&](const Slot& s, double v) {
    if (s.is_coordinate()) Q(s.coord()) += v;
  };
  const Slot* o = frame.slots;
  if (frame.body) {
    add(o[0], force.fx), add(o[1], force.fy), add(o[2], force.turn);
    return;
  }
  const Slot* x = o + 3;
  add(o[0], force.fx), add(o[1], force.fy), add(o[2], force.fz);
  add(x[0], force.along_x), add(x[1], force.along_y);
  if (frame.x_is_point && !frame.bar) add(o[0], -force.along_x), add(o[1], -force.along_y);
}

// add_planar_force()'s terms, in its order, for those that read a few of its sums (JointReactions' flat sites):
// visit(slot, field, negated), the value kPlanarFields[field], negated or not. (add_planar_force() keeps its own
// written-out form: Q's assembly at every row, which a visitor the compiler did not inline made slower;
// NaturalReactions.PlanarTermsSumAsAddPlanarForce holds the two to the same sums.)
template <class Visit>
void for_each_planar_term(const PlanarFrame& frame, Visit&& visit) {
  const Slot* o = frame.slots;
  if (frame.body) {
    visit(o[0], 0, false), visit(o[1], 1, false), visit(o[2], 3, false);
    return;
  }
  const Slot* x = o + 3;
  visit(o[0], 0, false), visit(o[1], 1, false), visit(o[2], 2, false);
  visit(x[0], 4, false), visit(x[1], 5, false);
  if (frame.x_is_point && !frame.bar) visit(o[0], 4, true), visit(o[1], 5, true);
}

// The lengths at which a model's distance constraints hold pairs of points, and which constraint holds each.
class BarLengths {
 public:
  struct Bar {
    double length = 0.0;
    std::size_t constraint = 0;  // its index among the model's constraints
  };
  BarLengths() = default;
  // `model`'s distance constraints; none when the model dropped redundant rows (their minimum-norm multipliers,
  // unlike the others, would not be the same under a bar's Q).
  explicit BarLengths(const Model& model);
  // The distance constraint that holds `frame`'s origin and x point, a planar frame of points; null when none does.
  const Bar* find(const PartFrame& frame) const;
  // Its length L, 0 when none.
  double of(const PartFrame& frame) const {
    const Bar* b = find(frame);
    return b ? b->length : 0.0;
  }

 private:
  std::unordered_map<std::array<std::uint64_t, 4>, Bar, SlotsHash> bar_;  // both orders of a, b
};

// A rigid bar's weight at its two points (PlanarForce's fx, fy, along_x, along_y, fz), read from `p` (a MassivePart,
// or PartForces' shared BarMass: m_o, m_x, m_b, mass): the constant part of bar_force_at()'s force.
struct BarWeight {
  double fx = 0.0, fy = 0.0, along_x = 0.0, along_y = 0.0, fz = 0.0;
};
template <class Bar>
[[gnu::always_inline]] inline BarWeight bar_weight(const Bar& p, kin3::V3 gravity) {
  const double gx = gravity.x, gy = gravity.y;  // (R v = (−v_y, v_x), the quarter turn)
  return {p.m_o * gx - p.m_b * gy, p.m_o * gy + p.m_b * gx, p.m_x * gx + p.m_b * gy, p.m_x * gy - p.m_b * gx,
          p.mass * gravity.z};
}

// w's share of PlanarForce field `field` (kPlanarFields' order; turn's is zero)
inline double bar_weight_share(const BarWeight& w, int field) {
  const double shares[6] = {w.fx, w.fy, w.fz, 0.0, w.along_x, w.along_y};
  return shares[field];
}

// A rigid bar's force field by field (kPlanarFields' order), the one statement of its sums: the weight's share less
// ((n₀ a₀ + n₁ a₁) + n₂ a₂), each a_k one of its frame's four accelerations (`accel`: origin x, y; x's target x, y)
// and n_k one of its mass numbers (`number`: oo, ox, xx, m_b), negated where `minus`. fz is the weight's alone and
// turn zero (`count` 0). Those who sum one field alone (JointReactions' simple sites) read it here, in this order,
// and so get bar_force_at()'s bits.
struct BarFieldTerm {
  std::uint8_t accel = 0, number = 0;
  bool minus = false;
};
struct BarField {
  int count = 0;
  BarFieldTerm terms[3];
};
inline constexpr BarField kBarFields[6] = {
    {3, {{0, 0, false}, {2, 1, false}, {3, 3, true}}},   // fx: M_oo a_o + M_ox a_x, M_ox = ox I + m_b R
    {3, {{1, 0, false}, {3, 1, false}, {2, 3, false}}},  // fy
    {0, {}},                                             // fz: the weight's
    {0, {}},                                             // turn: none (a bar has no angle of its own)
    {3, {{0, 1, false}, {1, 3, false}, {2, 2, false}}},  // along_x: M_xo a_o + M_xx a_x, M_xo = ox I − m_b R
    {3, {{1, 1, false}, {0, 3, true}, {3, 2, false}}},   // along_y
};
// mass number k of kBarFields (0 oo, 1 ox, 2 xx, 3 m_b) of `p` (a MassivePart, or PartForces' shared BarMass)
template <class Bar>
constexpr double bar_number(const Bar& p, int k) {
  return k == 0 ? p.oo : k == 1 ? p.ox : k == 2 ? p.xx : p.m_b;
}
// field `field` of a rigid bar's force with weight share `weight` at accelerations `a` (kBarFields' sums)
template <class Bar>
[[gnu::always_inline]] inline double bar_field(const Bar& p, double weight, int field, const double (&a)[4]) {
  const BarField& f = kBarFields[field];
  if (f.count == 0) return weight;
  auto term = [&](const BarFieldTerm& t) {
    return (t.minus ? -bar_number(p, t.number) : bar_number(p, t.number)) * a[t.accel];
  };
  return weight - ((term(f.terms[0]) + term(f.terms[1])) + term(f.terms[2]));
}

// A rigid bar's force from its weight `w` (bar_weight()) and its four accelerations (origin x, y; x's target x, y):
// the weight less its constant mass matrix, read from `p` (oo, ox, xx, m_b), times them (kBarFields). Always
// inlined: Q takes it for each of nfourbar 10⁴'s 2·10⁴ parts at every row.
template <class Bar>
[[gnu::always_inline]] inline void bar_force_at(const Bar& p, const BarWeight& w, double aox, double aoy, double axx,
                                                double axy, PlanarForce& f) {
  const double a[4] = {aox, aoy, axx, axy};
  f.fx = bar_field(p, w.fx, 0, a), f.fy = bar_field(p, w.fy, 1, a);
  f.along_x = bar_field(p, w.along_x, 4, a), f.along_y = bar_field(p, w.along_y, 5, a);
  f.fz = w.fz, f.turn = 0.0;
  f.valid = true;
}

class PartForces {
 public:
  PartForces() = default;
  // The parts with mass of `parts`, in order; with `rigid_bars`, those that are rigid bars of `model` (BarLengths)
  // with their constant mass matrix (file comment). (∂τ/∂p differentiates the frames' motion's Q, with whose λ
  // alone its formula holds: a sweep that asks for them takes no bars.)
  PartForces(const std::vector<Part>& parts, const Model& model, bool rigid_bars, std::vector<char> planar_read = {});
  // Q += the parts' and the loads' generalized forces at (q, q̇, q̈, t), as add_generalized_forces(parts, loads, …)
  // (q̈ null: zero); `parts` those this was made from. With `planar` (one entry per part), each part with mass on a
  // planar frame that `planar_read` flags (every one when it was not given) also leaves there what it added, as
  // add_massive_part() would, bit for bit (PlanarForce::valid false where it took the general path); the others'
  // entries are not touched.
  void add(const std::vector<Part>& parts, const Loads& loads, const double* q, const double* qd, const double* qdd,
           double t, Eigen::VectorXd& Q, PlanarForce* planar = nullptr) const;

 private:
  // A rigid bar's mass numbers (MassivePart's), shared by the bars that have the same (nfourbar's 2·10⁴ have one).
  struct BarMass {
    double m_o = 0.0, m_x = 0.0, m_b = 0.0, oo = 0.0, xx = 0.0, ox = 0.0, mass = 0.0;
  };
  // A rigid bar whose PlanarForce is read (planar_read): its frame's slots decoded (−1: a constant), its BarMass
  // and its part.
  struct BarTerm {
    std::int32_t at[5] = {-1, -1, -1, -1, -1};  // origin x, y, z; x's target x, y
    std::uint32_t mass = 0;                     // its BarMass
    std::uint32_t part = 0;                     // its index among the parts
  };
  // The rigid bars' Q, assembled once (file comment): Q_i += wx_i g_x + wy_i g_y − Σ_j M_ij q̈_j at each coordinate
  // i the bars reach, M their constant mass matrix summed over the bars (bar_cols_, bar_mass_: the entries of the
  // i-th row end at `end`) and w their weight per unit of gravity. One sparse product a row instead of 2·10⁴ bars'
  // scattered sums at nfourbar 10⁴ (bench/README.md).
  struct BarRow {
    std::int32_t coordinate = 0;
    std::uint32_t end = 0;
    double wx = 0.0, wy = 0.0;
  };
  std::vector<MassivePart> massive_;  // the other parts with mass, in order
  std::vector<BarRow> bar_rows_;
  std::vector<std::int32_t> bar_cols_;
  std::vector<double> bar_mass_;
  std::vector<std::pair<std::int32_t, double>> bar_wz_;  // the weight along z per unit of g_z (a coordinate origin z)
  std::vector<BarTerm> read_bars_;
  std::vector<BarMass> bar_masses_;
  std::vector<char> planar_read_;  // per part (empty: every one)
};

// Whether part `p` has mass: add_generalized_forces() counts it.
inline bool has_mass(const Part& p) { return p.mass_source != MassSource::kNone && p.mass.mass != 0.0; }

// Q += the generalized force of `p` with mass, as `massive` (massive_part(p, …)) reads it: its planar frame's closed
// form (a rigid bar's constant mass matrix where massive.frame.bar), or its motion and Jacobian. With `planar`, a
// planar frame's force is left there too (PlanarForce::valid false when the general path took it).
void add_massive_part(const Part& p, const MassivePart& massive, kin3::V3 gravity, const double* q, const double* qd,
                      const double* qdd, double t, Eigen::VectorXd& Q, PlanarForce* planar = nullptr);

// `p` (the index-th part) as its generalized forces read it; a rigid bar's (file comment) when `bar_length` > 0, its
// frame a planar one of points (else the length is not read).
MassivePart massive_part(const Part& p, std::size_t index, double bar_length = 0.0);

}  // namespace phiq::detail
