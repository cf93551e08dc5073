/// @file
/// Joint reactions (kinetostatics, after phiq/inverse_dynamics.hpp): the force and moment a joint exerts on one of
/// the bodies it joins, from its rows' multipliers λ. A constraint c acts on the coordinates with the generalized
/// force g = −Φq,cᵀ λ_c; restricted to the coordinates of the body its kind names (ReactionSite,
/// kinds/reaction_site.hpp: side a's body, side b's when a is fixed), g is the virtual work of one wrench on that
/// body, (F, M_O) about the body's origin O, with J_bᵀ (F, M_O) = g for the body's frame Jacobian J_b
/// (part_jacobian(), phiq/part_motion.hpp). The reaction is written about the joint's point P: F and
/// M_P = M_O + (O − P) × F, world axes, or along the joint's own (ReactionSite::axes, when OutputEfforts asks:
/// a bearing's axial and radial loads, a guide's force along and across its slide). The other body receives −F and −M_P
/// (a joint's equations do not change when both bodies move together, so its forces and moments balance).
///
/// Natural coordinates' joints, points two bodies share (phiq/natural_joints.hpp), split the equations at the point
/// among the bodies instead; their moment is zero.
///
/// A model with redundant rows has many λ (the structure is statically indeterminate): minimum_norm_multipliers()
/// takes the one of least norm, and names the constraints whose share is not determined.
///
/// A gear's or a rack's row relates coordinates alone, so under its multiplier the bearings of its members see none
/// of the teeth's push: add_gear_mesh_forces() gives the change of load whose solve with Φqᵀ moves λ to the
/// multipliers under which they do (a sweep does it before evaluating the reactions).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <cstdint>
#include <utility>
#include <vector>

#include "phiq/kinds/reaction_site.hpp"
#include "phiq/linear_solver.hpp"
#include "phiq/model.hpp"
#include "phiq/natural_joints.hpp"
#include "phiq/output_plan.hpp"
#include "phiq/part_motion.hpp"

namespace phiq {

namespace detail {
struct PlanarForce;
struct PlanarFrame;
class BarLengths;
}  // namespace detail

/// How many values constraint c's reaction has: 3 (Fx, Fy, Mz) for a planar joint, 6 for a spatial one, 0 when its
/// kind states no ReactionSite or it has none (ConstraintBlock::states_reaction()). Pre-condition: c is one of the
/// model's constraints.
int reaction_width(const Model& model, Index c);

/// A constraint of a block other than the model's, standing for one of the model's (JointReactions::Along).
struct ReactionBlockAt {
  const ConstraintBlock* block = nullptr;  ///< null: the model's own
  std::size_t index = 0;                   ///< in `block`
};

/// The reactions of a list of joints, evaluated at any (q, t, λ): built once per model (which block holds each
/// constraint, which coordinates it reads), with scratch for evaluate(). Not thread-safe: one per thread.
class JointReactions {
 public:
  /// A constraint of a block other than the model's, standing for one of the model's.
  using BlockAt = ReactionBlockAt;
  /// The constraints an evaluate() reads from a model along a design parameter (their rows and Jacobian entries the
  /// model's: its copies, or the constraint with its data moved), where the losses' derivative along p reads the
  /// reactions under the same λ (detail::FrictionLosses::force_rate()). Made by along().
  struct Along {
    std::vector<BlockAt> sites;  ///< per constraint site (empty: none read elsewhere)
    /// A natural body's own constraint read elsewhere.
    struct Own {
      const ConstraintBlock* block = nullptr;  ///< the model's block
      std::size_t index = 0;                   ///< the constraint's index there
      BlockAt at;                              ///< where it is read
    };
    std::vector<Own> own;  ///< the natural bodies' own constraints read elsewhere
  };
  /// Pre-condition: each of `constraints` has a reaction (reaction_width() > 0); else phiq::Error naming it.
  JointReactions(const Model& model, std::vector<Index> constraints);
  /// The reactions `efforts` lists (OutputEfforts::reactions, in order): a constraint's, or a natural joint's of
  /// OutputEfforts::natural. Pre-condition: as above for the constraints; a natural joint's index is one of
  /// `natural`'s joints (else phiq::Error). `rigid_bars`: evaluate()'s `planar` is left by a Q that takes rigid bars'
  /// constant mass matrices (internal: a sweep's, solve/part_forces.hpp).
  JointReactions(const Model& model, const OutputEfforts& efforts, bool rigid_bars = false);
  /// The joints `other` lists, its set-up (sites, columns, bodies) copied rather than found again in the model, with
  /// scratch of its own: a sweep's chunks each evaluate on their own thread. Safe while `other` evaluates on
  /// another thread (its set-up is not written after construction).
  static JointReactions with_set_up_of(const JointReactions& other) { return JointReactions(other, SetUpOnly{}); }
  /// The values evaluate() writes: per constraint, Fx, Fy, Mz (N, N·m) for a planar joint, Fx, Fy, Fz, Mx, My, Mz
  /// for a spatial one.
  Index size() const { return set_->size; }
  /// Whether the k-th listed joint is spatial (6 values) rather than planar (3).
  bool spatial(std::size_t k) const { return set_->sites[k].spatial; }
  /// Whether evaluate()'s `planar` may come from a Q with rigid bars: as constructed, unless a natural body with
  /// mass on a bar does not own the bar's row (internal: the sweep then takes no bar in Q).
  bool rigid_bars() const { return set_->rigid_bars; }
  /// Which of OutputEfforts::parts' planar forces evaluate() reads from `planar` with `sum_bars`: one flag per part
  /// (`parts` of them; internal: a sweep's Q leaves the others unwritten). Without sum_bars, a site whose part's
  /// force was left unwritten takes the general path: the same bits.
  std::vector<char> planar_parts_read(std::size_t parts) const;
  /// Writes the reactions at (q, t) under multipliers `lambda` (one per model row) to out[0, size()).
  /// Pre-condition: q has the model's coordinates; the model is the one given to the constructor.
  /// No natural joint may be listed (they read q̇ and q̈: the overload below; else phiq::Error).
  /// `along`: constraints read elsewhere (Along).
  void evaluate(const double* q, double t, const Eigen::VectorXd& lambda, double* out, const Along* along = nullptr);
  /// The same at the motion (q, q̇, q̈, t), which natural joints read (their bodies' inertia). `planar`, when not
  /// null, is what detail::PartForces::add() left of OutputEfforts::parts' forces at this (q, q̇, q̈, t) (internal: a
  /// sweep's, whose Q has computed them): a natural body's part's weight and inertia are read there rather than
  /// computed again, the same values bit for bit. Pre-condition: λ solves Φqᵀ λ = Q with that Q when `planar` is
  /// given (with rigid bars as constructed: they move their own rows' multipliers), else with
  /// add_generalized_forces()'. With `planar` and `sum_bars`, a rigid bar's simple site (a point of the bar whose
  /// reaction is one of its force's values) sums that value from q̈ itself, bit for bit (its part's PlanarForce is
  /// not read: planar_parts_read() leaves it out); without `sum_bars` it reads it, as every other site.
  void evaluate(const double* q, const double* qd, const double* qdd, double t, const Eigen::VectorXd& lambda,
                double* out, const detail::PlanarForce* planar = nullptr, bool sum_bars = true,
                const Along* along = nullptr);
  /// Keeps the listed joints' geometry at (q, t): each site, its body's frame Jacobian and the factors of the
  /// equations that give its wrench, which every λ at that q shares (detail::FrictionLosses' passes). Pre-condition
  /// as the first evaluate()'s: no natural joint listed (else phiq::Error).
  void keep_geometry(const double* q, double t);
  /// The first evaluate() at keep_geometry()'s (q, t), the same values to rounding, without finding the geometry
  /// again: the reaction is linear in the joint's own multipliers, so keep_geometry() keeps its values per unit
  /// multiplier of each row, and this sums them (six products a planar pin). Pre-condition: keep_geometry() at
  /// this q and t.
  void evaluate_kept(const double* q, double t, const Eigen::VectorXd& lambda, double* out);
  /// `listed[k]` for the k-th listed joint where its block is not null (empty: none), `own` each a natural body's
  /// own constraint and where to read it. Pre-condition: the blocks outlive the result's use.
  Along along(const std::vector<BlockAt>& listed, const std::vector<std::pair<Index, BlockAt>>& own,
              const Model& model) const;
  /// The natural bodies' own constraints whose Φq values the natural joints' balances read (along()'s `own`).
  std::vector<Index> own_constraints(const Model& model) const;
  /// The k-th listed joint, a planar natural one: its force's derivative along each multiplier it reads (its body's
  /// own constraints' rows), in world axes, at the last evaluate()'s q: `rows[i]` and (∂Fx, ∂Fy)/∂λ at `d[2 i]`.
  void natural_force_rows(std::size_t k, std::vector<Index>& rows, std::vector<double>& d) const;
  /// keep_geometry()'s values of the k-th listed joint per unit multiplier of each of its rows (column j: row
  /// kept_first_row(k) + j; a planar joint's first three values). Pre-condition: keep_geometry().
  const Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>& kept_per_row(std::size_t k) const {
    return kept_[k].per_row;
  }
  /// The k-th listed joint's first row in the model's (kept_per_row()).
  Index kept_first_row(std::size_t k) const { return set_->sites[k].first_row; }

 private:
  struct Site {
    const ConstraintBlock* block = nullptr;
    std::size_t index = 0;       // in its block
    std::vector<Index> columns;  // the coordinates the constraint reads (to clear the scratch)
    bool spatial = false;
    Index first_row = 0;  // its rows in the model's
    int rows = 0;
  };
  // A natural joint's site. Its flat form, where the body's part is read from a sweep's Q (BodyPart::part), no load
  // is the body's alone and the model is planar: component k's Q_b is the sum of the PlanarForce values terms[k]
  // names (kPlanarFields' index, +8 when negated), in add_planar_force()'s order, and its reaction g_[at[k]] − Q_b;
  // along a fixed component (a ground pivot's), −Σ g_ over the body's points' moving components there
  // − Q_b, or NaN when `shared` (another of its points is fixed along it too). The same sums as the general path's
  // without writing the body's Q (qb_) and clearing it, nor reading the body's points at every row.
  struct NaturalSite {
    static constexpr int kMaxTerms = 3;  // per component (a point is at most an origin and an x target)
    // What the flat path reads at every row, first: one cache line of 64 bytes (10⁴ sites a row at nfourbar 10⁴).
    bool flat = false;
    // flat, moving along x and y, one Q term and one entry of Φq each (a bar's point: nfourbar's every joint)
    bool simple = false;
    std::uint8_t count[2] = {0, 0}, terms[2][kMaxTerms] = {};
    bool shared[2] = {false, false};
    // Its sums of the body's own constraints' forces, Σ Φq values × λ over FlatSums' groups: component k's
    // are groups [group_first[k], group_first[k + 1]), one for a moving component (its coordinate's), one per moving
    // point for a fixed one; each sums the body's entries in its column, in their order, as the general path's g_
    std::uint32_t group_first[3] = {0, 0, 0};
    std::size_t part = 0;             // the flat form's part (OutputEfforts::parts)
    Index at[3] = {0, 0, 0};          // its components' coordinates (n and above: promoted constants)
    std::size_t joint = 0, body = 0;  // in SetUp::natural
    std::size_t point = 0;            // the joint's place among the body's points
  };
  // The natural bodies' own constraints' Jacobian entries (of the bodies sites report on; the others' are empty) and
  // the columns the bodies' forces touch, body b's at [first[b], first[b + 1]) of each list (flat: one allocation
  // per list, not per body). An entry is a value's slot in
  // Φq's pattern, its row and column, in the pattern's order (by column, then row: a column's sum over the body's
  // constraints runs in their order, as their rows do). `runs`: the constraints of the bodies a site reports on, as
  // ranges of one block, whose Jacobian a row evaluates once (one call per range, not per site).
  struct OwnEntry {
    Index slot = 0, row = 0, column = 0;
  };
  struct OwnRun {
    const ConstraintBlock* block = nullptr;
    std::size_t begin = 0, end = 0;
  };
  // group g of the flat sites' sums: entries terms[term_first[g] … term_first[g + 1])
  struct FlatSums {
    std::vector<std::uint32_t> term_first{0};
    std::vector<OwnEntry> terms;
  };
  // A simple site (NaturalSite::simple) as a row reads it, without FlatSums' indirections nor the site's own 80
  // bytes: component k's reaction is own_values_[slot[k]] λ[row[k]] − Q_b, Q_b the value of `part`'s PlanarForce
  // that term[k] names (kPlanarFields' index, +8 when negated). On a rigid bar (`bar`) the site sums that value
  // itself (evaluate()'s sum_bars), as detail::bar_field() does: with BarSum `form`'s numbers, weight[k] −
  // ((m[k][0] q̈[a[k][0]] + m[k][1] q̈[a[k][1]]) + m[k][2] q̈[a[k][2]]), a term on a constant slot with m 0 (a ±0,
  // which changes no sum but a zero's sign, and Q_b starts from +0). 10⁴ a row at nfourbar 10⁴, where that saves a
  // crank's whole force; 52 bytes, which a row reads from memory.
  struct SimpleSite {
    std::uint32_t slot[2] = {0, 0}, row[2] = {0, 0};
    std::uint32_t part = 0;
    std::uint32_t form = 0;  // (bar) its BarSum among SetUp::bar_sums
    std::uint32_t a[2][3] = {};
    std::uint8_t term[2] = {0, 0};
    bool simple = false;  // the site is simple (else the other fields are not read)
    bool bar = false;
  };
  // The numbers of a bar's simple site's sums (SimpleSite), shared by the sites whose numbers are the same bits
  // (nfourbar's 10⁴ cranks have one).
  struct BarSum {
    double m[2][3] = {}, weight[2] = {};
  };
  // A natural body's part as the whole model's Q takes it when that is a rigid bar, while set up (find_body_parts()
  // to find_flat_sites(), which builds its sites' BarSums): its mass numbers (detail::bar_number()'s order) and its
  // weight's share of each PlanarForce field under the loads' gravity (detail::bar_weight_share())
  struct BarForm {
    bool bar = false;
    double numbers[4] = {}, weights[6] = {};
  };
  struct BodyRows {
    std::vector<std::size_t> entries_first, q_first;
    std::vector<OwnEntry> entries;
    std::vector<Index> q_columns;
    std::vector<OwnRun> runs;
    FlatSums flat;  // the flat sites' sums (NaturalSite::group_first)
    // own_values_' index of each of the model's Jacobian entries (as Model::slot_of_entry(), onto the own entries
    // alone, in `entries`' order: a row reads them for 10⁴ sites, which the whole pattern's slots spread over its
    // megabytes), and slot_of_entry its data
    std::vector<EntryIndex> own_slot_of_entry;
    const EntryIndex* slot_of_entry = nullptr;
    bool overwrite = false;  // no two entries of the model share a slot (Model::jacobian())
  };
  // A natural body's part as OutputEfforts::parts' has it: `part` its index there when the whole model's Q computes
  // the body's weight and inertia (evaluate()'s `planar`) as the body's own Q would, bit for bit, else none; `slots`
  // its promoted planar frame's (detail::PlanarFrame), where its force is added.
  // `applied` the loads on the body alone, when any. (A row reads these rather than the NaturalBody, whose
  // kilobytes each, 10⁴ of them in nfourbar 10⁴, would come from memory at every row.)
  struct BodyPart {
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::size_t part = kNone;
    Slot slots[5];
    bool x_is_point = true;
    double bar_length = 0.0;  // > 0: the body is a rigid bar, its force a bar's (solve/part_forces.hpp)
    const AppliedLoads* applied = nullptr;
    detail::PlanarFrame frame() const;  // the promoted planar frame the slots name
  };
  struct SetUpOnly {};  // with_set_up_of()'s constructor
  JointReactions(const JointReactions& other, SetUpOnly);
  void turn_natural(const NaturalSite& s, const double* q, double t, double* force) const;
  void add_site(const Model& model, Index c, std::vector<int>& site_of);
  void find_columns(const Model& model, const std::vector<int>& site_of);
  void add_natural(const Model& model, const OutputEfforts& efforts, bool rigid_bars);
  // qx_, q̇x_, q̈x_ (the promoted constants past the model's coordinates) and qb_ (zero) at their sizes
  void size_natural_scratch();
  // `bars`: the model's rigid bars where the sweep's Q takes them (else empty)
  // (and `forms`, per natural body: its BarForm)
  void find_body_parts(const Model& model, const OutputEfforts& efforts, const detail::BarLengths& bars,
                       std::vector<BarForm>& forms);
  void find_flat_sites(const Model& model, const std::vector<BarForm>& forms);
  // s's groups (NaturalSite::group_first), for a model of n coordinates; `moving`: its fixed components' moving
  // points' coordinates
  void add_flat_sums(NaturalSite& s, Index n, const std::vector<Index> (&moving)[2]);
  // simple site `at`'s sums on body part `part`, a rigid bar of BarForm `form` (SimpleSite::a, and its BarSum)
  BarSum bar_sum(SimpleSite& at, const BodyPart& part, const BarForm& form, Index n) const;
  // A constraint site's geometry at one q: its ReactionSite, its body's frame Jacobian, the factors of the normal
  // equations J_b J_bᵀ w = J_b g whose solution is its wrench (directions no coordinate moves set to w_i = 0), and
  // the body's origin.
  struct SiteGeometry {
    ReactionSite site;
    PartJacobian jac;
    Eigen::LDLT<Eigen::Matrix<double, 6, 6>> normal;
    // The normal equations are the identity (a planar reference-point body's: its x, y, ψ move its origin and its
    // angle one each): the wrench is the right-hand side, which normal's solve would give bit for bit.
    bool identity = false;
    bool unmoved[6] = {};
    kin3::V3 origin;
    // keep_geometry()'s: the reaction's values per unit multiplier of each of the site's rows, column j row j's
    Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6> per_row;
  };
  // (`at`: the site's constraint read elsewhere, Along)
  void site_geometry(const Site& s, const double* q, double t, SiteGeometry& g, BlockAt at = {}) const;
  void site_reaction(const Site& s, const SiteGeometry& g, const double* q, double t, const Eigen::VectorXd& lambda,
                     double*& out, BlockAt at = {});
  void evaluate_site(const Site& s, const double* q, double t, const Eigen::VectorXd& lambda, double*& out,
                     BlockAt at = {});
  void body_forces(std::size_t b, double t, const detail::PlanarForce* planar);
  // BodyRows::entries' slots numbered afresh, own_values_ sized to them (BodyRows::own_slot_of_entry)
  void number_own_entries(const Model& model);
  // own_values_ = Φq's values of BodyRows::runs at (q, t), once a row
  void evaluate_own_jacobian(const double* q, double t, const Along* along = nullptr);
  // g_ += Φq,cᵀ λ_c over body b's own constraints (own_values_), and g_'s entries those touch cleared again
  void add_body_constraint_forces(std::size_t b, const Eigen::VectorXd& lambda);
  void clear_body_constraint_forces(std::size_t b);
  // The row's motion: q, q̇, q̈ copied into qx_, qdx_, qddx_ at the first site that reads them (a row of flat sites
  // reads q alone).
  struct RowMotion {
    const double *q, *qd, *qdd;
    bool extended;
  };
  void evaluate_natural(const NaturalSite& s, RowMotion& row, double t, const Eigen::VectorXd& lambda,
                        const detail::PlanarForce* planar, double*& out);
  bool evaluate_flat(const NaturalSite& s, const double* q, double t, const Eigen::VectorXd& lambda,
                     const detail::PlanarForce* planar, double* out);
  // What construction finds, never written after it: shared by with_set_up_of()'s copies (a sweep's chunks), which
  // have scratch of their own. At nfourbar 10⁴ it is megabytes, which a copy per chunk would have the system map in
  // again and again.
  struct SetUp {
    std::vector<Site> sites;
    std::vector<NaturalSite> natural_sites;
    std::vector<SimpleSite> simple_sites;             // per natural site, read where it is simple
    std::vector<BarSum> bar_sums;                     // SimpleSite::form's
    std::vector<std::pair<bool, std::size_t>> order;  // (natural, index) per listed reaction
    std::shared_ptr<const NaturalJoints> natural;
    BodyRows body_rows;
    std::vector<BodyPart> body_parts;  // per natural body
    // per natural body, its parts (natural_body_parts()) where a site of its takes the general path at every row
    // (not flat), else empty
    std::vector<std::vector<Part>> body_parts_kept;
    bool joint_axes = false;  // constraints' reactions along ReactionSite::axes, not world axes
    bool rigid_bars = false;  // rigid_bars()
    Index size = 0;
  };
  std::shared_ptr<SetUp> set_ = std::make_shared<SetUp>();
  Eigen::VectorXd qx_, qdx_, qddx_, qb_;  // q, q̇, q̈ with the promoted constants; a body's Q
  std::vector<double> g_;                 // −Φq,cᵀ λ_c, one entry per coordinate, zero between evaluations
  std::vector<double> own_values_;        // Φq's values of the natural bodies' own constraints (BodyRows' slots)
  SiteGeometry geometry_;                 // evaluate_site()'s (its vectors' capacity kept: no allocation per row)
  std::vector<SiteGeometry> kept_;        // keep_geometry()'s, one per constraint site
  Eigen::VectorXd unit_;                  // keep_geometry()'s unit multipliers
  std::vector<Part> body_part_;           // a body's parts built where they are read (body_parts_kept's others)
};

/// What add_gear_mesh_forces() finds at a row: the meshes it names, in `meshes`' order.
struct MeshFindings {
  std::vector<Index> working;  ///< meshes whose push does work along q̇: their centres are not where the row needs
  std::vector<Index> slack;    ///< belts whose slack strand would need a negative tension (T0 < |ΔT|/2): they slip
  /// Spatial gear pairs whose pitch point is not placed at this row, and why: no push
  std::vector<std::pair<Index, const char*>> unplaced;
};

/// What turns the torques of each gear pair of `meshes` under multipliers `lambda` into the push of its teeth,
/// added to `dq` (one value per coordinate). A gear's row relates angles alone (GearMesh), so λ turns its gears by
/// torques and their bearings see nothing of the mesh; the teeth push at the pitch point, across the line of the
/// centres c1 → c2 (bodies' reference points, at distance d), with F = −λ_g (1 + k)/d along t = ẑ × (c2 − c1)/d:
/// the same torques, and F t on c1, −F t on c2, which the carrier's torque F d made up for. So dq = F t at gear 1's
/// centre, −F t at gear 2's, and F d on the carrier's angle. It does no work in any motion that keeps the centres
/// where the mesh needs them: δ with Φqᵀ δ = dq is the change of the other joints' multipliers (nothing at the
/// drivers' rows or the gears'), λ + δ the multipliers under which the bearings carry the teeth's push. The teeth's
/// pressure angle α parts the gears as well, by |F| tan α along the line of centres (no moment about them, no work).
/// A mesh whose centres coincide adds nothing. A rack and pinion likewise: its row pushes the rack along its travel e
/// (its body's x or y) and turns the pinion; its teeth push at P = c_p + k ẑ × e, which adds λ e and the parting
/// |λ| tan α on the pinion's centre, the parting on the rack across its travel and the moment of its push about its
/// reference point on its angle. A belt or chain whose strands
/// are known (GearMesh::strands_known()) pulls its pulleys' centres by its two strands' tensions along them, which
/// its torque −λ on pulley 1 splits (GearMesh); without them, or with overlapping pulleys, it adds nothing. A
/// spatial pair (OutputMesh::spatial: bevel, worm, spur or helical) pushes its shafts at its pitch point
/// (SpatialMesh), or adds nothing when that is not placed (appended to `found->unplaced`). A mesh with
/// OutputMesh::unloaded adds nothing. With the row's velocities `qd`, appends to `found->working` (when not null) the
/// meshes whose push does work along q̇ (beyond 10⁻⁶ of its terms): their bodies' reference points are not centres that
/// keep their places on the carrier, so the row does not describe their teeth (a gear on a moving arm whose carrier is
/// not named); and to `found->slack` the belts whose slack strand would need a negative tension. Pre-condition:
/// `lambda` has one value per model row, `qd` (if not null) one per coordinate. `scratch` (if not null): the spatial
/// pairs' shafts' Jacobian, its capacity reused from row to row (a sweep lends one: no allocation per row).
void add_gear_mesh_forces(const Model& model, const std::vector<OutputMesh>& meshes, const double* q,
                          const Eigen::VectorXd& lambda, Eigen::VectorXd& dq, const double* qd = nullptr,
                          MeshFindings* found = nullptr, PartJacobian* scratch = nullptr);

/// The multipliers of least norm among those with Φqᵀ λ = Q, from `lambda`, one of them (λ = 0 on the rows the model
/// dropped as redundant: multipliers_with_factors()), and `lu`, the factors of the kept rows of Φq at q. Each
/// dropped row r is a combination of the kept rows, Φq,r = Σ α_k Φq,k (one transposed solve with `lu`), so that
/// n_r = e_r − Σ α_k e_k is a direction λ may move along without changing Φqᵀ λ; λ is projected off those
/// directions. Appends to `indeterminate` (when not null) the constraints whose rows those directions move, in
/// model order: the joints whose reactions the motion does not determine. A model without dropped rows is left as
/// it is. Returns false when a solve fails. Its dense buffers (m × dropped rows) are allocated at each call; a sweep
/// lends its own per thread instead.
bool minimum_norm_multipliers(const Model& model, SparseLuNumeric& lu, const double* q, double t,
                              Eigen::VectorXd& lambda, std::vector<Index>* indeterminate = nullptr);

}  // namespace phiq
