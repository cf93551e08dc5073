// find_assembly_modes() (phiq/modes.hpp): the model's polynomial system solved, its real solutions mapped back to
// the model's coordinates and checked on the model's own equations.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "modes/homotopy.hpp"
#include "modes/model_rows.hpp"

namespace phiq {

namespace {
// A real solution whose model residual (relative to the rows' scales) is above this is no assembly: the residuals
// of true ones are at rounding (Newton's refinement), those of a surrogate's extra root of order one (π).
constexpr double kAssemblyResidual = 1e-6;
}  // namespace

AssemblyModes find_assembly_modes(const Model& model, const ModesOptions& options) {
  AssemblyModes out;
  out.polynomials = find_polynomial_system(model, options);
  if (out.polynomials.status != ModesStatus::kSuccess) {
    out.summary.status = out.polynomials.status;
    out.summary.message = out.polynomials.message;
    return out;
  }
  const PolynomialSystem& system = out.polynomials.system;
  const ToleranceScales& scales = model.tolerance_scales();
  std::vector<double> phi(static_cast<std::size_t>(model.num_equations()));
  auto model_residual = [&](const Eigen::VectorXd& q) {
    model.residual(q.data(), options.time, phi.data());
    double largest = 0.0;
    for (std::size_t i = 0; i < phi.size(); ++i)
      largest = std::max(largest, std::abs(phi[i]) / scales.row_scale(static_cast<Eigen::Index>(i)));
    return largest;
  };
  if (system.variables == 0) {  // every coordinate fixed by affine rows: one assembly, if the others hold there
    AssemblyMode mode;
    mode.q = out.polynomials.coordinates(Eigen::VectorXcd());
    mode.residual = model_residual(mode.q);
    if (mode.residual <= kAssemblyResidual) {
      out.modes.push_back(mode);
      out.summary.real = 1;
    } else {
      out.rejected = 1;
    }
  } else {
    std::vector<std::array<int, 4>> euler_variables;  // the bodies whose four Euler parameters are all unknowns
    Eigen::VectorXd offset = Eigen::VectorXd::Zero(system.variables);  // e = q0 + x (unitless: scale 1)
    for (const auto& body : modes_detail::euler_parameter_coordinates(model)) {
      std::array<int, 4> v{};
      for (std::size_t k = 0; k < 4; ++k) v[k] = out.polynomials.variable_of[static_cast<std::size_t>(body[k])];
      if (!std::all_of(v.begin(), v.end(), [](int x) { return x >= 0; })) continue;
      euler_variables.push_back(v);
      for (std::size_t k = 0; k < 4; ++k) offset(v[k]) = out.polynomials.origin(body[k]);
    }
    std::string unsafe;
    if (!options.block_solve ||
        !modes_detail::solve_in_blocks(system, euler_variables, offset, options, out.summary, unsafe)) {
      out.summary = solve_polynomial_system(system, options);
      if (!unsafe.empty()) out.summary.method_note = "the block solve was not safe: " + unsafe;
    }
    if (out.summary.status == ModesStatus::kNotSquare)
      out.summary.message = "the drivers leave the mechanism free (" + out.summary.message +
                            "): drive every freedom to count its assemblies";
    if (out.summary.status != ModesStatus::kSuccess) return out;
  }
  const std::vector<std::array<Index, 4>> euler = modes_detail::euler_parameter_coordinates(model);
  for (const Endpoint& e : out.summary.endpoints) {
    if (e.kind != EndpointKind::kReal && e.kind != EndpointKind::kSingular) continue;
    if (e.kind == EndpointKind::kSingular &&
        !(e.x.imag().cwiseAbs().maxCoeff() <= 1e3 * options.real_tolerance * (1.0 + e.x.cwiseAbs().maxCoeff())))
      continue;  // a complex singular solution
    AssemblyMode mode;
    mode.q = out.polynomials.coordinates(e.x);
    mode.condition = e.condition;
    mode.singular = e.kind == EndpointKind::kSingular;
    // e and −e are one orientation: the sign nearest the placement's
    for (const auto& body : euler) {
      double along = 0.0;
      Index largest = body[0];
      for (Index j : body) {
        along += mode.q(j) * out.polynomials.origin(j);
        if (std::abs(mode.q(j)) > std::abs(mode.q(largest)) + 1e-9) largest = j;
      }
      // a half turn from the placement (along 0): the largest component positive
      if (std::abs(along) <= 1e-9 ? mode.q(largest) < 0.0 : along < 0.0)
        for (Index j : body) mode.q(j) = -mode.q(j);
    }
    mode.residual = model_residual(mode.q);
    if (!(mode.residual <= kAssemblyResidual)) {  // a root of a surrogate row only (model_rows.hpp)
      ++out.rejected;
      continue;
    }
    const bool again = std::any_of(out.modes.begin(), out.modes.end(), [&](const AssemblyMode& other) {
      return mode_distance(model, mode.q, other.q) <= options.duplicate_tolerance;
    });
    if (again) {
      ++out.merged;
      continue;
    }
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
