// The predictors: their names and the choice among them (the public functions of phiq/sweep.hpp), the history each
// needs, and their formulas (Sweeper::predict(), run before every drive step): one place to read, or add, a way of
// guessing the next position.
#include "sweep/predictors.hpp"

#include "sweep/sweeper.hpp"

namespace phiq {

const char* to_string(Predictor p) {
  switch (p) {
    case Predictor::kAuto:
      return "auto";
    case Predictor::kPrevious:
      return "previous";
    case Predictor::kSecant:
      return "secant";
    case Predictor::kLinear:
      return "linear";
    case Predictor::kQuadratic:
      return "quadratic";
    case Predictor::kCubic:
      return "cubic";
    case Predictor::kParabolic:
      return "parabolic";
    case Predictor::kHermite:
      return "hermite";
  }
  return "?";
}

const std::vector<Predictor>& all_predictors() {
  static const std::vector<Predictor> all = {Predictor::kAuto,      Predictor::kPrevious, Predictor::kSecant,
                                             Predictor::kParabolic, Predictor::kLinear,   Predictor::kHermite,
                                             Predictor::kQuadratic, Predictor::kCubic};
  return all;
}

bool predictor_from_string(const std::string& name, Predictor* p) {
  for (Predictor k : all_predictors())
    if (name == to_string(k)) return *p = k, true;
  return false;
}

const char* predictor_names() {
  static const std::string names = [] {
    const std::vector<Predictor>& all = all_predictors();
    std::string s;
    for (std::size_t i = 0; i < all.size(); ++i)
      s += (i == 0 ? "" : i + 1 == all.size() ? " or " : ", ") + std::string(to_string(all[i]));
    return s;
  }();
  return names.c_str();
}

Predictor effective_predictor(Predictor p, bool velocities, bool accelerations) {
  if (p != Predictor::kAuto) return p;
  return accelerations ? Predictor::kCubic : velocities ? Predictor::kHermite : Predictor::kParabolic;
}

bool predictor_needs_velocities(Predictor p) {
  return p == Predictor::kLinear || p == Predictor::kHermite || predictor_needs_accelerations(p);
}

bool predictor_needs_accelerations(Predictor p) { return p == Predictor::kQuadratic || p == Predictor::kCubic; }

namespace detail {

int predictor_history_depth(Predictor p) {
  switch (p) {
    case Predictor::kPrevious:
      return 1;
    case Predictor::kSecant:
      return 2;
    case Predictor::kParabolic:
      return 3;
    case Predictor::kHermite:
      return 3;
    case Predictor::kLinear:
      return 1;
    case Predictor::kQuadratic:
      return 1;
    case Predictor::kCubic:
      return 2;
    case Predictor::kAuto:
      break;
  }
  return 0;
}

namespace {

// The nodes of the divided-difference predictors: tc, t_0, t_1, t_2 (the current row, then the history; the current
// row again where the history is shorter), their rows, and the reciprocals of their spacings, once per step, so that
// the passes multiply (no division per coordinate).
struct Nodes {
  double T[4];
  const double* xs[3];
  double i01, i12, i23, i02, i13, i03;
};

// One prediction at t1 from the current row (tc, q) and the history, formula by formula: each writes the guess of
// every coordinate into `out` and `kept` (ws.q and the sweeper's copy for jumped()) and gathers what the step's error
// estimate adds up (start_error()). Apart from the Sweeper so that each formula is read on its own, with only the
// inputs it uses; every formula runs one pass over the coordinates.
class Extrapolation {
 public:
  Extrapolation(const Model& model, const PredictorHistory& history, const State& current, double current_error,
                double t1, double tol, double* out, double* kept)
      : history_(history),
        n_(current.q.size()),
        h_(t1 - current.t),
        tc_(current.t),
        t1_(t1),
        tol_(tol),
        cs_(model.tolerance_scales().coordinate_scale.data()),
        out_(out),
        kept_(kept),
        q_(current.q.data()),
        k_(history.known),
        error_at_current_(current_error),
        inherited_(current_error) {}

  // previous, secant, parabolic: Newton's divided differences of q over tc, t_0, t_1, t_2, the polynomial of the
  // predictor's order through the last rows, and its next term as the error. Returns whether it moved off q.
  bool divided_differences(Predictor p);
  // hermite: the cubic through the current row (position and velocity v) and the two rows before.
  bool hermite(const double* v);
  // linear: q + h q̇, erring by h²/2 q̈ (q̈ from the last two q̇).
  bool linear(const double* v);
  // quadratic, cubic: the Taylor polynomial in q̇, q̈ (and q⃛ from the last two q̈).
  bool taylor(const double* v, const double* a, bool cubic);

  // The prediction is as far from the solution as the rows it extrapolates (how well each was solved) plus the
  // extrapolation's own error; accepted without a Newton step, its error becomes the next row's to carry. So the
  // error budget adds up over steps taken without Newton until it exceeds the tolerance, and a step resets it.
  // Infinite until the history has a row beyond what the formula needs (Newton then takes a step).
  double start_error() const { return estimated_ ? inherited_ + worst_.worst : INFINITY; }

 private:
  const double* x(int i) const { return history_.rows[static_cast<std::size_t>(i)].data(); }
  double th(int i) const { return history_.t[static_cast<std::size_t>(i)]; }
  // the estimated error of q at the row of node i (0: the current row)
  double row_error(int i) const { return i == 0 ? error_at_current_ : history_.error[static_cast<std::size_t>(i - 1)]; }
  // f(j, &error) returns the prediction of coordinate j and sets its error estimate.
  template <class F>
  void each(F&& f) {
    for (Index j = 0; j < n_; ++j) {
      double e = 0.0;
      const double p = f(j, e);
      out_[j] = kept_[j] = p;
      worst_.add(std::fabs(e), tol_ * cs_[j] + ToleranceScales::kUlpFloor * std::fabs(p));
    }
  }
  Nodes nodes() const {
    auto inv = [](double d) { return d != 0.0 ? 1.0 / d : 0.0; };
    const int k = k_;
    const double tc = tc_;
    Nodes nd{{tc, k > 0 ? th(0) : tc, k > 1 ? th(1) : tc, k > 2 ? th(2) : tc},
             {k > 0 ? x(0) : q_, k > 1 ? x(1) : q_, k > 2 ? x(2) : q_},
             0,
             0,
             0,
             0,
             0,
             0};
    const double* T = nd.T;
    nd.i01 = inv(T[0] - T[1]), nd.i12 = inv(T[1] - T[2]), nd.i23 = inv(T[2] - T[3]);
    nd.i02 = inv(T[0] - T[2]), nd.i13 = inv(T[1] - T[3]), nd.i03 = inv(T[0] - T[3]);
    return nd;
  }

  const PredictorHistory& history_;
  const Index n_;
  const double h_, tc_, t1_, tol_;
  const double* cs_;  // the coordinates' tolerance scales
  double* out_;
  double* kept_;
  const double* q_;
  const int k_;                    // rows of history known
  const double error_at_current_;  // the estimated error of q at the current row
  WorstRatio worst_;               // the largest error estimate, in units of the tolerance test
  bool estimated_ = true;          // the history holds a row beyond the formula's, for its next term
  double inherited_;               // the error of the rows extrapolated from, carried into the prediction
};

bool Extrapolation::divided_differences(Predictor p) {
  const int k = k_;
  const double h = h_, t1 = t1_;
  const double* q = q_;
  const int order = std::min(p == Predictor::kPrevious ? 0 : p == Predictor::kSecant ? 1 : 2, k);
  estimated_ = k > order;
  const bool estimated = estimated_;
  const int terms = order + (estimated ? 1 : 0);
  inherited_ = 0.0;
  const Nodes nd = nodes();
  const double* T = nd.T;
  const double* const* xs = nd.xs;
  const double i01 = nd.i01, i12 = nd.i12, i23 = nd.i23, i02 = nd.i02, i13 = nd.i13, i03 = nd.i03;
  const double w1 = h, w2 = w1 * (t1 - T[1]), w3 = w2 * (t1 - T[2]);
  // the rows' own errors carry over with the weights of Lagrange's polynomial through them at t1
  for (int i = 0; i <= order; ++i) {
    double w = 1.0;
    for (int l = 0; l <= order; ++l)
      if (l != i) w *= (t1 - T[l]) / (T[i] - T[l]);
    inherited_ += std::fabs(w) * row_error(i);
  }
  each([&](Index j, double& e) {
    const double v0 = q[j];
    if (terms == 0) return v0;
    const double d01 = (v0 - xs[0][j]) * i01;
    double p = v0, next = w1 * d01;
    if (terms >= 2) {
      const double d12 = (xs[0][j] - xs[1][j]) * i12;
      const double d012 = (d01 - d12) * i02;
      p += w1 * d01, next = w2 * d012;
      if (terms >= 3) {
        const double d23 = (xs[1][j] - xs[2][j]) * i23;
        const double d123 = (d12 - d23) * i13;
        p += w2 * d012, next = w3 * (d012 - d123) * i03;
      }
    }
    if (estimated)
      e = next;
    else
      p += next;  // the highest term is the prediction's own, with no estimate beyond it
    return p;
  });
  return order > 0;
}

bool Extrapolation::hermite(const double* v) {
  // Hermite divided differences over the nodes tc, tc, t_0, t_1, t_2 (f[tc] = q, f[tc, tc] = q̇)
  const int k = k_;
  const double h = h_, t1 = t1_;
  const double* q = q_;
  const int order = std::min(3, k + 1);  // Newton terms after q: (t − tc) q̇, then one per row of history
  estimated_ = k > 2;
  const bool estimated = estimated_;
  const int terms = order + (estimated ? 1 : 0);
  const Nodes nd = nodes();
  const double* T = nd.T;
  const double* const* xs = nd.xs;
  const double i01 = nd.i01, i12 = nd.i12, i23 = nd.i23, i02 = nd.i02, i13 = nd.i13, i03 = nd.i03;
  const double w1 = h, w2 = w1 * h, w3 = w2 * (t1 - T[1]), w4 = w3 * (t1 - T[2]);
  // Each term as a function of the positions q, q_0, q_1, q_2 (and q̇), so that the rows' own errors carry
  // over with the weights the prediction gives them: found by evaluating it on unit values.
  auto eval = [&](const double* f, double fd, double* next) {
    double p = f[0] + w1 * fd, nx = 0.0;
    if (terms >= 2) {
      const double a1 = (f[0] - f[1]) * i01;  // f[tc, t_0]
      const double b0 = (fd - a1) * i01;      // f[tc, tc, t_0]
      double add = w2 * b0;
      if (terms >= 3) {
        const double a2 = (f[1] - f[2]) * i12;  // f[t_0, t_1]
        const double b1 = (a1 - a2) * i02;      // f[tc, t_0, t_1]
        const double c0 = (b0 - b1) * i02;      // f[tc, tc, t_0, t_1]
        p += add, add = w3 * c0;
        if (terms >= 4) {
          const double a3 = (f[2] - f[3]) * i23;  // f[t_1, t_2]
          const double b2 = (a2 - a3) * i13;      // f[t_0, t_1, t_2]
          const double c1 = (b1 - b2) * i03;      // f[tc, t_0, t_1, t_2]
          const double d0 = (c0 - c1) * i03;      // f[tc, tc, t_0, t_1, t_2]
          p += add, add = w4 * d0;
        }
      }
      if (estimated)
        nx = add;
      else
        p += add;  // the highest term is the prediction's own, with no estimate beyond it
    }
    if (next) *next = nx;
    return p;
  };
  inherited_ = 0.0;
  for (int i = 0; i <= std::min(k, 2); ++i) {
    double unit[4] = {0.0, 0.0, 0.0, 0.0};
    unit[i] = 1.0;
    inherited_ += std::fabs(eval(unit, 0.0, nullptr)) * row_error(i);
  }
  each([&](Index j, double& e) {
    const double f[4] = {q[j], xs[0][j], xs[1][j], xs[2][j]};
    return eval(f, v[j], &e);
  });
  return true;
}

bool Extrapolation::linear(const double* v) {
  const int k = k_;
  const double h = h_;
  const double* q = q_;
  estimated_ = k > 0;
  const double c = estimated_ ? 0.5 * h * h / (tc_ - th(0)) : 0.0;
  const double* v0 = estimated_ ? x(0) : v;
  each([&](Index j, double& e) {
    e = c * (v[j] - v0[j]);  // h²/2 q̈, q̈ from the last two q̇
    return q[j] + h * v[j];
  });
  return true;
}

bool Extrapolation::taylor(const double* v, const double* a, bool cubic) {
  const int k = k_;
  const double h = h_, tc = tc_;
  const double* q = q_;
  cubic = cubic && k > 0;
  estimated_ = k > (cubic ? 1 : 0);
  const bool estimated = estimated_;
  const double hh = 0.5 * h * h, h3 = h * h * h / 6.0;
  const double dt0 = k > 0 ? tc - th(0) : 1.0, i_dt0 = 1.0 / dt0;
  const double i_dt1 = k > 1 ? 1.0 / (th(0) - th(1)) : 1.0;
  const double* a0 = k > 0 ? x(0) : a;
  const double* a1 = k > 1 ? x(1) : a;
  // cubic: q⃛ ≈ (q̈ − q̈_0) / (tc − t_0), which errs by (tc − t_0)/2 q⁗; with the Taylor remainder the
  // prediction errs by h³ (h/24 + (tc − t_0)/12) q⁗, q⁗ ≈ 2 q̈[tc, t_0, t_1] (Newton's divided difference)
  const double ce = h * h * h * (h / 24.0 + dt0 / 12.0) * 2.0 / (tc - (k > 1 ? th(1) : tc - 1.0));
  each([&](Index j, double& e) {
    double p = q[j] + h * v[j] + hh * a[j];
    if (k > 0) {
      const double jerk = (a[j] - a0[j]) * i_dt0;
      if (cubic) {
        p += h3 * jerk;
        if (estimated) e = ce * (jerk - (a0[j] - a1[j]) * i_dt1);
      } else {
        e = h3 * jerk;
      }
    }
    return p;
  });
  return true;
}

}  // namespace

// ws.q = the predictor's guess at t1 from the current state and the history (kept in prediction_.q for jumped()),
// and newton_.start_error = the size of the next term of the extrapolation in units of the tolerance test — its
// error estimate, from one more row of history than the prediction needs (infinite until there is one, so that
// Newton then takes a step). One pass over the vectors.
void Sweeper::predict(double t1) {
  const Index n = current_.q.size();
  ws_->q.resize(n);
  prediction_.q.resize(n);
  if (current_.t == singular_.branch_t && singular_.branch_qd.size() == n) {
    // positions only, from a singular start: along the branch's own q̇ and q̈ there (singular_point()), which no
    // history of positions tells; Newton then takes its steps (no error estimate).
    const double h = t1 - current_.t, hh = 0.5 * h * h;
    for (Index j = 0; j < n; ++j)
      ws_->q[j] = prediction_.q[j] = current_.q[j] + h * singular_.branch_qd[j] + hh * singular_.branch_qdd[j];
    prediction_.moved = true;
    newton_.start_error = INFINITY;
    return;
  }
  Extrapolation x(model_, history_, current_, current_accuracy_.error, t1, opt_.newton.tolerance, ws_->q.data(),
                  prediction_.q.data());
  switch (predictor_) {
    case Predictor::kPrevious:
    case Predictor::kSecant:
    case Predictor::kParabolic:
      prediction_.moved = x.divided_differences(predictor_);
      break;
    case Predictor::kHermite:
      prediction_.moved = x.hermite(current_.qd.data());
      break;
    case Predictor::kLinear:
      prediction_.moved = x.linear(current_.qd.data());
      break;
    case Predictor::kQuadratic:
    case Predictor::kCubic:
      prediction_.moved = x.taylor(current_.qd.data(), current_.qdd.data(), predictor_ == Predictor::kCubic);
      break;
    case Predictor::kAuto:
      break;
  }
  newton_.start_error = x.start_error();
}

}  // namespace detail

}  // namespace phiq
