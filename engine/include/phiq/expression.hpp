/// @file
/// Equation constraints written as text, exactly as the notes write Φ: "xA - L2*cos(theta2)".
///
/// The text is parsed by phiq (constant parts folded in double precision) and differentiated exactly by GiNaC
/// once, when the model is built; the value, the gradient and ∂/∂t are compiled into flat register tapes with
/// common subexpressions shared, so that evaluation inside the Newton loop never touches the symbolic engine and
/// never re-parses. γ needs second derivatives: it is computed exactly by second-order forward (Taylor-mode)
/// automatic differentiation of the value tape along (q̇, 1), which costs a few passes over the tape, where symbolic
/// second derivatives can grow with the cube of a product's length. A power u^p with a constant exponent has the
/// derivatives p u^(p−1) and p (p−1) u^(p−2), each evaluated as a power: at u = 0 they are exactly 0 where p is
/// large enough ((2x)² has the derivative 8x), and infinite (not NaN) where they really are (√u). The tapes do not
/// follow GiNaC's order of terms (which follows hash values that change from process to process): the same text
/// compiles to the same tapes, hence the same bits, in every process and whatever was compiled before.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "phiq/types.hpp"

namespace phiq {

/// One compiled straight-line program over doubles. Inputs are read from q (coordinates), qd (velocities) and t.
class Tape {
 public:
  /// Instruction codes: loads of inputs, arithmetic, and the supported functions (kSign is csgn). kPowInt is a^k and
  /// kPowHalf is √a^k for an integer k in imm (exact repeated squaring); kPow is a^b.
  enum class Op : std::uint8_t {
    kConst,
    kLoadQ,
    kLoadQd,
    kLoadT,
    kAdd,
    kSub,
    kMul,
    kDiv,
    kNeg,
    kPowInt,
    kPowHalf,
    kPow,
    kSqrt,
    kSin,
    kCos,
    kTan,
    kAsin,
    kAcos,
    kAtan,
    kAtan2,
    kExp,
    kLog,
    kSinh,
    kCosh,
    kTanh,
    kAbs,
    kSign,
  };
  /// One instruction; its result is the register with its own index (static single assignment).
  struct Instr {
    Op op;                                          ///< what it computes
    std::uint32_t a = 0;                            ///< first operand register (or the input index for loads)
    std::uint32_t b = 0;                            ///< second operand register
    double imm = 0.0;                               ///< constant value, or integer exponent for kPowInt and kPowHalf
    bool operator==(const Instr&) const = default;  ///< field by field
  };

  /// Evaluates the program; out[k] receives register outputs()[k]; qd null reads q̇ as 0. Thread-safe (scratch is
  /// thread-local).
  void evaluate(const double* q, const double* qd, double t, double* out) const;
  /// Second-order Taylor coefficients of output 0 along s ↦ (q + s q̇, t + s): value, d/ds and ½ d²/ds² at s = 0.
  /// Exact (no truncation). Thread-safe.
  void taylor2(const double* q, const double* qd, double t, double out[3]) const;

  /// The same program: instruction for instruction (constants by value), and the same outputs.
  bool operator==(const Tape&) const = default;
  std::size_t size() const { return code_.size(); }            ///< number of instructions
  std::size_t num_outputs() const { return outputs_.size(); }  ///< number of outputs
  /// The program as text, one instruction per line ("r3 = mul r1 r2"; constants as hexadecimal floats, so that
  /// equal listings are the same program bit for bit), then its outputs. For tests and debugging.
  std::string listing() const;

 private:
  friend class TapeBuilder;
  friend class CompiledExpression;
  friend struct TapeInternals;  // the Taylor pass over any scalar (src/expression/taylor.hpp)
  std::vector<Instr> code_;
  std::vector<std::uint32_t> outputs_;
};

/// What a name in an expression stands for.
struct NameBinding {
  /// The three things a name can be.
  enum class Kind {
    kCoordinate,  ///< a generalized coordinate (index in q)
    kConstant,    ///< a parameter, substituted by its value
    kTime,        ///< the time t
  };
  Kind kind;              ///< what the name is
  Index coordinate = -1;  ///< for kCoordinate
  double value = 0.0;     ///< for kConstant
};

/// Resolves a name to a binding, or returns nullopt when the name is unknown.
using NameResolver = std::function<std::optional<NameBinding>(const std::string&)>;

/// The compiled form of a scalar function g(q, t) together with its exact derivatives.
class CompiledExpression {
 public:
  /// Hostile-input limits: longer or deeper texts, or derivatives that compile to more instructions, are refused.
  static constexpr std::size_t kMaxTextLength = 4096;  ///< characters
  static constexpr int kMaxNesting = 64;               ///< parentheses
  static constexpr std::size_t kMaxTapeSize = 50000;   ///< instructions over value, gradient and Φt

  /// Parses and differentiates `text`. Throws phiq::Error with a one-line message naming the expression and the
  /// offending name or token when the text is malformed, uses an unknown name or an unsupported function.
  /// `allow_time` false rejects `t` (e.g. for constant fields). `allow_rates` true admits `der(u)`, the rate of u
  /// along the motion (Σ ∂u/∂q_j q̇_j + ∂u/∂t, differentiated exactly; not of a u that reads q̇): a load's
  /// component (`-c*der(x)`); elsewhere it is refused, naming where rates may be read.
  static std::shared_ptr<const CompiledExpression> compile(const std::string& text, const NameResolver& resolve,
                                                           bool allow_time = true, bool allow_rates = false);

  /// The same function: the same text, coordinates and programs (a scene's parameter is a constant of the tapes,
  /// so a scene read at two values of a parameter its expression reads gives two different functions). Where the
  /// function came from (same_source()) is not compared.
  bool operator==(const CompiledExpression& o) const {
    return text_ == o.text_ && coords_ == o.coords_ && rate_coords_ == o.rate_coords_ &&
           depends_on_time_ == o.depends_on_time_ && angle_difference_ == o.angle_difference_ && value_ == o.value_ &&
           gradient_ == o.gradient_ && partial_t_ == o.partial_t_ && rate_gradient_ == o.rate_gradient_;
  }
  /// The text it was compiled from.
  const std::string& text() const { return text_; }
  /// Coordinates g depends on, ascending; gradient() writes ∂g/∂q for these, in this order.
  const std::vector<Index>& coordinates() const { return coords_; }
  /// True when g depends on t explicitly.
  bool depends_on_time() const { return depends_on_time_; }
  /// True when g is an angle defined modulo 2π by its top-level form: a sum whose terms include atan2(…), each
  /// such term with coefficient +1 or −1 and no atan2 nested deeper (`atan2(yA - y0, xA - x0) - t`,
  /// `atan2(yB, xB) - atan2(yA, xA)`). atan2 jumps by 2π as its angle passes ±π, so an equation g − f = 0 of such a
  /// g is solved with its residual wrapped to (−π, π] (EquationSpec), as the joint-angle drivers are.
  bool angle_difference() const { return angle_difference_; }

  /// Coordinates whose rates q̇ g reads (through der()), ascending; rate_gradient() writes ∂g/∂q̇ for these. Empty
  /// for every expression compiled without `allow_rates`.
  const std::vector<Index>& rate_coordinates() const { return rate_coords_; }
  /// g(q, t). Pre-condition: q has an entry for every index in coordinates(). Thread-safe (as all below).
  /// Where g reads rates, they are 0 (at rest).
  double value(const double* q, double t) const { return value(q, nullptr, t); }
  /// g(q, q̇, t); qd null: q̇ = 0. Pre-condition: qd has an entry for every index in rate_coordinates().
  double value(const double* q, const double* qd, double t) const;
  /// ∂g/∂q_j for j in coordinates(), in that order, into dg_dq.
  void gradient(const double* q, double t, double* dg_dq) const { gradient(q, nullptr, t, dg_dq); }
  /// ∂g/∂q_j at (q, q̇, t); qd null: q̇ = 0.
  void gradient(const double* q, const double* qd, double t, double* dg_dq) const;
  /// ∂g/∂q̇_j for j in rate_coordinates(), in that order, into dg_dqd; qd null: q̇ = 0.
  void rate_gradient(const double* q, const double* qd, double t, double* dg_dqd) const;
  /// ∂g/∂t.
  double partial_t(const double* q, double t) const;
  /// γ contribution: −( Σ_jk g_qjqk q̇j q̇k + 2 Σ_j g_qjt q̇j + g_tt ).
  double gamma(const double* q, const double* qd, double t) const;

  /// The value, gradient and ∂/∂t tapes as text (Tape::listing), for tests and debugging: the same text (and the
  /// same names) give the same listing in every process.
  std::string listing() const;

  /// The same function with the coordinate indices it was compiled with reinterpreted, without symbolic work (the
  /// tapes are copied and patched): compiled index k reads q[target[k]] when target[k] ≥ 0 and is the constant
  /// value[k] when target[k] < 0. The derivatives stay exact; coordinates that coincide after the mapping have
  /// their gradient entries summed. Used by scene families (`for`): one expression is compiled once with
  /// placeholder indices and instantiated per member. `text` is the text of the result. Throws phiq::Error when
  /// a compiled index has no entry in `target` (or `value` is shorter than `target`).
  std::shared_ptr<const CompiledExpression> rebind(const std::vector<Index>& target, const std::vector<double>& value,
                                                   std::string text) const;

  /// The constants c of g that a scene's data can move, with their values: the parameters its text reads (in the
  /// order it first reads them), then, for a family member (rebind()), the values its rebinding gave the compiled
  /// indices that are no coordinate of the member, in index order. Empty for an expression made by
  /// along_constants(), or rebound twice.
  const std::vector<double>& constants() const { return constants_; }
  /// True when `other` was compiled from the same text against the same names (the same coordinates, the same
  /// parameters whatever their values, the same rebinding), so that their constants() match one to one: an
  /// equation of a scene read at two values of a parameter.
  bool same_source(const CompiledExpression& other) const;
  /// h = Σ_j rate[j] ∂g/∂c_j with c = constants() held at their values: g's rate along a design parameter that
  /// moves c at `rate` (EquationSpec::data_derivative()), compiled with its derivatives as g is, exactly (symbolic
  /// differentiation along the constants, then the same tapes: h's value, Φq-like gradient and ∂/∂t, and its γ by
  /// Taylor mode). Null when every rate is 0. Symbolic work once per text and rates: family members whose
  /// constants move alike share it (rebound from one compilation). Throws phiq::Error when `rate` is not of
  /// constants()' size, or when a constant that moves is an exponent (u^c: g's power with a constant exponent is
  /// not the general power a moving exponent needs), or the derivative exceeds the tape limit.
  std::shared_ptr<const CompiledExpression> along_constants(const std::vector<double>& rate) const;

  /// @cond internal
  struct Source;
  friend struct CompiledExpressionBuilder;
  friend struct TapeInternals;
  /// @endcond

 private:
  std::shared_ptr<const Source> source_;  // the text and the names it was compiled with: along_constants() reads it
  std::vector<double> constants_;         // constants()
  std::vector<Index> target_;             // rebind()'s target (empty unless rebound)
  std::string text_;
  std::vector<Index> coords_, rate_coords_;
  bool depends_on_time_ = false;
  bool angle_difference_ = false;
  Tape value_, gradient_, partial_t_, rate_gradient_;
};

/// Evaluates a constant expression (numbers, named constants, pi, functions), e.g. "L2/2" or "2*pi".
double evaluate_constant_expression(const std::string& text,
                                    const std::function<std::optional<double>(const std::string&)>& constant);

}  // namespace phiq
