/// @file
/// Sensitivities of the drivers' efforts to design parameters, ∂τ/∂p: which dimension or mass lowers the peak torque.
///
/// A driver's effort is τ = −λ_r, λ the multipliers of Φqᵀ λ = Q(q, q̇, q̈, p) (phiq/inverse_dynamics.hpp), r its
/// first row. With w = Φq⁻¹ e_r (one solve with the row's factors, per driver), τ = −wᵀ Q, and differentiating
/// totally along p, with q, q̇, q̈ moving along their sensitivities s, ṡ, s̈ (phiq/sensitivity.hpp):
///
///   dτ/dp = λᵀ (dΦq/dp) w − wᵀ dQ/dp,
///
///   (dΦq/dp) w = ∂(Φq w)/∂p |q  +  H(s, w),        H(u, v) = (Φq u)_q v, the second derivative of Φ,
///   dQ/dp      = ∂Q/∂p |q,q̇,q̈  +  Q_q s + Q_q̇ ṡ + Q_q̈ s̈.
///
/// No transposed product with Φq along p is needed: ∂(Φq w)/∂p is the velocity term's derivative along p (as the
/// sensitivities take it, over the constraints p reaches, exactly where the kinds differentiate their own data) at
/// q̇ = ±w, halved; H(s, w) is exact from γ, a quadratic in q̇ at fixed q whose polarisation
///
///   H(a, b) = −[γ(a + b) + γ(−a − b) − γ(a − b) − γ(b − a)] / 8
///
/// cancels Φqt and Φtt (four evaluations of γ at q itself, no step). dQ/dp is exact too (parts/force_rate.hpp): Q
/// again in dual numbers through the parts' frame jets, every pose, Jacobian column, velocity, acceleration and load
/// carried with its rate along s, ṡ, s̈; what p changes of the parts and loads themselves (a mass, a centre, an
/// inertia, a ground point of a frame, gravity, a load's point, expression or constants) by the rates of those data
/// between the scene read at p ± h, p ± 2h (OutputSensitivity::parts_along; exact for data linear in p); a
/// torsional spring's angle with its second derivatives, by the polarisation of γ for an expression and of the
/// joint's acceleration in q̇ for a spatial joint's angle; a frame of expressions (relative angles) by its
/// expressions' second-order Taylor pass in dual numbers along (q + ε s, q̇ + ε ṡ, q̈ + ε s̈), their third
/// derivatives included, and its copies' jets along p. Where the scene read along p is not the same structure (a
/// frame of another kind or coordinates, a load's count, an expression present in one copy only), Q is
/// differenced (along p by the fourth-order difference over the copies, along the motion with a step that moves
/// the coordinate s moves most by 10⁻³ of its scale; ~10⁻¹² relative). A co-moving coordinate
/// (ParameterReach::comotion) is moved along p as the sensitivities move it.
///
/// With a bearing's friction or a gear's losses (their moments m_i read λ: solve/friction_losses.hpp), λ solves
/// Φqᵀ λ = Q + Q_f(λ, q, p), and the same holds with w̃ for w, (Φq − (∂Q_f/∂λ)ᵀ) w̃ = e_r (the fixed point's adjoint,
/// solved in passes that contract as the losses' own did), and dQ/dp + dQ_f/dp at fixed λ for dQ/dp: Q_f at
/// q ± ε (s − q̂), ±2ε, and with the losses' data of the scene at p ± h, ±2h, each a fourth-order difference, the
/// friction's directions held. A parameter of a loss's own joint or ratio (a spatial joint's axes, a slide's line, a
/// mesh's ratio, which split its load otherwise) is refused by name; a planar pin's journal reads λ alone. At a row
/// where a bearing's turn passes zero its friction's sign flips and τ has no derivative.
///
/// A driver's power P = Σ λ_r Φt_r over its rows: dP/dp = Σ (dλ_r/dp Φt_r + λ_r dΦt_r/dp), dλ_r/dp as −dτ/dp above
/// with w = Φq⁻¹ e_r for each row, and dΦt/dp = ∂Φt/∂p |q + Φqt (s − q̂), the latter −[γ(a) − γ(−a)]/4 at a = s − q̂.
///
/// Cost per written row: one direct solve per driver row, and per parameter 1 evaluation of Q in dual numbers (8 of Q
/// where differenced), 3 of the velocity term over the reach and 2 of γ, and per driver row 2 of the velocity term
/// and 4 of γ; the sensitivities of q, q̇, q̈ in the direct form (every coordinate's).
#pragma once

#include <string>
#include <vector>

#include "phiq/kinematics.hpp"
#include "phiq/output_plan.hpp"
#include "phiq/workspace.hpp"

namespace phiq {

/// Values of the efforts' and powers' sensitivities: effort i (of OutputEfforts::constraints) to parameter j at
/// `j·efforts + i`, then, after every effort's, power i to parameter j.
struct EffortSensitivityLayout {
  std::size_t efforts = 0;  ///< OutputEfforts::constraints.size()
  /// Offset of ∂τ_i/∂p_j.
  std::size_t offset(std::size_t j, std::size_t i) const { return j * efforts + i; }
  /// Offset of ∂P_i/∂p_j among the values for `parameters` parameters.
  std::size_t power_offset(std::size_t parameters, std::size_t j, std::size_t i) const {
    return (parameters + j) * efforts + i;
  }
  /// Values for `parameters` parameters: ∂τ/∂p, then ∂P/∂p.
  std::size_t size(std::size_t parameters) const { return 2 * parameters * efforts; }
};

/// ∂τ/∂p and ∂P/∂p of each driver of `efforts` (OutputEfforts::constraints) to each of `parameters`, at the motion in
/// `ws` (q, q̇, q̈ solved at t), into `out` (EffortSensitivityLayout, resized): solves the sensitivities (direct form,
/// order 2) and the multipliers with one factorisation of Φq at ws.q (the file comment). The parts and loads along
/// a parameter are its OutputSensitivity::parts_along / loads_along, or `efforts`' own where those are null (a
/// parameter that reaches the constraints only). NaN for a driver the model dropped as redundant. Returns kSuccess,
/// kSingularJacobian at a singular position (out NaN: τ is unbounded there), or a factorisation's failure;
/// `message` says why. Throws phiq::Error for the pre-conditions of solve_sensitivities() and a plan whose efforts
/// lack parts or loads. Thread-safe for distinct workspaces.
SolveStatus solve_effort_sensitivities(const Model& model, const OutputEfforts& efforts,
                                       const std::vector<OutputSensitivity>& parameters, double t, Workspace& ws,
                                       std::vector<double>& out, std::string* message = nullptr);

}  // namespace phiq
