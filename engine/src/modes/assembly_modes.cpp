// find_assembly_modes() (phiq/modes.hpp): the model's polynomial system solved, its real solutions mapped back to
// the model's coordinates and checked on the model's own equations.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "modes/homotopy.hpp"

namespace phiq {

AssemblyModes find_assembly_modes(const Model& model, const ModesOptions& options) {
  AssemblyModes out;
  out.polynomials = find_polynomial_system(model, options);
  if (out.polynomials.status != ModesStatus::kSuccess) {
    out.summary.status = out.polynomials.status;
    out.summary.message = out.polynomials.message;
    return out;
  }
  const PolynomialSystem& system = out.polynomials.system;
  if (system.variables == 0) {  // every coordinate fixed by its own row: one assembly
    AssemblyMode mode;
    mode.q = out.polynomials.coordinates(Eigen::VectorXcd());
    out.modes.push_back(mode);
    out.summary.real = 1;
  } else {
    out.summary = solve_polynomial_system(system, options);
    if (out.summary.status == ModesStatus::kNotSquare)
      out.summary.message = "the drivers leave the mechanism free (" + out.summary.message +
                            "): drive every freedom to count its assemblies";
    if (out.summary.status != ModesStatus::kSuccess) return out;
  }
  const ToleranceScales& scales = model.tolerance_scales();
  std::vector<double> phi(static_cast<std::size_t>(model.num_equations()));
  for (const Endpoint& e : out.summary.endpoints) {
    if (e.kind != EndpointKind::kReal && e.kind != EndpointKind::kSingular) continue;
    if (e.kind == EndpointKind::kSingular &&
        !(e.x.imag().cwiseAbs().maxCoeff() <= 1e3 * options.real_tolerance * (1.0 + e.x.cwiseAbs().maxCoeff())))
      continue;  // a complex singular solution
    AssemblyMode mode;
    mode.q = out.polynomials.coordinates(e.x);
    mode.condition = e.condition;
    mode.singular = e.kind == EndpointKind::kSingular;
    model.residual(mode.q.data(), options.time, phi.data());
    for (std::size_t i = 0; i < phi.size(); ++i)
      mode.residual = std::max(mode.residual, std::abs(phi[i]) / scales.row_scale(static_cast<Eigen::Index>(i)));
    out.modes.push_back(std::move(mode));
  }
  return out;
}

double mode_distance(const Model& model, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double d = 0.0;
  for (Index j = 0; j < model.num_coordinates(); ++j) {
    double diff = a(j) - b(j);
    if (model.coordinate_unit(j) == Unit::kAngle)
      diff = std::remainder(diff, 2.0 * std::numbers::pi);
    else if (model.coordinate_unit(j) == Unit::kLength)
      diff /= model.length_scale();
    d = std::max(d, std::abs(diff));
  }
  return d;
}

ModeLocation locate_mode(const Model& model, const Eigen::VectorXd& q, const std::vector<AssemblyMode>& modes) {
  ModeLocation where;
  for (std::size_t k = 0; k < modes.size(); ++k) {
    const double d = mode_distance(model, q, modes[k].q);
    const int index = static_cast<int>(k);
    if (where.mode < 0 || d < where.distance) {
      where.next = where.mode, where.next_distance = where.distance;
      where.mode = index, where.distance = d;
    } else if (where.next < 0 || d < where.next_distance) {
      where.next = index, where.next_distance = d;
    }
  }
  return where;
}

}  // namespace phiq
