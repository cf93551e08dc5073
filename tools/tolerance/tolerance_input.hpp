// What `phiq tolerance` is given: the toleranced parameters (a standard deviation, a ± limit, or a block of a
// covariance file each), their covariance Σ with its Cholesky factor, and the reproducible samples drawn from it.
// The numbers only: the command (tools/cli/tolerance.cpp) reads the scene and sweeps.
#pragma once

#include <Eigen/Dense>

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace phiq::tolerance {

// How a parameter varies about its nominal value p.
enum class Distribution {
  kNormal,   // N(p, σ²): --sd, or a parameter of --covariance
  kUniform,  // uniform on [p − l, p + l] (--limit l): σ = l/√3
};

struct Tolerance {
  std::string name;
  Distribution distribution = Distribution::kNormal;
  double spread = 0.0;  // σ for kNormal given by --sd, l for kUniform; unused for a covariance parameter
  bool from_covariance = false;
};

// A covariance file: a header of parameter names and the symmetric positive definite matrix, one row per
// parameter in the header's order.
struct Covariance {
  std::vector<std::string> names;
  Eigen::MatrixXd matrix;
};

// "NAME=VALUE" with VALUE a finite number (decimal or exponent form, an optional '+'), as --set, --sd and --limit
// take it. Throws phiq::Error "OPTION NAME=VALUE: WHY".
std::pair<std::string, double> parse_named_value(const std::string& option, const std::string& text);

// "NAME=VALUE" of --sd / --limit: the value finite and > 0. Throws phiq::Error "OPTION NAME=VALUE: WHY".
Tolerance parse_tolerance(const std::string& option, const std::string& text);

// Reads and checks a covariance file: a square matrix as wide as its header, finite, symmetric (to 1e-12 of its
// largest entry), positive definite (its Cholesky factorisation names the first parameter where it fails), no
// parameter named twice. Throws phiq::Error "PATH: WHY".
Covariance read_covariance(const std::string& path);

// The lower Cholesky factor of `a` (symmetric); throws phiq::Error "...: not positive definite ..." naming
// `names[k]`, the first pivot that is not positive.
Eigen::MatrixXd cholesky(const Eigen::MatrixXd& a, const std::vector<std::string>& names);

// The joint distribution of the toleranced parameters, in the order `tolerances` lists them (those of the
// covariance file where the file's block begins, in the file's order): Σ, block diagonal (the covariance file's
// block, σ² for the others), and L with L Lᵀ = Σ.
struct ParameterSpread {
  std::vector<Tolerance> parameters;
  Eigen::MatrixXd sigma;
  Eigen::MatrixXd factor;
};
// Throws phiq::Error for a parameter given twice (by two options, or by an option and the file).
ParameterSpread parameter_spread(const std::vector<Tolerance>& options, const Covariance* covariance);

// Standard normal deviates by Box–Muller over std::mt19937_64 (std::normal_distribution's output is
// implementation-defined; this one is the same wherever the 64-bit Mersenne twister and libm agree), and uniform
// deviates on [0, 1) from the top 53 bits of one draw.
class NormalStream {
 public:
  explicit NormalStream(std::uint64_t seed) : engine_(seed) {}
  double uniform();  // [0, 1)
  double normal();   // N(0, 1), two per pair of uniforms (the second kept for the next call)

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// `samples` parameter sets (rows: samples, columns: spread.parameters) as offsets from the nominal values:
// δ = L z, where z_j is a standard normal for a normal parameter and √3 (2u − 1) (uniform, unit variance) for a
// uniform one, which Σ's block structure leaves uncorrelated. Drawn in order, case after case, parameter after
// parameter, from one NormalStream(seed): the same seed gives the same samples.
Eigen::MatrixXd sample_offsets(const ParameterSpread& spread, long samples, std::uint64_t seed);

}  // namespace phiq::tolerance
