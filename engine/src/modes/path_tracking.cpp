// One path of the homotopy (homotopy.hpp): from its start point at t = 1 to t = 0 by an adaptive RK4 predictor on
// dX/dt = −H_X⁻¹ H_t and a Newton corrector at each new t, in projective coordinates on a random affine patch per
// group, so that a path whose affine solution diverges ends at a finite point with X_j0 → 0.
//
// The end game. A path that ends at a regular solution is tracked to t = 0 itself. One that ends at a singular
// point (several paths meet there, or a solution set at infinity) cannot be: near t = 0 the paths that meet are
// branches of one Puiseux series X(t) = Σ a_k t^{k/c} (c the winding number) and the corrector's step collapses.
// Below t = 0.1 a path is taken in pieces t = 0.1 / 4^k, whose points estimate c (|X_k − X_{k+1}| ∝ t_k^{1/c}).
// A path whose step collapses, or whose estimates settle at c ≥ 2, is run round circles |t| = r in the complex
// plane from the first radius where the estimates settled (Cauchy's end game, Morgan, Sommese and Wampler 1991):
// after c turns it is back where it began, and the mean of its points at equally spaced angles over those turns is
// X(0) by Cauchy's integral formula in s = t^{1/c} (the trapezoid rule on a circle, exact to r^{K/c} for K points a
// turn). The radius shrinks by 4 until two estimates agree.
//
// Every path whose step collapses short of t = 0 goes through the end game, whether it ends at a finite
// singular point or at infinity: on the patch, a path to infinity is a path to a finite point with X_j0 = 0, and
// the end game places that point as it places any other, so that the path is classified by the homogenising
// coordinate of its end (homotopy_solve.cpp), not by where its step collapsed. The winding number is found by
// turning until the path closes, up to ModesOptions::max_winding turns (and no more than the paths there are: c
// paths meet at an end of winding number c); a path that does not close within them is failed, with its reason.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

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

// x in three significant digits, for a failed path's reason
std::string short_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

constexpr double kEndGameStart = 0.1;  // the radius of the first circle
constexpr int kPointsPerTurn = 8;

// How an end game went.
struct EndGame {
  bool ended = false;
  Eigen::VectorXcd estimate;  // X(0)
  int winding = 0;
  double accuracy = std::numeric_limits<double>::infinity();  // |last two estimates' difference| / (1 + |X|)
  std::string failure;                                        // why not, when not ended
};

// Cauchy's end game from X on the path at t = r (the file's comment), at most max_winding turns a circle.
// theta0: the circles begin (and the radius shrinks) on the ray at that angle.
EndGame cauchy_end_game(const Homotopy& h, Eigen::VectorXcd X, double r, double theta0, int max_winding, Tracking& tr) {
  EndGame out;
  Eigen::VectorXcd previous;
  auto closed = [](const Eigen::VectorXcd& at, const Eigen::VectorXcd& begin) {
    return inf_norm(at - begin) <= 1e-7 * (1.0 + inf_norm(begin));
  };
  for (int round = 0; round < 10 && r > 1e-12; ++round) {
    const Eigen::VectorXcd begin = X;
    Eigen::VectorXcd sum = Eigen::VectorXcd::Zero(X.size()), at = X;
    int turns = 0, points = 0;
    double stopped = 0.0;
    while (turns < max_winding) {
      for (int k = 0; k < kPointsPerTurn; ++k) {
        sum += at, ++points;
        const Piece arc{0.0,
                        0.0,
                        true,
                        r,
                        theta0 + 2.0 * std::numbers::pi * k / kPointsPerTurn,
                        2.0 * std::numbers::pi / kPointsPerTurn};
        if (!track_piece(h, at, arc, tr, &stopped)) {
          out.failure = "its step collapsed on the end game's circle |t| = " + short_number(r);
          return out;
        }
      }
      ++turns;
      if (closed(at, begin)) break;
    }
    if (!closed(at, begin)) {
      out.failure = "it did not close within " + std::to_string(max_winding) + (max_winding == 1 ? " turn" : " turns") +
                    " of |t| = " + short_number(r) +
                    " (its winding number is above the limit, ModesOptions::max_winding)";
      return out;
    }
    const Eigen::VectorXcd mean = sum / static_cast<double>(points);
    out.winding = turns, out.estimate = mean;
    if (previous.size()) out.accuracy = inf_norm(mean - previous) / (1.0 + inf_norm(mean));
    if (previous.size() && out.accuracy <= 1e-9) {
      out.ended = true;
      return out;
    }
    previous = mean;
    const Piece inward{std::polar(r, theta0), std::polar(r / 4.0, theta0)};
    if (!track_piece(h, X, inward, tr, &stopped)) break;
    r /= 4.0;
  }
  // where the path cannot be taken closer, or after the last round: the last estimate when the last two agree to
  // 1e-6 (its accuracy then says how good it is)
  out.ended = previous.size() > 0 && out.winding > 0 && out.accuracy <= 1e-6;
  if (!out.ended)
    out.failure = "the end game's estimates of its end did not settle (apart by " + short_number(out.accuracy) + ")";
  return out;
}

constexpr double kShrink = 4.0;  // the ratio of successive radii along the ray

// log(kShrink) over log of the ratio of two successive differences along the ray: the cycle number c of the path's
// Puiseux series X(t) = X(0) + a t^{1/c} + … (each difference shrinks by kShrink^{1/c}); 0 when the differences do
// not shrink.
double cycle_estimate(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b, const Eigen::VectorXcd& c) {
  const double d1 = inf_norm(a - b), d2 = inf_norm(b - c);
  return d2 > 0.0 && d1 > d2 ? std::log(kShrink) / std::log(d1 / d2) : 0.0;
}

using RaySamples = std::vector<std::pair<double, Eigen::VectorXcd>>;  // (t on the ray, X there)

// Samples along a ray, and the first sample k where two successive estimates of the cycle number (from samples
// k … k + 3) round to one integer within 0.1, with that integer ((−1, 0) while there is none): found as the samples
// come, each window once.
struct Ray {
  RaySamples along;
  std::ptrdiff_t settled_at = -1;
  int cycle = 0;
  void add(double t, const Eigen::VectorXcd& X) {
    along.emplace_back(t, X);
    if (settled_at >= 0 || along.size() < 4) return;
    auto settled = [](double c) { return c >= 0.9 && std::abs(c - std::round(c)) <= 0.1; };
    const std::size_t k = along.size() - 4;
    const double c1 = cycle_estimate(along[k].second, along[k + 1].second, along[k + 2].second);
    const double c2 = cycle_estimate(along[k + 1].second, along[k + 2].second, along[k + 3].second);
    if (settled(c1) && settled(c2) && std::round(c1) == std::round(c2))
      settled_at = static_cast<std::ptrdiff_t>(k), cycle = static_cast<int>(std::round(c1));
  }
};

// The path from t = 0.1 (X) along the ray at angle theta to t = 0.1 / 4^k, k = 1, 2, …, down to `floor`, while it
// can be taken (*collapsed: the |t| where its step collapsed, else 0), and, when `stop_at_cycle` is true, no further
// than where its cycle-number estimates settle at 2 or more (its end is singular: the end game's).
Ray sample_ray(const Homotopy& h, Eigen::VectorXcd X, double theta, double floor, bool stop_at_cycle, Tracking& tr,
               double* collapsed) {
  Ray ray;
  ray.add(kEndGameStart, X);
  double stopped = 0.0;
  *collapsed = 0.0;
  for (double r = kEndGameStart; r / kShrink >= floor; r /= kShrink) {
    if (!track_piece(h, X, Piece{std::polar(r, theta), std::polar(r / kShrink, theta)}, tr, &stopped)) {
      *collapsed = r - stopped * (r - r / kShrink);
      break;
    }
    ray.add(r / kShrink, X);
    if (stop_at_cycle && ray.cycle >= 2) break;
  }
  return ray;
}

// The radii to start the end game at, with the path's point there, from its samples along a ray. A circle round
// t = 0 holds the path's Puiseux series only inside its radius of convergence (other branch points of the homotopy
// cluster near t = 0 when paths go to a solution set at infinity: a circle round them too permutes many paths, and
// does not close within a few turns): the first radius where the cycle-number estimates settle, then 16 and 256
// times smaller; without such a radius, the three smallest at least 16 times above where the step collapsed.
RaySamples end_game_radii(const Ray& ray, double collapsed) {
  const std::ptrdiff_t first = ray.settled_at;
  RaySamples along = ray.along;
  while (first < 0 && along.size() > 1 && along.back().first < 16.0 * collapsed) along.pop_back();
  std::size_t begin = first >= 0 ? static_cast<std::size_t>(first) : along.size() >= 3 ? along.size() - 3 : 0;
  RaySamples radii;
  for (std::size_t k = begin; k < along.size() && radii.size() < 3; k += 2) radii.push_back(along[k]);
  return radii;
}

}  // namespace

PathEnd track_path(const Homotopy& h, std::int64_t p, int max_winding, bool careful) {
  // careful: the second pass over the paths that failed or met another path's end (homotopy_solve.cpp), with
  // steps ten times shorter at most and a closer first correction, which keep a path from jumping onto another
  Tracking tr{careful ? 0.01 : 0.1, careful ? 1e-5 : 1e-3};
  PathEnd end;
  end.X = h.start(p);
  double stopped = 0.0;
  if (!track_piece(h, end.X, Piece{1.0, kEndGameStart}, tr, &stopped)) {
    end.t = 1.0 - stopped * (1.0 - kEndGameStart);
    end.steps = tr.steps;
    end.failure = "its step collapsed at t = " + short_number(end.t) + ", before the end game's circle";
    return end;
  }
  // Along the ray in pieces t = 0.1 / 4^k, whose points estimate the cycle number of the path's Puiseux series: to
  // t = 1e-10 and then straight to 0 for a path whose end is regular; a path whose cycle number settles at 2 or more
  // (a singular end) or whose step collapses goes to the end game.
  const Eigen::VectorXcd at_start = end.X;
  double collapsed = 0.0;
  const Ray real_ray = sample_ray(h, at_start, 0.0, 1e-10, true, tr, &collapsed);
  const bool settled = collapsed == 0.0 && real_ray.cycle >= 2;
  bool straight = false;
  end.X = real_ray.along.back().second, end.t = real_ray.along.back().first;
  if (collapsed == 0.0 && !settled) {
    straight = track_piece(h, end.X, Piece{end.t, 0.0}, tr, &stopped);
    end.t = straight ? 0.0 : end.t * (1.0 - stopped);
  } else if (collapsed > 0.0) {
    end.t = collapsed;
  }
  end.reached = straight;
  if (!straight) {
    // the end game for every path whose step collapsed or whose end is singular, at a finite point or at infinity
    // alike, on circles where the path's own points say its Puiseux series holds (end_game_radii)
    EndGame game;
    for (const auto& [r, X] : end_game_radii(real_ray, collapsed > 0.0 ? collapsed : end.t)) {
      game = cauchy_end_game(h, X, r, 0.0, max_winding, tr);
      if (game.ended) break;
    }
    // Failing that, the same along the rays at ±π/6, reached along the arc |t| = 0.1: the straight path may have
    // collapsed near a singular point of the homotopy other than t = 0 (the γ trick keeps them off the real segment,
    // not far from it), or lost its accuracy near t = 0 before its Puiseux series settled.
    for (const double theta : {std::numbers::pi / 6.0, -std::numbers::pi / 6.0}) {
      if (game.ended) break;
      Eigen::VectorXcd X = at_start;
      if (!track_piece(h, X, Piece{0.0, 0.0, true, kEndGameStart, 0.0, theta}, tr, &stopped)) continue;
      double lost = 0.0;
      const Ray ray = sample_ray(h, X, theta, 1e-14, false, tr, &lost);
      for (const auto& [r, Y] : end_game_radii(ray, lost)) {
        EndGame around = cauchy_end_game(h, Y, r, theta, max_winding, tr);
        if (around.ended) {
          game = std::move(around);
          break;
        }
      }
    }
    if (game.ended) {
      end.X = game.estimate, end.t = 0.0, end.reached = true, end.winding = game.winding;
      end.accuracy = game.accuracy;
    } else {
      end.failure = (settled ? "its end is singular (its cycle number settled by t = " + short_number(end.t) + ")"
                             : "its step collapsed at t = " + short_number(end.t)) +
                    " and " + game.failure;
    }
  }
  end.steps = tr.steps;
  return end;
}

}  // namespace phiq::modes_detail
