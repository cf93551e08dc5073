// What find_polynomial_system() reads of a model (engine/src/modes/): its rows evaluated in double, with a
// polynomial surrogate for the rows that are not polynomial themselves but vanish where a polynomial does, and the
// elimination of the coordinates that affine rows fix.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "phiq/modes.hpp"

namespace phiq::modes_detail {

// The model's rows at q, one evaluation of the whole model per call (the models solved here are small). A spatial
// joint-angle driver's row, θ − f(T) wrapped (an atan2 of the joint frames' axes), is read as its surrogate
// s cos f − c sin f, c = x_a · x_b and s = y_a · x_b: polynomial in the bodies' Euler parameters or natural
// coordinates, zero at θ = f and at θ = f + π (find_assembly_modes() drops the second by the model's own Φ).
class ModelRows {
 public:
  ModelRows(const Model& model, double t);
  double row(const Eigen::VectorXd& q, Index r);
  // Whether row r is evaluated through a surrogate.
  bool surrogate(Index r) const { return static_cast<bool>(surrogate_[static_cast<std::size_t>(r)]); }

 private:
  const Model& model_;
  double t_;
  std::vector<double> phi_;
  std::vector<std::function<double(const double* q)>> surrogate_;  // per row; empty: the model's own
};

// The Euler parameters (e0 … e3) of every body whose four are coordinates: e and −e are one placement.
std::vector<std::array<Index, 4>> euler_parameter_coordinates(const Model& model);

class Random;

// The value and the slopes (per unit of each scaled variable, q_j = base_j + scale_j · u) of row r at `base` when it
// is affine in the coordinates `columns`: checked at random points, to rounding of the row's size. False when not.
bool affine_row(ModelRows& rows, Index r, const std::vector<Index>& columns, const Eigen::VectorXd& scale,
                const Eigen::VectorXd& base, Random& random, double& value, Eigen::VectorXd& slope);

// Row r as an AngleRelation when it is affine in the free coordinates it reads (`free`), all angles, their slopes in
// ratios of integers and the multiple-angle polynomial of degree ≤ 24: the relation and that polynomial, over
// `variables` unknowns (angle j's c is variable_of[j], its s the next). False otherwise (nothing set).
bool angle_relation(ModelRows& rows, Index r, const std::vector<Index>& free, const std::vector<int>& variable_of,
                    const Eigen::VectorXd& base, int variables, Random& random, AngleRelation& relation,
                    Polynomial& polynomial);

// Turns angles of q by whole turns so that `relation` holds exactly (q's angles from atan2: it holds modulo 2π).
void apply_relation_turns(const AngleRelation& relation, Eigen::VectorXd& q);

// Solves a square system block by block (block_solve.cpp): its Dulmage–Mendelsohn blocks in order, each for every
// real solution of those before it, a body's Euler parameters (`euler_variables`: the four variables of each,
// e = offset + x) carried forward with one sign (the equations read them through the rotation, the same at ±e), and
// the results refined and classified on the whole system. `out` then counts the paths of all blocks, their complex,
// infinite and failed ends, and holds the real solutions of the whole system (one per ±e) as its endpoints
// (ModesMethod::kBlocks). False with `unsafe` empty, nothing done, when the system is one block or not square;
// false with `unsafe` saying why (which block, what it found) when the block solve is not safe (the file's
// comment): the caller solves the whole system.
bool solve_in_blocks(const PolynomialSystem& system, const std::vector<std::array<int, 4>>& euler_variables,
                     const Eigen::VectorXd& offset, const ModesOptions& options, ModesSummary& out,
                     std::string& unsafe);

// Fixes the coordinates affine rows determine, until none is left to fix: a row that reads one free coordinate and
// is affine in it (a driver), then a set of rows each affine in all the free coordinates it reads (gears and
// belts among driven angles, the pins their angles then leave linear) solved together, fixing every coordinate the
// set determines (those the null space of its matrix does not move). Updates out.fixed, out.eliminated_rows
// (unsorted), `base` (the origin with the fixed values) and `eliminated` (per row). `row_columns`: the coordinates
// each row reads.
void eliminate_affine_rows(ModelRows& rows, const std::vector<std::vector<Index>>& row_columns, ModelPolynomials& out,
                           Eigen::VectorXd& base, std::vector<bool>& eliminated);

}  // namespace phiq::modes_detail
