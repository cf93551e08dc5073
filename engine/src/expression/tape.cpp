// The register tape machine at run time: evaluation of a compiled Tape (the value, the gradient, ∂/∂t; on the
// Newton hot path for equation constraints, so its loop and the instruction semantics it inlines stay in this one
// file), second-order Taylor-mode evaluation for γ (expression/taylor.hpp's, over doubles), and the listing.
// Compilation into tapes is tape_builder.cpp.
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "expression/taylor.hpp"
#include "expression/tape_ops.hpp"
#include "phiq/expression.hpp"

namespace phiq {

using detail::apply;
using detail::is_binary;

void Tape::evaluate(const double* q, const double* qd, double t, double* out) const {
  thread_local std::vector<double> r;
  if (r.size() < code_.size()) r.resize(code_.size());
  const std::size_t n = code_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Instr& in = code_[i];
    switch (in.op) {
      case Op::kLoadQ:
        r[i] = q[in.a];
        break;
      case Op::kLoadQd:  // (a load's der(); no constraint's tape reads q̇)
        r[i] = qd ? qd[in.a] : 0.0;
        break;
      case Op::kLoadT:
        r[i] = t;
        break;
      default:
        r[i] = apply(in.op, r[in.a], r[in.b], in.imm);
        break;
    }
  }
  for (std::size_t k = 0; k < outputs_.size(); ++k) out[k] = r[outputs_[k]];
}

namespace {
// The inputs along s ↦ (q + s q̇, t + s) (Tape::taylor2()).
struct TapeTaylorLoads {
  const double* q;
  const double* qd;
  detail::Taylor<double> time;
  detail::Taylor<double> coordinate(std::uint32_t j) const { return {q[j], qd[j], 0.0}; }
  double velocity(std::uint32_t j) const { return qd[j]; }
};
}  // namespace

void Tape::taylor2(const double* q, const double* qd, double t, double out[3]) const {
  const detail::Taylor<double> o = detail::taylor2<double>(*this, TapeTaylorLoads{q, qd, {t, 1.0, 0.0}});
  out[0] = o.v, out[1] = o.d, out[2] = o.h;
}

std::string Tape::listing() const {
  static const char* const names[] = {"const",  "loadq",   "loadqd", "loadt", "add",  "sub",  "mul",  "div",  "neg",
                                      "powint", "powhalf", "pow",    "sqrt",  "sin",  "cos",  "tan",  "asin", "acos",
                                      "atan",   "atan2",   "exp",    "log",   "sinh", "cosh", "tanh", "abs",  "sign"};
  std::ostringstream s;
  char imm[64];
  for (std::size_t i = 0; i < code_.size(); ++i) {
    const Instr& in = code_[i];
    std::snprintf(imm, sizeof imm, "%a", in.imm);
    s << 'r' << i << " = " << names[static_cast<int>(in.op)];
    switch (in.op) {
      case Op::kConst:
        s << ' ' << imm;
        break;
      case Op::kLoadQ:
      case Op::kLoadQd:
        s << ' ' << in.a;
        break;
      case Op::kLoadT:
        break;
      default:
        s << " r" << in.a;
        if (is_binary(in.op)) s << " r" << in.b;
        if (in.op == Op::kPowInt || in.op == Op::kPowHalf) s << ' ' << imm;
    }
    s << '\n';
  }
  s << "out";
  for (std::uint32_t o : outputs_) s << " r" << o;
  s << '\n';
  return s.str();
}

}  // namespace phiq
