// expression_jet_rate() (parts/expression_rate.hpp): the value tape's Taylor pass (expression/taylor.hpp) over dual
// numbers, the path's q̈ folded into its loads (q + σ q̇ + σ²/2 q̈), so that one pass gives the jet and its rate.
#include "parts/expression_rate.hpp"

#include <cmath>
#include <type_traits>

#include "expression/taylor.hpp"
#include "parts/frame_rates.hpp"

namespace phiq::detail {

namespace {

// The Taylor coefficients of the inputs along the path, their rates along p in the ε part (T = Dual) or none (T =
// double: a copy's jet).
template <class T>
struct ExpressionRateLoads {
  const MotionRates& m;
  Index k;
  Taylor<T> time;
  static T scalar(double value, double rate) {
    if constexpr (std::is_same_v<T, Dual>)
      return Dual(value, rate);
    else
      return value;
  }
  Taylor<T> coordinate(std::uint32_t j) const {
    const T at = scalar(m.q[j], m.s[j]);
    if (k >= 0) return {at, T(static_cast<Index>(j) == k ? 1.0 : 0.0), T(0.0)};
    return {at, scalar(m.qd[j], m.sd[j]), m.qdd ? scalar(0.5 * m.qdd[j], 0.5 * m.sdd[j]) : T(0.0)};
  }
  T velocity(std::uint32_t) const { return T(std::nan("")); }  // (an expression's tape reads no q̇)
};

// The jet (value, d/dσ, d²/dσ²) of e along the path.
template <class T>
JetT<T> expression_jet(const CompiledExpression& e, const MotionRates& m, Index k) {
  const Taylor<T> time{T(m.t), T(k >= 0 ? 0.0 : 1.0), T(0.0)};
  const Taylor<T> w = taylor2<T>(TapeInternals::value(e), ExpressionRateLoads<T>{m, k, time});
  return {w.v, w.d, k >= 0 ? T(0.0) : 2.0 * w.h};
}

}  // namespace

JetT<Dual> expression_jet_rate(const CompiledExpression& e, const std::array<const CompiledExpression*, 4>* copies,
                               double h, const MotionRates& m, Index k) {
  JetT<Dual> j = expression_jet<Dual>(e, m, k);
  if (!copies) return j;
  JetT<double> x[4];
  for (std::size_t c = 0; c < 4; ++c) x[c] = expression_jet<double>(*(*copies)[c], m, k);
  auto rate = [&](double JetT<double>::*part) {
    const double at[4] = {x[0].*part, x[1].*part, x[2].*part, x[3].*part};
    return copies_rate(at, h);
  };
  j.v.e += rate(&JetT<double>::v), j.d.e += rate(&JetT<double>::d), j.dd.e += rate(&JetT<double>::dd);
  return j;
}

}  // namespace phiq::detail
