// Simbody peer of phiq_bench_peers: see SimbodyNFourBar in peers.hpp.
//
// Compiled WITHOUT NDEBUG: Debian 12's libsimbody is built without it, and some of Simbody's inline code (state
// and cache bookkeeping in SimTKcommon's headers) differs with it, so a caller compiled with -DNDEBUG crashes. The
// check below makes a build that forgets it fail instead of crashing at run time.
#ifdef NDEBUG
#error "peer_simbody.cpp must be compiled without NDEBUG (Debian's Simbody crashes otherwise): see bench/CMakeLists.txt"
#endif

#include <time.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "Simbody.h"
#include "peers.hpp"

namespace phiq_bench {

namespace {

// θ(t) = θ0 + ω t prescribed at the position level (so θ̇ and θ̈ are prescribed too).
class CrankAngle : public SimTK::Motion::Custom::Implementation {
 public:
  SimTK::Motion::Level getLevel(const SimTK::State&) const override { return SimTK::Motion::Position; }
  void calcPrescribedPosition(const SimTK::State& s, int nq, SimTK::Real* q) const override {
    if (nq == 1) q[0] = theta_at(s.getTime());
  }
  void calcPrescribedPositionDot(const SimTK::State&, int nq, SimTK::Real* qdot) const override {
    if (nq == 1) qdot[0] = kRate;
  }
  void calcPrescribedPositionDotDot(const SimTK::State&, int nq, SimTK::Real* qdotdot) const override {
    if (nq == 1) qdotdot[0] = 0.0;
  }
};

// The thread's CPU time (s), the clock of phiq_bench_peers.
double thread_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void check(const SimTK::ProjectResults& r, const char* what, double t) {
  if (r.getExitStatus() != SimTK::ProjectResults::Succeeded)
    throw std::runtime_error(std::string("Simbody ") + what + " failed at t = " + std::to_string(t));
}

}  // namespace

struct SimbodyNFourBar::Impl {
  Impl(int n_, Start start_) : n(n_), start(start_), matter(system), forces(system) {
    using namespace SimTK;
    // Unit mass and inertia: the kinematics does not depend on them (the projected system has no free mobility
    // left), but Simbody's acceleration stage solves the dynamics and needs a non-singular mass matrix.
    const Body::Rigid link(MassProperties(1.0, Vec3(0), UnitInertia(1.0)));
    MobilizedBody::Pin crank0(matter.Ground(), Transform(), link, Transform());  // tip at station (1, 0, 0)
    Motion::Custom(crank0, new CrankAngle);
    cranks.push_back(crank0);
    MobilizedBody parent = crank0;
    Vec3 joint(1, 0, 0);  // where the next coupler is pinned on the current crank (its tip)
    for (int i = 1; i <= n; ++i) {
      // coupler i−1 from P_{i−1} (its origin) to P_i (station (1, 0, 0)); crank i from P_i (its origin, the tip)
      // back to its pivot at station (−1, 0, 0), which is closed onto the ground point (i, 0, 0).
      MobilizedBody::Pin coupler(parent, Transform(joint), link, Transform());
      MobilizedBody::Pin crank(coupler, Transform(Vec3(1, 0, 0)), link, Transform());
      Constraint::PointOnLine(matter.Ground(), UnitVec3(ZAxis), Vec3(i, 0, 0), crank, Vec3(-1, 0, 0));
      couplers.push_back(coupler);
      cranks.push_back(crank);
      parent = crank;
      joint = Vec3(0);
    }
    initial = system.realizeTopology();
    // The exact solution at θ0: crank 0 at θ0, couplers at −θ (back to horizontal), cranks i ≥ 1 at +θ; the same
    // for the rates. (From u = 0, Simbody's projectU does not reach 1e-10 at N = 1000: the velocity constraints of a
    // 2001-pin chain are badly conditioned in joint coordinates. phiq and the dense peer solve the velocities of
    // row 0 from scratch; that row is not timed.)
    cranks[0].setOneQ(initial, 0, kTheta0);
    cranks[0].setOneU(initial, 0, kRate);
    for (int i = 0; i < n; ++i) {
      couplers[i].setOneQ(initial, 0, -kTheta0);
      couplers[i].setOneU(initial, 0, -kRate);
      cranks[i + 1].setOneQ(initial, 0, kTheta0);
      cranks[i + 1].setOneU(initial, 0, kRate);
    }
    initial.setTime(0.0);
    qopt.setRequiredAccuracy(kTolerance).setOption(ProjectOptions::UseInfinityNorm);
    uopt = qopt;
    reset();
  }

  void reset() {  // row 0 is not a drive step: its work is not counted
    const long long it = iterations;
    const double acc = acceleration_seconds;
    state = initial;
    solve(0.0);
    iterations = it, acceleration_seconds = acc;
  }

  // Prescribe and project at the state's q as it is (the predictor has already been applied).
  void solve(double t) {
    using namespace SimTK;
    state.setTime(t);
    system.realize(state, Stage::Time);
    system.prescribeQ(state);
    system.realize(state, Stage::Position);
    ProjectResults r;
    system.projectQ(state, no_error_estimate, qopt, r);
    check(r, "projectQ", t);
    iterations += r.getNumIterations();
    system.prescribeU(state);
    system.realize(state, Stage::Velocity);
    system.projectU(state, no_error_estimate, uopt, r);
    check(r, "projectU", t);
    const double t0 = thread_seconds();
    system.realize(state, Stage::Acceleration);
    acceleration_seconds += thread_seconds() - t0;
  }

  void step(double t) {
    const double h = t - state.getTime();
    // pins: q̇ = u, so the quadratic predictor of phiq's sweep is q + h u + h²/2 u̇
    if (start == Start::kQuadratic) state.updQ() += h * state.getU() + (0.5 * h * h) * state.getUDot();
    solve(t);
  }

  Deviation deviation() const {
    using namespace SimTK;
    Deviation d;
    const double t = state.getTime();
    for (int i = 0; i <= n; ++i) {
      const MobilizedBody& c = cranks[i];
      const Vec3 tip_station = i == 0 ? Vec3(1, 0, 0) : Vec3(0);
      const Vec3 pivot_station = i == 0 ? Vec3(0) : Vec3(-1, 0, 0);
      const ExactTip e = exact_tip(i, t);
      const Vec3 p = c.findStationLocationInGround(state, tip_station);
      const Vec3 pivot = c.findStationLocationInGround(state, pivot_station);
      const Vec3 v = c.findStationVelocityInGround(state, tip_station);
      const Vec3 a = c.findStationAccelerationInGround(state, tip_station);
      d.position = std::max({d.position, std::abs(p[0] - e.x), std::abs(p[1] - e.y), std::abs(p[2]),
                             std::abs(pivot[0] - i), std::abs(pivot[1]), std::abs(pivot[2])});
      d.velocity = std::max({d.velocity, std::abs(v[0] - e.vx), std::abs(v[1] - e.vy), std::abs(v[2])});
      d.acceleration = std::max({d.acceleration, std::abs(a[0] - e.ax), std::abs(a[1] - e.ay), std::abs(a[2])});
    }
    return d;
  }

  int n;
  Start start;
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter;
  SimTK::GeneralForceSubsystem forces;  // none: the accelerations are kinematic (no free mobility)
  std::vector<SimTK::MobilizedBody> cranks, couplers;
  SimTK::State initial, state;
  SimTK::ProjectOptions qopt, uopt;
  SimTK::Vector no_error_estimate;  // empty: no integrator error estimate to project
  long long iterations = 0;
  double acceleration_seconds = 0.0;
};

SimbodyNFourBar::SimbodyNFourBar(int n, Start start) : impl_(std::make_unique<Impl>(n, start)) {}
SimbodyNFourBar::~SimbodyNFourBar() = default;
void SimbodyNFourBar::reset() { impl_->reset(); }
void SimbodyNFourBar::step(double t) { impl_->step(t); }
Deviation SimbodyNFourBar::deviation() const { return impl_->deviation(); }
long long SimbodyNFourBar::projection_iterations() const { return impl_->iterations; }
double SimbodyNFourBar::acceleration_seconds() const { return impl_->acceleration_seconds; }
int SimbodyNFourBar::mobilities() const { return impl_->state.getNU(); }
int SimbodyNFourBar::constraint_equations() const { return impl_->state.getNQErr(); }

}  // namespace phiq_bench
