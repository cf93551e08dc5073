// What the files of the modes stage share: the compiled (homogenised) form of a polynomial system that the path
// tracker evaluates, one path's tracking, and a deterministic random stream.
#pragma once

#include <complex>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Dense>

#include "phiq/modes.hpp"

namespace phiq::modes_detail {

using cd = std::complex<double>;

// A reproducible stream of uniform numbers (splitmix64): the same on every platform and standard library, unlike
// std::uniform_real_distribution, so that a run's γ, patch and fitting points are the same everywhere.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double symmetric() { return 2.0 * uniform() - 1.0; }                        // [-1, 1)
  cd unit_complex();                                                          // on the unit circle
 private:
  std::uint64_t state_;
};

// A partition of the variables into groups, each homogenised by its own coordinate (a multi-homogeneous start
// system, start_systems.cpp); one group is the total-degree homotopy's projective space. Homogeneous points X hold
// the groups' homogenising coordinates first: X(j) for group j, then X(groups + v) = x_v.
struct Grouping {
  int groups = 1;
  std::vector<int> group_of;              // per variable
  std::vector<std::vector<int>> members;  // per group, its variables ascending
};
Grouping single_group(int variables);
Grouping grouping_from(const std::vector<int>& group_of);

// A system compiled for evaluation: each term its coefficient, its factors (variable, power) and, homogenised, the
// powers of the groups' homogenising coordinates that bring it to its equation's degree in each group.
struct CompiledSystem {
  struct Term {
    cd coefficient;
    std::vector<std::pair<int, int>> homogenising;  // (group j, power of X(j)), powers ≥ 1
    std::vector<std::pair<int, int>> factors;       // (variable v, power ≥ 1)
  };
  int variables = 0;
  int groups = 1;
  std::vector<std::vector<Term>> equations;
  std::vector<int> degree;                     // total degree per equation
  std::vector<std::vector<int>> group_degree;  // [equation][group]
  std::vector<double> coefficient_scale;       // largest |coefficient| per equation
  int max_power = 0;
  CompiledSystem(const PolynomialSystem& s, const Grouping& grouping);
  explicit CompiledSystem(const PolynomialSystem& s) : CompiledSystem(s, single_group(s.variables)) {}
  // F(x) and its Jacobian (equations × variables) at an affine point x.
  void affine(const Eigen::VectorXcd& x, Eigen::VectorXcd& f, Eigen::MatrixXcd* jac) const;
  // The homogenised F̂(X) and its Jacobian (equations × (groups + variables)) at X.
  void homogenised(const Eigen::VectorXcd& X, Eigen::VectorXcd& f, Eigen::MatrixXcd* jac) const;
};

// The multi-homogeneous Bézout number of a square system under a grouping: the number of ways to give each
// equation one group, each group as many equations as it has variables, weighted by the product of the equations'
// degrees in their groups (saturated at 2⁶²). One group: the total degree.
std::int64_t multihomogeneous_bezout(const std::vector<std::vector<int>>& group_degree, const Grouping& grouping);
std::vector<std::vector<int>> group_degrees(const PolynomialSystem& s, const Grouping& grouping);

// The start system G of the homotopy: for one group, x_i^{d_i} − x0^{d_i} (its roots the roots of unity), else
// Wampler's linear product: G_i = Π_j Π_{k < d_ij} ℓ_ijk(X_j), random linear forms in each group's homogeneous
// coordinates, whose roots are found by solving one linear system per group (start_systems.cpp).
struct StartSystem {
  Grouping grouping;
  std::vector<std::vector<int>> degrees;  // [equation][group]
  // linear_product: ℓ_ijk's coefficients on (X(j), then group j's variables), [i][j][k]
  bool linear_product = false;
  std::vector<std::vector<std::vector<Eigen::VectorXcd>>> factors;
  // the start points: each assignment of equations to groups (assignment[i] = group), and the first path of each
  std::vector<std::vector<int>> assignments;
  std::vector<std::int64_t> first_path;
  std::int64_t paths = 0;
};
// Total degree (one group) or linear product (several); false when the grouping's start points are too many to list.
bool make_start_system(const std::vector<std::vector<int>>& degrees, const Grouping& grouping, Random& random,
                       StartSystem& out);

// The homotopy H(X, t) = (1 − t) F̂(X) + γ t Ĝ(X) of a square system on an affine patch of each group's projective
// space (a_j · X_j = 1).
struct Homotopy {
  const CompiledSystem* target;
  const StartSystem* start_system;
  cd gamma;
  Eigen::VectorXcd patch;  // (conjugated) a_j on each group's coordinates
  // The start point of path p, on the patches.
  Eigen::VectorXcd start(std::int64_t p) const;
  // H(X, t) (n + groups rows with the patches) and, when asked, H_X and H_t.
  void evaluate(const Eigen::VectorXcd& X, cd t, Eigen::VectorXcd& h, Eigen::MatrixXcd* hx, Eigen::VectorXcd* ht) const;
  // The affine point of X (x_v = X(groups + v) / X(group of v)).
  Eigen::VectorXcd affine(const Eigen::VectorXcd& X) const;
  // min over the groups of |X(j)| / max |X_j|: 0 at infinity, of order one at a finite point.
  double finiteness(const Eigen::VectorXcd& X) const;
};

// Where one path ended.
struct PathEnd {
  Eigen::VectorXcd X;    // the last point (homogeneous, on the patch)
  double t = 1.0;        // the t it reached (0 at a clean end)
  bool reached = false;  // tracked to t = 0, straight or by the end game
  int steps = 0;
  int winding = 0;        // the winding number Cauchy's end game found (0: no end game)
  double accuracy = 0.0;  // the end game's last two estimates of X(0) apart, over 1 + |X|∞ (0: tracked straight)
  std::string failure;    // why the path did not reach t = 0, when it did not
};

// Tracks path p from t = 1 to t = 0, the end game turning at most max_winding times round t = 0; `careful`: shorter
// steps and a closer corrector (a second attempt).
PathEnd track_path(const Homotopy& h, std::int64_t p, int max_winding, bool careful = false);

// The square system with each equation's highest-degree form cancelled, where it can be, by polynomial multiples of
// the equations before it (lowest degree first): the same ideal, so the same finite solutions, in fewer paths
// (degree_lowering.cpp).
PolynomialSystem lowered_degrees(const PolynomialSystem& square);

// Newton (Gauss-Newton for more equations than unknowns) on f's equations from x, in place: returns the residual
// max_i |F_i| / (largest |coefficient| of F_i) and sets *condition, the condition number of the Jacobian with the
// variables scaled by 1 + |x|∞.
double refine_endpoint(const CompiledSystem& f, Eigen::VectorXcd& x, double* condition);

}  // namespace phiq::modes_detail
