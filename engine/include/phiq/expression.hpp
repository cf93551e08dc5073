// Equation constraints written as text, exactly as the notes write Φ: "xA - L2*cos(theta2)".
//
// The text is parsed and differentiated exactly by GiNaC once, when the model is built; every derived quantity
// (value, gradient, ∂/∂t, γ) is then compiled into a flat register tape with common subexpressions shared, so that
// evaluation inside the Newton loop never touches the symbolic engine and never re-parses.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "phiq/types.hpp"

namespace phiq {

// One compiled straight-line program over doubles. Inputs are read from q (coordinates), qd (velocities) and t.
class Tape {
 public:
  enum class Op : std::uint8_t {
    kConst, kLoadQ, kLoadQd, kLoadT,
    kAdd, kSub, kMul, kDiv, kNeg, kPowInt, kPow, kSqrt,
    kSin, kCos, kTan, kAsin, kAcos, kAtan, kAtan2, kExp, kLog, kSinh, kCosh, kTanh, kAbs, kSign,
  };
  struct Instr {
    Op op;
    std::uint32_t a = 0, b = 0;  // operand registers (or the input index for loads)
    double imm = 0.0;            // constant value, or integer exponent for kPowInt
  };

  // Evaluates the program; out[k] receives register outputs()[k]. Thread-safe (scratch is thread-local).
  void evaluate(const double* q, const double* qd, double t, double* out) const;

  std::size_t size() const { return code_.size(); }
  std::size_t num_outputs() const { return outputs_.size(); }

 private:
  friend class TapeBuilder;
  std::vector<Instr> code_;
  std::vector<std::uint32_t> outputs_;
};

// What a name in an expression stands for.
struct NameBinding {
  enum class Kind { kCoordinate, kConstant, kTime } kind;
  Index coordinate = -1;  // for kCoordinate
  double value = 0.0;     // for kConstant
};

// Resolves a name to a binding, or returns nullopt when the name is unknown.
using NameResolver = std::function<std::optional<NameBinding>(const std::string&)>;

// The compiled form of a scalar function g(q, t) together with its exact derivatives.
class CompiledExpression {
 public:
  // Parses and differentiates `text`. Throws phiq::Error with a one-line message naming the expression and the
  // offending name or token when the text is malformed, uses an unknown name or an unsupported function.
  // `allow_time` false rejects `t` (e.g. for constant fields).
  static std::shared_ptr<const CompiledExpression> compile(const std::string& text, const NameResolver& resolve,
                                                           bool allow_time = true);

  const std::string& text() const { return text_; }
  // Coordinates g depends on, ascending; gradient() writes ∂g/∂q for these, in this order.
  const std::vector<Index>& coordinates() const { return coords_; }
  bool depends_on_time() const { return depends_on_time_; }

  double value(const double* q, double t) const;
  void gradient(const double* q, double t, double* dg_dq) const;
  double partial_t(const double* q, double t) const;
  // γ contribution: −( Σ_jk g_qjqk q̇j q̇k + 2 Σ_j g_qjt q̇j + g_tt ).
  double gamma(const double* q, const double* qd, double t) const;

 private:
  std::string text_;
  std::vector<Index> coords_;
  bool depends_on_time_ = false;
  Tape value_, gradient_, partial_t_, gamma_;
};

// Evaluates a constant expression (numbers, named constants, pi, functions), e.g. "L2/2" or "2*pi".
double evaluate_constant_expression(const std::string& text,
                                    const std::function<std::optional<double>(const std::string&)>& constant);

}  // namespace phiq
