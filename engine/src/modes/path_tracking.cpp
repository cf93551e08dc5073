// One path of the homotopy (homotopy.hpp): from its start point at t = 1 to t = 0 by an adaptive RK4 predictor on
// dX/dt = −H_X⁻¹ H_t and a Newton corrector at each new t, in projective coordinates on a random affine patch per
// group, so that a path whose affine solution diverges ends at a finite point with X_j0 → 0.
//
// The end game. A path that ends at a regular solution is tracked to t = 0 itself. One that ends at a singular
// point (several paths meet there, or a solution set at infinity) cannot be: near t = 0 the paths that meet are
// branches of one Puiseux series X(t) = Σ a_k t^{k/c} (c the winding number) and the corrector's step collapses.
// Such a path is taken back to its point at t = 0.1 and run round circles |t| = r in the complex plane (Cauchy's
// end game, Morgan, Sommese and Wampler 1991): after c turns it is back where it began, and the mean of its points
// at equally spaced angles over those turns is X(0) by Cauchy's integral formula in s = t^{1/c} (the trapezoid rule
// on a circle, exact to r^{K/c} for K points a turn). The radius shrinks by 4 until two estimates agree.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/LU>

#include "modes/homotopy.hpp"

namespace phiq::modes_detail {

namespace {

double inf_norm(const Eigen::VectorXcd& v) { return v.cwiseAbs().maxCoeff(); }

// dX/ds along the path at (X, t(s)), dt/ds given
Eigen::VectorXcd velocity(const Homotopy& h, const Eigen::VectorXcd& X, cd t, cd dt_ds) {
  Eigen::VectorXcd value, ht;
  Eigen::MatrixXcd hx;
  h.evaluate(X, t, value, &hx, &ht);
  return Eigen::PartialPivLU<Eigen::MatrixXcd>(hx).solve(-ht * dt_ds);
}

// A piece of the path in t: a segment from `from` to `to`, or (arc) the circle t = radius · e^{iθ} from θ0 over dθ.
struct Piece {
  cd from, to;
  bool arc = false;
  double radius = 0.0, theta0 = 0.0, dtheta = 0.0;
  cd t(double s) const { return arc ? std::polar(radius, theta0 + s * dtheta) : from + s * (to - from); }
  cd dt(double s) const { return arc ? cd(0.0, dtheta) * t(s) : to - from; }
  double length() const { return arc ? radius * std::abs(dtheta) : std::abs(to - from); }
};

struct Tracking {
  double max_step, first_correction;  // in units of t's length
  int steps = 0;
};

constexpr double kMinStep = 1e-14, kCorrectorTolerance = 1e-10;
constexpr int kMaxSteps = 200000;

// Tracks X along `piece` (s from 0 to 1): true when it got to the end; else *stopped is the s it reached.
bool track_piece(const Homotopy& h, Eigen::VectorXcd& X, const Piece& piece, Tracking& tr, double* stopped) {
  const double length = piece.length();
  const double max_step = std::min(1.0, tr.max_step / length);
  double s = 0.0, step = std::min(max_step, 0.01 / std::max(length, 0.01));
  int successes = 0;
  Eigen::VectorXcd value;
  Eigen::MatrixXcd hx;
  while (s < 1.0 && tr.steps < kMaxSteps) {
    ++tr.steps;
    const double ds = std::min(step, 1.0 - s), s1 = (ds == 1.0 - s) ? 1.0 : s + ds;
    const Eigen::VectorXcd k1 = velocity(h, X, piece.t(s), piece.dt(s));
    const Eigen::VectorXcd k2 = velocity(h, X + 0.5 * ds * k1, piece.t(s + 0.5 * ds), piece.dt(s + 0.5 * ds));
    const Eigen::VectorXcd k3 = velocity(h, X + 0.5 * ds * k2, piece.t(s + 0.5 * ds), piece.dt(s + 0.5 * ds));
    const Eigen::VectorXcd k4 = velocity(h, X + ds * k3, piece.t(s1), piece.dt(s1));
    Eigen::VectorXcd Y = X + (ds / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    bool converged = false;
    double previous = 0.0;
    const double size = 1.0 + inf_norm(X);
    for (int it = 0; it < 3 && Y.allFinite(); ++it) {
      h.evaluate(Y, piece.t(s1), value, &hx, nullptr);
      const Eigen::VectorXcd delta = Eigen::PartialPivLU<Eigen::MatrixXcd>(hx).solve(value);
      const double norm = inf_norm(delta);
      // a first correction this large means the prediction left the path's neighbourhood (it could land on
      // another path); a correction that does not contract means Newton is not converging
      if (!std::isfinite(norm) || (it == 0 && norm > tr.first_correction * size) || (it > 0 && norm > 0.5 * previous))
        break;
      Y -= delta;
      previous = norm;
      if (norm <= kCorrectorTolerance * size) {
        converged = true;
        break;
      }
    }
    if (converged) {
      X = Y;
      s = s1;
      if (++successes >= 3) step = std::min(2.0 * step, max_step), successes = 0;
    } else {
      step *= 0.5;
      successes = 0;
      if (step * length < kMinStep) break;
    }
  }
  *stopped = s;
  return s >= 1.0;
}

constexpr double kEndGameStart = 0.1;  // the radius of the first circle
constexpr int kPointsPerTurn = 8;
constexpr int kMaxWinding = 8;

// Cauchy's end game from X on the path at t = r (the file's comment): true with *estimate = X(0) and *winding.
// theta0: the circles begin (and the radius shrinks) on the ray at that angle.
bool cauchy_end_game(const Homotopy& h, Eigen::VectorXcd X, double r, double theta0, Tracking& tr,
                     Eigen::VectorXcd* estimate, int* winding) {
  Eigen::VectorXcd previous;
  for (int round = 0; round < 10 && r > 1e-12; ++round) {
    const Eigen::VectorXcd begin = X;
    Eigen::VectorXcd sum = Eigen::VectorXcd::Zero(X.size()), at = X;
    int turns = 0, points = 0;
    double stopped = 0.0;
    while (turns < kMaxWinding) {
      for (int k = 0; k < kPointsPerTurn; ++k) {
        sum += at, ++points;
        const Piece arc{0.0,
                        0.0,
                        true,
                        r,
                        theta0 + 2.0 * std::numbers::pi * k / kPointsPerTurn,
                        2.0 * std::numbers::pi / kPointsPerTurn};
        if (!track_piece(h, at, arc, tr, &stopped)) return false;
      }
      ++turns;
      if (inf_norm(at - begin) <= 1e-7 * (1.0 + inf_norm(begin))) break;
    }
    if (!(inf_norm(at - begin) <= 1e-7 * (1.0 + inf_norm(begin)))) return false;
    const Eigen::VectorXcd mean = sum / static_cast<double>(points);
    *winding = turns;
    if (previous.size() && inf_norm(mean - previous) <= 1e-9 * (1.0 + inf_norm(mean))) {
      *estimate = mean;
      return true;
    }
    previous = mean, *estimate = mean;
    const Piece inward{std::polar(r, theta0), std::polar(r / 4.0, theta0)};
    if (!track_piece(h, X, inward, tr, &stopped)) return round > 0;  // the last estimate, if there is one
    r /= 4.0;
  }
  return previous.size() > 0;
}

}  // namespace

PathEnd track_path(const Homotopy& h, std::int64_t p, bool careful) {
  // careful: the second pass over the paths that failed or met another path's end (homotopy_solve.cpp), with
  // steps ten times shorter at most and a closer first correction, which keep a path from jumping onto another
  Tracking tr{careful ? 0.01 : 0.1, careful ? 1e-5 : 1e-3};
  // Without a converged end game, a path whose step collapses below kEndGame has reached its end all the same: the
  // endpoint is refined by Newton on the original equations and classified (a point Newton does not take onto a
  // solution is a failed path).
  constexpr double kEndGame = 1e-3;
  PathEnd end;
  end.X = h.start(p);
  double stopped = 0.0;
  if (!track_piece(h, end.X, Piece{1.0, kEndGameStart}, tr, &stopped)) {
    end.t = 1.0 - stopped * (1.0 - kEndGameStart);
    end.steps = tr.steps;
    return end;
  }
  const Eigen::VectorXcd at_start = end.X;
  const bool straight = track_piece(h, end.X, Piece{kEndGameStart, 0.0}, tr, &stopped);
  end.t = straight ? 0.0 : kEndGameStart * (1.0 - stopped);
  end.reached = straight || end.t < kEndGame;
  // the end game for a path still at a finite distance: one whose homogenising coordinate has fallen below
  // kInfinite of its size (in a group) diverges, and its classification needs no more (homotopy_solve.cpp)
  constexpr double kInfinite = 1e-4;
  if (!straight && h.finiteness(end.X) >= kInfinite) {
    Eigen::VectorXcd estimate;
    int winding = 0;
    bool ended = cauchy_end_game(h, at_start, kEndGameStart, 0.0, tr, &estimate, &winding);
    // The circle |t| = 0.1 may enclose a singular point of the homotopy other than t = 0 (the γ trick keeps them
    // off the real segment, not far from it; the straight step collapsed there): round it, along the arc to the
    // angle ±π/6 and in along that ray, and the end game on circles smaller than where the straight path stopped.
    for (const double theta : {std::numbers::pi / 6.0, -std::numbers::pi / 6.0}) {
      if (ended || end.t < 1e-8) break;
      Eigen::VectorXcd X = at_start;
      const double r = end.t / 4.0;
      if (track_piece(h, X, Piece{0.0, 0.0, true, kEndGameStart, 0.0, theta}, tr, &stopped) &&
          track_piece(h, X, Piece{std::polar(kEndGameStart, theta), std::polar(r, theta)}, tr, &stopped))
        ended = cauchy_end_game(h, X, r, theta, tr, &estimate, &winding);
    }
    if (ended) end.X = estimate, end.t = 0.0, end.reached = true, end.winding = winding;
  }
  end.steps = tr.steps;
  return end;
}

}  // namespace phiq::modes_detail
