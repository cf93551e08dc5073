// Internal: add_generalized_forces() (phiq/inverse_dynamics.hpp) for a sweep, whose efforts evaluate Q at every
// written row: the parts with mass gathered once, those on planar frames as the slots and the four numbers their
// forces read (80 bytes each instead of a Part's kilobyte: at 2·10⁴ parts a row spent its time reading the Parts).
// The same Q, bit for bit, as add_generalized_forces().
#pragma once

#include <Eigen/Core>

#include <vector>

#include "parts/planar_motion.hpp"
#include "phiq/parts.hpp"

namespace phiq::detail {

// A part with mass, as its generalized forces read it.
struct MassivePart {
  PlanarFrame frame;                      // its frame's slots, where `planar`
  double mass = 0.0, cx = 0.0, cy = 0.0;  // its mass and its centre's x, y in its frame
  double izz = 0.0;                       // its inertia about z through the centre
  std::size_t part = 0;                   // its index among the parts
  bool planar = false;                    // on a planar frame (else the general path reads the Part)
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
inline void add_planar_force(const PlanarFrame& frame, const PlanarForce& force, Eigen::VectorXd& Q) {
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
  if (frame.x_is_point) add(o[0], -force.along_x), add(o[1], -force.along_y);
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
  if (frame.x_is_point) visit(o[0], 4, true), visit(o[1], 5, true);
}

class PartForces {
 public:
  PartForces() = default;
  // The parts with mass of `parts`, in order.
  explicit PartForces(const std::vector<Part>& parts);
  // Q += the parts' and the loads' generalized forces at (q, q̇, q̈, t), as add_generalized_forces(parts, loads, …);
  // `parts` those this was made from. With `planar` (one entry per part), each part with mass on a planar frame
  // also leaves there what it added (PlanarForce::valid false where it took the general path); the others' entries
  // are not touched.
  void add(const std::vector<Part>& parts, const Loads& loads, const double* q, const double* qd, const double* qdd,
           double t, Eigen::VectorXd& Q, PlanarForce* planar = nullptr) const;

 private:
  std::vector<MassivePart> massive_;
};

// Whether part `p` has mass: add_generalized_forces() counts it.
inline bool has_mass(const Part& p) { return p.mass_source != MassSource::kNone && p.mass.mass != 0.0; }

// `p` (the index-th part) as its generalized forces read it.
MassivePart massive_part(const Part& p, std::size_t index);

}  // namespace phiq::detail
