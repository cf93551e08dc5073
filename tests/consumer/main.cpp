// An embedding simulator in miniature, built against the installed phiq package: it builds a four-bar in code
// (natural coordinates + a driven crank angle), advances its own clock, calls the position, velocity and
// acceleration solves each tick, and checks the results against Freudenstein's closed form and finite
// differences of its own positions, and that the version macros, constant and function of its headers and library
// agree; and a part's geometry (a box's mass, the mesh reader that links Assimp). Exit 0 when every check holds.
#include <phiq/phiq.hpp>
#include <phiq/shapes.hpp>

#if !defined(PHIQ_VERSION_MAJOR) || !defined(PHIQ_VERSION_MINOR) || !defined(PHIQ_VERSION_PATCH)
#error "phiq/version.hpp defines PHIQ_VERSION_MAJOR, _MINOR and _PATCH"
#endif
#if PHIQ_VERSION_MAJOR == 0 && PHIQ_VERSION_MINOR < 1
#error "this consumer needs phiq 0.1 or later"
#endif

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

int main() {
  using namespace phiq;
  const double a = 0.4, b = 1.2, c = 1.0, d = 1.0, omega = 1.5;  // crank, coupler, rocker, ground; rad/s
  ModelBuilder mb;
  const Index xa = mb.add_coordinate("xA", 0.38), ya = mb.add_coordinate("yA", 0.05), xb = mb.add_coordinate("xB", 1.1),
              yb = mb.add_coordinate("yB", 0.95), th = mb.add_coordinate("theta2", 0.0);
  const auto S = Slot::coordinate;
  const auto C = Slot::constant;
  const Point2 O{C(0), C(0)}, A{S(xa), S(ya)}, B{S(xb), S(yb)}, Cc{C(d), C(0)};
  mb.add("crank", DistanceSpec{O, A, a});
  mb.add("coupler", DistanceSpec{A, B, b});
  mb.add("rocker", DistanceSpec{Cc, B, c});
  mb.add("crank_angle", SegmentAngleSpec{O, A, S(th)});
  mb.add_driver("motor", th, MotionLaw::linear(0.0, omega));
  const Model model = std::move(mb).build();
  Workspace ws(model);

  const double K1 = d / a, K2 = d / c, K3 = (a * a - b * b + c * c + d * d) / (2 * a * c);
  double worst_angle = 0, worst_vel = 0;
  double xb_2 = 0, xb_1 = 0, vb_1 = 0;  // x_B two ticks ago, one tick ago, and ẋ_B one tick ago
  int ticks = 0;
  for (int k = 0; k <= 400; ++k) {  // the simulator's own clock
    const double t = 0.01 * k;
    if (solve_position(model, t, NewtonOptions{}, ws) != SolveStatus::kSuccess ||
        solve_velocity(model, t, ws) != SolveStatus::kSuccess ||
        solve_acceleration(model, t, ws) != SolveStatus::kSuccess) {
      std::fprintf(stderr, "consumer: solve failed at t = %g\n", t);
      return 1;
    }
    const double th2 = ws.q(th);
    const double A_ = std::cos(th2) - K1 - K2 * std::cos(th2) + K3, B_ = -2 * std::sin(th2),
                 C_ = K1 - (K2 + 1) * std::cos(th2) + K3;
    const double th4 = 2 * std::atan2(-B_ - std::sqrt(B_ * B_ - 4 * A_ * C_), 2 * A_);  // open branch
    worst_angle = std::max(worst_angle, std::fabs(std::remainder(std::atan2(ws.q(yb), ws.q(xb) - d) - th4, 2 * M_PI)));
    if (k >= 2)  // ẋ_B one tick ago against the central difference of the positions around it (O(h²))
      worst_vel = std::max(worst_vel, std::fabs((ws.q(xb) - xb_2) / 0.02 - vb_1));
    xb_2 = xb_1;
    xb_1 = ws.q(xb);
    vb_1 = ws.qd(xb);
    ++ticks;
  }
  // a part's geometry: a box's mass, and the mesh reader refusing a file that is not there, naming it (Assimp, a
  // private dependency that a static libphiq brings to this link)
  Shape box;
  box.size = {0.1, 0.2, 0.5};
  const double box_mass = shape_mass_properties(box, 1000.0).mass;
  std::string mesh_refusal = "(no error)";
  try {
    load_mesh_file("no_such_part.stl");
  } catch (const Error& e) {
    mesh_refusal = e.what();
  }
  if (std::fabs(box_mass - 10.0) > 1e-12 || mesh_refusal.rfind("no_such_part.stl: cannot read", 0) != 0) {
    std::fprintf(stderr, "consumer: box mass %.17g (10 kg), mesh reader: %s\n", box_mass, mesh_refusal.c_str());
    return 1;
  }
  // the library's own version (version()) is the headers' (kVersion), and the macros spell it
  const std::string macros = std::to_string(PHIQ_VERSION_MAJOR) + "." + std::to_string(PHIQ_VERSION_MINOR) + "." +
                             std::to_string(PHIQ_VERSION_PATCH);
  if (std::strcmp(version(), kVersion) != 0 || macros != kVersion) {
    std::fprintf(stderr, "consumer: version() %s, kVersion %s, macros %s\n", version(), kVersion, macros.c_str());
    return 1;
  }
  std::printf("consumer: phiq %s, %d ticks, worst rocker angle error %.2e rad, velocity vs difference %.2e\n",
              version(), ticks, worst_angle, worst_vel);
  return (ticks == 401 && worst_angle < 1e-10 && worst_vel < 1e-3) ? 0 : 1;
}
