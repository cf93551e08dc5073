// One path of the total-degree homotopy (homotopy.hpp): from its start point at t = 1 to t = 0 by an adaptive
// RK4 predictor on dX/dt = −H_X⁻¹ H_t and a Newton corrector at each new t, in projective coordinates on a random
// affine patch, so that a path whose affine solution diverges ends at a finite point with X0 → 0.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/LU>

#include "modes/homotopy.hpp"

namespace phiq::modes_detail {

Eigen::VectorXcd Homotopy::start(std::int64_t p) const {
  const int n = target->variables;
  Eigen::VectorXcd X(n + 1);
  X(0) = 1.0;
  for (int i = 0; i < n; ++i) {
    const int d = std::max(1, target->degree[static_cast<std::size_t>(i)]);
    const std::int64_t k = p % d;
    p /= d;
    X(i + 1) = std::polar(1.0, 2.0 * std::numbers::pi * static_cast<double>(k) / d);
  }
  return X / patch.dot(X);  // (dot conjugates its first argument: patch holds the conjugated a)
}

void Homotopy::evaluate(const Eigen::VectorXcd& X, double t, Eigen::VectorXcd& h, Eigen::MatrixXcd* hx,
                        Eigen::VectorXcd* ht) const {
  const int n = target->variables;
  thread_local Eigen::VectorXcd f;
  thread_local Eigen::MatrixXcd jf;
  target->homogenised(X, f, hx ? &jf : nullptr);
  h.resize(n + 1);
  if (hx) hx->setZero(n + 1, n + 1);
  if (ht) ht->resize(n + 1);
  for (int i = 0; i < n; ++i) {
    const int d = std::max(1, target->degree[static_cast<std::size_t>(i)]);
    const cd g = std::pow(X(i + 1), d) - std::pow(X(0), d);
    h(i) = (1.0 - t) * f(i) + t * gamma * g;
    if (ht) (*ht)(i) = gamma * g - f(i);
    if (hx) {
      hx->row(i) = (1.0 - t) * jf.row(i);
      (*hx)(i, i + 1) += t * gamma * static_cast<double>(d) * std::pow(X(i + 1), d - 1);
      (*hx)(i, 0) -= t * gamma * static_cast<double>(d) * std::pow(X(0), d - 1);
    }
  }
  h(n) = patch.dot(X) - 1.0;
  if (ht) (*ht)(n) = 0.0;
  if (hx) hx->row(n) = patch.adjoint();
}

namespace {

double inf_norm(const Eigen::VectorXcd& v) { return v.cwiseAbs().maxCoeff(); }

// dX/dt along the path at (X, t)
Eigen::VectorXcd velocity(const Homotopy& h, const Eigen::VectorXcd& X, double t) {
  Eigen::VectorXcd value, ht;
  Eigen::MatrixXcd hx;
  h.evaluate(X, t, value, &hx, &ht);
  return Eigen::PartialPivLU<Eigen::MatrixXcd>(hx).solve(-ht);
}

}  // namespace

PathEnd track_path(const Homotopy& h, std::int64_t p, bool careful) {
  // careful: the second pass over the paths that failed or met another path's end (homotopy_solve.cpp), with
  // steps ten times shorter at most and a closer first correction, which keep a path from jumping onto another
  const double kMaxStep = careful ? 0.01 : 0.1, kFirstCorrection = careful ? 1e-5 : 1e-3;
  constexpr double kMinStep = 1e-14, kCorrectorTolerance = 1e-10;
  // A path whose step collapses below kEndGame has reached its end: a singular endpoint (several paths meet, or
  // a solution set at infinity), where the corrector cannot converge as t → 0; the endpoint is refined by Newton
  // on the original equations and classified (a point Newton does not take onto a solution is a failed path).
  constexpr double kEndGame = 1e-3;
  constexpr int kMaxSteps = 200000;
  PathEnd end;
  end.X = h.start(p);
  double t = 1.0, step = 0.01;
  int successes = 0;
  Eigen::VectorXcd value;
  Eigen::MatrixXcd hx;
  while (t > 0.0 && end.steps < kMaxSteps) {
    ++end.steps;
    const double dt = std::min(step, t), t1 = (dt == t) ? 0.0 : t - dt;
    const Eigen::VectorXcd& X = end.X;
    const Eigen::VectorXcd k1 = velocity(h, X, t);
    const Eigen::VectorXcd k2 = velocity(h, X - 0.5 * dt * k1, t - 0.5 * dt);
    const Eigen::VectorXcd k3 = velocity(h, X - 0.5 * dt * k2, t - 0.5 * dt);
    const Eigen::VectorXcd k4 = velocity(h, X - dt * k3, t1);
    Eigen::VectorXcd Y = X - (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    bool converged = false;
    double previous = 0.0;
    const double size = 1.0 + inf_norm(X);
    for (int it = 0; it < 3 && Y.allFinite(); ++it) {
      h.evaluate(Y, t1, value, &hx, nullptr);
      const Eigen::VectorXcd delta = Eigen::PartialPivLU<Eigen::MatrixXcd>(hx).solve(value);
      const double norm = inf_norm(delta);
      // a first correction this large means the prediction left the path's neighbourhood (it could land on
      // another path); a correction that does not contract means Newton is not converging
      if (!std::isfinite(norm) || (it == 0 && norm > kFirstCorrection * size) || (it > 0 && norm > 0.5 * previous))
        break;
      Y -= delta;
      previous = norm;
      if (norm <= kCorrectorTolerance * size) {
        converged = true;
        break;
      }
    }
    if (converged) {
      end.X = Y;
      t = t1;
      if (++successes >= 3) step = std::min(2.0 * step, kMaxStep), successes = 0;
    } else {
      step *= 0.5;
      successes = 0;
      if (step < kMinStep) break;
    }
  }
  end.t = t;
  end.reached = t == 0.0 || t < kEndGame;
  return end;
}

}  // namespace phiq::modes_detail
