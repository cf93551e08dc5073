// A parallel chunk's seed turned to the sign of Euler parameters its bodies' motion continues with (euler_signs.hpp).
#include "sweep/euler_signs.hpp"

#include <algorithm>
#include <cmath>

#include "phiq/constraint_block.hpp"
#include "phiq/kinds/euler_parameters.hpp"

namespace phiq::detail {

namespace {

using Quat = std::array<double, 4>;

// A seed is turned over only where it is clearly the opposite of the orientation expected (the 4-vectors within
// 26° of opposite): where the motion is not at a steady rate the extrapolation errs, and a seed left as it is
// costs at worst the chunk (the seam check refuses it), one turned wrongly too. The near-singular Cardan joint's
// output shaft, extrapolated from row 0's rate over a chunk (its speed falls from 57 times the input's), comes
// out at −0.64 with its seed on the right sign.
constexpr double kOpposite = -0.9;
constexpr double kQuarterTurn = 0.5 * 3.141592653589793;

// The Hamilton product a ⊗ b (scalar part first).
Quat product(const Quat& a, const Quat& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}
Quat conjugate(const Quat& a) { return {a[0], -a[1], -a[2], -a[3]}; }
// d ⊗ e*: from two seeds, the turn between them; from a rate ė (or ë) and e, ½ ω (the vector part of ½ α)
Quat relative(const Quat& d, const Quat& e) { return product(d, conjugate(e)); }
// |the vector part|
double vector_norm(const Quat& a) { return std::sqrt(a[1] * a[1] + a[2] * a[2] + a[3] * a[3]); }

// The turn by angle 2·half about the unit axis along v (any axis when v is zero).
Quat turn(double half, double vx, double vy, double vz) {
  const double norm = std::sqrt(vx * vx + vy * vy + vz * vz), s = norm > 0.0 ? std::sin(half) / norm : 0.0;
  return {std::cos(half), s * vx, s * vy, s * vz};
}

}  // namespace

EulerSeedSigns::EulerSeedSigns(const Model& model) {
  // A body's sign is free when its Euler parameters are coordinates or constants 0 (−e then solves its equations
  // too); a constant non-zero one fixes it.
  for (const auto& block : model.blocks()) {
    const auto* euler = dynamic_cast<const TypedBlock<EulerParametersSpec>*>(block.get());
    if (!euler) continue;
    for (std::size_t i = 0; i < euler->size(); ++i) {
      std::array<Index, 4> body{};
      bool free = true;
      for (int k = 0; k < 4; ++k) {
        const Slot& s = euler->spec(i).e[k];
        body[static_cast<std::size_t>(k)] = s.coord();
        free = free && (s.is_coordinate() || s.value() == 0.0);
      }
      if (free) bodies_.push_back(body);
    }
  }
  last_.resize(bodies_.size()), before_.resize(bodies_.size()), rate_.resize(bodies_.size());
  accel_.resize(bodies_.size());
}

void EulerSeedSigns::keep_rates(const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd, std::size_t b, bool turned) {
  const bool has_rate = qd.size() > 0, has_accel = has_rate && qdd.size() > 0;
  for (std::size_t k = 0; k < 4; ++k) {
    const Index j = bodies_[b][k];
    rate_[b][k] = j < 0 || !has_rate ? 0.0 : (turned ? -qd[j] : qd[j]);
    accel_[b][k] = j < 0 || !has_accel ? 0.0 : (turned ? -qdd[j] : qdd[j]);
  }
}

void EulerSeedSigns::start(double t0, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  const Eigen::VectorXd none;  // (both sides of each choice below lvalues: no copy of q̇ or q̈ per body)
  const Eigen::VectorXd &rate = qd.size() == q.size() ? qd : none, &accel = qdd.size() == q.size() ? qdd : none;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    for (std::size_t k = 0; k < 4; ++k) last_[b][k] = bodies_[b][k] < 0 ? 0.0 : q[bodies_[b][k]];
    keep_rates(rate, accel, b, false);
  }
  has_rate_ = rate.size() > 0;
  t_last_ = t0;
  known_ = 1;
}

namespace {

// Turns q's Euler parameters of `body` (0 − x: a zero stays +0, as the sweep in order has it).
void turn_over(const std::array<Index, 4>& body, Eigen::VectorXd& q) {
  for (const Index j : body)
    if (j >= 0) q[j] = 0.0 - q[j];
}

}  // namespace

bool EulerSeedSigns::turn_like(const double* reference, Eigen::VectorXd& q) const {
  bool turned = false;
  for (const std::array<Index, 4>& body : bodies_) {
    double dot = 0.0;
    for (const Index j : body)
      if (j >= 0) dot += q[j] * reference[j];
    if (dot < 0.0) turn_over(body, q), turned = true;
  }
  return turned;
}

double EulerSeedSigns::largest_turn(double span) const {
  double largest = 0.0;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    double turn = 0.0;
    if (has_rate_) {
      turn = 2.0 * (vector_norm(relative(rate_[b], last_[b])) * span +
                    0.5 * vector_norm(relative(accel_[b], last_[b])) * span * span);
    } else if (known_ >= 2) {
      const Quat r = relative(last_[b], before_[b]);
      turn = 2.0 * std::atan2(vector_norm(r), std::fabs(r[0])) * span / (t_last_ - t_before_);
    } else {
      return INFINITY;  // nothing known
    }
    largest = std::max(largest, turn);
  }
  return largest;
}

bool EulerSeedSigns::turns_far(double span) const { return !(largest_turn(span) < kQuarterTurn); }

bool EulerSeedSigns::align(double t, Eigen::VectorXd& seed, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  bool turned = false;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const std::array<Index, 4>& body = bodies_[b];
    Quat e{};
    for (std::size_t k = 0; k < 4; ++k) e[k] = body[k] < 0 ? 0.0 : seed[body[k]];
    // the orientation expected at t: the last seed's turned by φ = ω Δt + α Δt²/2 (ė = ½ ω ⊗ e, so ė ⊗ e* = ½ ω;
    // ë ⊗ e* = ½ α − ¼ |ω|², whose vector part is ½ α), where its rates are known; else turning at a constant
    // rate, the turn from the seed before last to the last carried on over (t − t_last) (with neither, the first
    // seed keeps the sign the seeding pass reached: in sub-steps where the sweep solves positions only)
    Quat expected{};
    if (has_rate_) {
      const double dt = t - t_last_;
      const Quat w = relative(rate_[b], last_[b]), a = relative(accel_[b], last_[b]);  // ½ ω, ½ α
      const Quat h{0.0, w[1] * dt + 0.5 * a[1] * dt * dt, w[2] * dt + 0.5 * a[2] * dt * dt,
                   w[3] * dt + 0.5 * a[3] * dt * dt};  // φ/2 (a is 0 without ë)
      expected = product(turn(vector_norm(h), h[1], h[2], h[3]), last_[b]);
    } else if (known_ >= 2) {
      const Quat r = relative(last_[b], before_[b]);
      const double half = std::atan2(vector_norm(r), r[0]);
      const double s = (t - t_last_) / (t_last_ - t_before_);
      expected = product(turn(s * half, r[1], r[2], r[3]), last_[b]);
    }
    const double dot = e[0] * expected[0] + e[1] * expected[1] + e[2] * expected[2] + e[3] * expected[3];
    const bool turn_this = dot < kOpposite;
    if (turn_this) {
      turn_over(body, seed);
      for (double& x : e) x = 0.0 - x;
      turned = true;
    }
    before_[b] = last_[b], last_[b] = e;
    keep_rates(qd, qdd, b, turn_this);
  }
  has_rate_ = qd.size() > 0;
  t_before_ = t_last_, t_last_ = t;
  ++known_;
  return turned;
}

}  // namespace phiq::detail
