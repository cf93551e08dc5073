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

class PartForces {
 public:
  PartForces() = default;
  // The parts with mass of `parts`, in order.
  explicit PartForces(const std::vector<Part>& parts);
  // Q += the parts' and the loads' generalized forces at (q, q̇, q̈, t), as add_generalized_forces(parts, loads, …);
  // `parts` those this was made from.
  void add(const std::vector<Part>& parts, const Loads& loads, const double* q, const double* qd, const double* qdd,
           double t, Eigen::VectorXd& Q) const;

 private:
  std::vector<MassivePart> massive_;
};

}  // namespace phiq::detail
