// The parts a Sweeper's state falls into (sweeper.hpp): the predictor's history and its last prediction, how well
// a row is known, the singular-position state, the orientation of Φq along the branch, the values of a row's
// outputs, and the per-sweeper buffers of the sensitivities' and efforts' solves. Each is plain data with the
// few operations on it alone; the Sweeper decides when they change.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "phiq/joint_reactions.hpp"
#include "phiq/sweep.hpp"
#include "solve/friction_losses.hpp"
#include "solve/minimum_norm.hpp"
#include "solve/part_forces.hpp"
#include "solve/sensitivity_internal.hpp"

namespace phiq::detail {

// The class of a delivered row in SweepAccuracy, and its estimated error (units of the tolerance test; infinite
// when no solve estimated it).
enum class RowClass { kConverged, kRoundingLevel, kSingular };

// What the predictor extrapolates from (q for the position predictors, q̇ for linear, q̈ for quadratic and cubic)
// at the converged rows before the current one, newest first: `depth` rows kept (predictor_history_depth), `known`
// of them valid. Its own type so that the predictor formulas (predictors.cpp) read it without the Sweeper.
struct PredictorHistory {
  std::vector<Eigen::VectorXd> rows;
  std::vector<double> t;      // their times
  std::vector<double> error;  // the estimated error of q at those rows (units of the tolerance test)
  int depth = 0, known = 0;

  // depth rows of n zeros: every buffer the states rotate through has the workspace's size from the start, so that
  // a swap never hands the workspace an empty vector.
  void size(int rows_kept, Index n) {
    depth = rows_kept;
    rows.assign(static_cast<std::size_t>(depth), Eigen::VectorXd::Zero(n));
    t.resize(static_cast<std::size_t>(depth));
    error.resize(static_cast<std::size_t>(depth));
  }
  // The row at time `at` enters as the newest by a buffer swap: `x` gets the oldest row's buffer, which the caller
  // overwrites without allocating.
  void push(Eigen::VectorXd& x, double at, double x_error) {
    if (depth == 0) return;
    std::rotate(rows.rbegin(), rows.rbegin() + 1, rows.rend());
    std::rotate(t.rbegin(), t.rbegin() + 1, t.rend());
    rows[0].swap(x);
    t[0] = at;
    std::rotate(error.rbegin(), error.rbegin() + 1, error.rend());
    error[0] = x_error;
    known = std::min(known + 1, depth);
  }
};

// The last prediction (predict()), which jumped() compares the converged position with.
struct LastPrediction {
  Eigen::VectorXd q;
  bool moved = false;  // it moved from the current state (else nothing was predicted: jumped() has nothing to say)
};

// How well a row's position is known: its estimated error (PositionSummary::error_estimate, units of the tolerance
// test; infinite when unknown), the coordinate where it is reached (error_coordinate, −1 if not said) and its size
// there (error_size), and how the row's Newton ended.
struct RowAccuracy {
  double error = INFINITY;
  Index coordinate = -1;
  double known_to = 0.0;
  RowClass row_class = RowClass::kConverged;
};

// The singular-position state (singular_positions.cpp).
struct SingularState {
  bool bracketing = false;  // inside singular_point(): no nested bracketing
  bool at_row = false;      // the current state is a singular position (its derivatives bracketed)
  // Positions only, at a singular start: the branch's q̇ and q̈ there (singular_point()) and its time; the first
  // prediction from that row extrapolates along them (predict()), NaN once used.
  Eigen::VectorXd branch_qd, branch_qdd;
  double branch_t = NAN;
};

// A sign of det Φq is ±1 at a regular position and 0 at a singular one; kSignUnknown where no factorisation tells
// it (positions only, a start accepted from its prediction).
constexpr int kSignUnknown = 2;

// Which way Φq is oriented at a factorisation: det Φq's sign, and at a regular position the fingerprint of the
// signs of its diagonal blocks' determinants (SparseLuNumeric::block_signs(): KLU factorises a chain loop by
// loop). Along a branch it changes exactly where the motion passes a singular position: det Φq's sign alone misses
// an even number of loops crossing at once (nfourbar of even N through its flat position), the blocks do not.
struct Orientation {
  int sign = kSignUnknown;
  std::uint64_t blocks = 0;
  bool regular() const { return sign == 1 || sign == -1; }
  bool operator==(const Orientation& o) const { return sign == o.sign && blocks == o.blocks; }
  bool operator!=(const Orientation& o) const { return !(*this == o); }
};
inline Orientation orientation_of(const SparseLuNumeric& lu) {
  const int sign = lu.determinant_sign();
  return {sign, sign == 1 || sign == -1 ? lu.block_signs() : 0};
}

// The orientation of Φq along the branch: the bifurcation check between rows (converged(), row_outputs()).
struct BranchOrientation {
  Orientation delivered{0, 0};  // at the last delivered row (det_sign())
  double delivered_t = 0.0;     // and the time it holds at
  Orientation current;          // at the current state (sign_at_solution() when it converged)
  Orientation current_row;      // what the current state's row reports (converged()), and at which time
  double current_row_t = 0.0;
};

// The values of a written row's outputs beyond q, q̇, q̈ (row_outputs()), sized by the output plan once.
struct RowOutputValues {
  RowOutputValues(const Model& model, const SweepOptions& opt)
      : points(opt.points.size()),
        joints(opt.joints.size()),
        orientations(opt.orientations.size()),
        sensitivities(
            static_cast<std::size_t>(SensitivityLayout{model.num_coordinates()}.size(opt.sensitivities.size()))),
        efforts(static_cast<std::size_t>(effort_values(opt.efforts, opt.sensitivities.size()))) {}
  std::vector<PointMotion> points;
  std::vector<JointMotion> joints;
  std::vector<OrientationMotion> orientations;
  double rcond = 0.0;
  std::vector<double> sensitivities;  // SensitivityLayout
  std::vector<double> efforts;        // the efforts, powers, reactions and the efforts' sensitivities (effort_values())
};

// The factors of Φq a row's sensitivities and efforts solve with (row_factors()).
struct RowFactorCache {
  // The factors the last derivatives() solved with: its workspace, that workspace's factorisation count then, and
  // the row's time. row_sensitivities() solves with them while they are still the workspace's (no factorisation
  // since) and of the same row.
  struct {
    const Workspace* ws = nullptr;
    Index factorizations = -1;
    double t = NAN;
  } derivatives;
  // Factors at the row where the workspace's are elsewhere; shared by a copy (a Stepper's way back), which never
  // solves at the same time.
  std::shared_ptr<Workspace> own;
};

// The sensitivities' solves (row_sensitivities()): the coordinates whose columns are written, the form they are
// solved in (effective_sensitivity_form) and their scratch.
struct SensitivityWork {
  explicit SensitivityWork(const SweepOptions& opt)
      : outputs(opt.sensitivities.empty() ? std::vector<Index>{} : opt.sensitivity_outputs()),
        form(sweep_sensitivity_form(opt, outputs.size())) {}
  std::vector<Index> outputs;
  SensitivityForm form;
  SensitivityScratch scratch;
};

// The efforts' solves (row_efforts(), row_reactions()): their vectors, the efforts of drivers the model dropped
// (NaN at every row), the joints whose reactions are written (none when none are) and whether the first row has
// said which of them are indeterminate (a model with redundant rows; once per sweep).
struct EffortWork {
  EffortWork(std::vector<std::size_t> dropped_efforts, std::optional<JointReactions> written_reactions)
      : dropped(std::move(dropped_efforts)), reactions(std::move(written_reactions)) {}
  EffortSensitivityScratch sensitivity_scratch;
  Eigen::VectorXd q, kept, lambda, phi_t;    // Q, the kept rows, λ, Φt
  Eigen::VectorXd mesh_q, mesh_lambda;       // the gear meshes' push on their bearings, and its multipliers
  MeshFindings mesh_findings;                // what add_gear_mesh_forces() found at the row
  PartJacobian mesh_jacobian;                // add_gear_mesh_forces()' scratch (spatial pairs' shafts)
  std::shared_ptr<const PartForces> forces;  // Q's parts, gathered once a sweep (Sweeper's constructor)
  // what Q's parts on planar frames added, one per part, when natural joints' reactions read their bodies' (else
  // empty)
  std::vector<PlanarForce> planar;
  std::vector<std::size_t> dropped;
  std::optional<JointReactions> reactions;
  std::optional<FrictionLosses> losses;  // the bearings' friction and the gears' losses, if the loads have any
  bool reactions_noted = false;
  MinimumNormScratch minimum_norm;  // row_reactions()'s, with redundant rows
};

}  // namespace phiq::detail
