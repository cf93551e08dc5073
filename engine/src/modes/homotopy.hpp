// What the files of the modes stage share: the compiled (homogenised) form of a polynomial system that the path
// tracker evaluates, one path's tracking, and a deterministic random stream.
#pragma once

#include <complex>
#include <cstdint>
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

// A system compiled for evaluation: each term its coefficient, its factors (variable, power) and, homogenised, the
// power of x0 that brings it to its equation's degree. Variables of the homogenised system: X0 = x0, X(v+1) = x_v.
struct CompiledSystem {
  struct Term {
    cd coefficient;
    int homogenising = 0;                      // power of X0 in the homogenised equation
    std::vector<std::pair<int, int>> factors;  // (variable v, power ≥ 1)
  };
  int variables = 0;
  std::vector<std::vector<Term>> equations;
  std::vector<int> degree;
  std::vector<double> coefficient_scale;  // largest |coefficient| per equation
  int max_power = 0;
  explicit CompiledSystem(const PolynomialSystem& s);
  // F(x) and its Jacobian (equations × variables) at an affine point x.
  void affine(const Eigen::VectorXcd& x, Eigen::VectorXcd& f, Eigen::MatrixXcd* jac) const;
  // The homogenised F̂(X) and its Jacobian (equations × (variables + 1)) at X.
  void homogenised(const Eigen::VectorXcd& X, Eigen::VectorXcd& f, Eigen::MatrixXcd* jac) const;
};

// The total-degree homotopy of a square system on an affine patch of projective space.
struct Homotopy {
  const CompiledSystem* target;
  cd gamma;
  Eigen::VectorXcd patch;  // a · X = 1
  // The start point of path p (mixed radix over the degrees), on the patch.
  Eigen::VectorXcd start(std::int64_t p) const;
  // H(X, t) (n + 1 rows with the patch) and, when asked, H_X and H_t.
  void evaluate(const Eigen::VectorXcd& X, double t, Eigen::VectorXcd& h, Eigen::MatrixXcd* hx,
                Eigen::VectorXcd* ht) const;
};

// Where one path ended.
struct PathEnd {
  Eigen::VectorXcd X;    // the last point (homogeneous, on the patch)
  double t = 1.0;        // the t it reached (0 at a clean end)
  bool reached = false;  // tracked to t = 0, or to the end game's small t with a collapsing step
  int steps = 0;
};

// Tracks path p from t = 1 to t = 0; `careful`: shorter steps and a closer corrector (a second attempt).
PathEnd track_path(const Homotopy& h, std::int64_t p, bool careful = false);

// Newton (Gauss-Newton for more equations than unknowns) on f's equations from x, in place: returns the residual
// max_i |F_i| / (largest |coefficient| of F_i) and sets *condition, the condition number of the Jacobian with the
// variables scaled by 1 + |x|∞.
double refine_endpoint(const CompiledSystem& f, Eigen::VectorXcd& x, double* condition);

}  // namespace phiq::modes_detail
