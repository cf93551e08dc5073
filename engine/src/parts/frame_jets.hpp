// Internal: a frame's origin and axes in truncated Taylor arithmetic along a path (value, first and second
// derivative), over any scalar type T with +, −, ×, 1/x, sqrt, sin and cos: doubles for part_motion() and
// part_jacobian() (part_motion.cpp), dual numbers for their exact derivatives along a parameter (force_rate.cpp).
#pragma once

#include <array>
#include <cmath>

#include "phiq/parts.hpp"

namespace phiq::detail {

// A value with its first and second derivatives along the path.
template <class T>
struct JetT {
  T v{}, d{}, dd{};
};
template <class T>
JetT<T> operator+(const JetT<T>& a, const JetT<T>& b) {
  return {a.v + b.v, a.d + b.d, a.dd + b.dd};
}
template <class T>
JetT<T> operator-(const JetT<T>& a, const JetT<T>& b) {
  return {a.v - b.v, a.d - b.d, a.dd - b.dd};
}
template <class T>
JetT<T> operator*(const JetT<T>& a, const JetT<T>& b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2.0 * a.d * b.d + a.v * b.dd};
}
template <class T>
JetT<T> operator*(double k, const JetT<T>& a) {
  return {k * a.v, k * a.d, k * a.dd};
}
template <class T>
JetT<T> scaled(const T& k, const JetT<T>& a) {
  return {k * a.v, k * a.d, k * a.dd};
}
template <class T>
JetT<T> constant_jet(double c) {
  return {T(c), T(0.0), T(0.0)};
}
template <class T>
JetT<T> sqrt(const JetT<T>& a) {  // s² = a: 2 s s' = a', 2 s'² + 2 s s'' = a''
  using std::sqrt;
  const T s = sqrt(a.v), d = a.d / (2.0 * s);
  return {s, d, (a.dd - 2.0 * d * d) / (2.0 * s)};
}
template <class T>
JetT<T> inverse(const JetT<T>& a) {
  const T r = 1.0 / a.v;
  return {r, -a.d * r * r, -a.dd * r * r + 2.0 * a.d * a.d * r * r * r};
}
template <class T>
JetT<T> sin(const JetT<T>& a) {
  using std::cos, std::sin;
  const T s = sin(a.v), c = cos(a.v);
  return {s, c * a.d, c * a.dd - s * a.d * a.d};
}
template <class T>
JetT<T> cos(const JetT<T>& a) {
  using std::cos, std::sin;
  const T s = sin(a.v), c = cos(a.v);
  return {c, -s * a.d, -s * a.dd - c * a.d * a.d};
}

template <class T>
using JetV = std::array<JetT<T>, 3>;
template <class T>
using JetR = std::array<JetT<T>, 9>;  // row-major rotation

template <class T>
JetT<T> dot(const JetV<T>& a, const JetV<T>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
template <class T>
JetV<T> cross(const JetV<T>& a, const JetV<T>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
template <class T>
JetV<T> times(const JetT<T>& k, const JetV<T>& a) {
  return {k * a[0], k * a[1], k * a[2]};
}
template <class T>
JetV<T> minus(const JetV<T>& a, const JetV<T>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
template <class T>
JetR<T> columns(const JetV<T>& x, const JetV<T>& y, const JetV<T>& z) {
  return {x[0], y[0], z[0], x[1], y[1], z[1], x[2], y[2], z[2]};
}

template <class T>
JetR<T> about_z(const JetT<T>& psi) {
  const JetT<T> c = cos(psi), s = sin(psi), o = constant_jet<T>(0.0), one = constant_jet<T>(1.0);
  return {c, constant_jet<T>(0.0) - s, o, s, c, o, o, o, one};
}

// R(e/|e|) = (e0² − e·e) 1 + 2 e eᵀ + 2 e0 [e]×, e = (e1, e2, e3) after the normalisation.
template <class T>
JetR<T> from_euler(std::array<JetT<T>, 4> e) {
  const JetT<T> n = inverse(sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]));
  for (JetT<T>& x : e) x = n * x;
  const JetT<T> a = e[0] * e[0] - e[1] * e[1] - e[2] * e[2] - e[3] * e[3];
  JetR<T> r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[3 * i + j] = 2.0 * (e[1 + i] * e[1 + j]) + (i == j ? a : constant_jet<T>(0.0));
  const JetT<T> t1 = 2.0 * (e[0] * e[1]), t2 = 2.0 * (e[0] * e[2]), t3 = 2.0 * (e[0] * e[3]);
  r[1] = r[1] - t3, r[3] = r[3] + t3, r[2] = r[2] + t2, r[6] = r[6] - t2, r[5] = r[5] - t1, r[7] = r[7] + t1;
  return r;
}

// R = 1 + sin θ [u]× + (1 − cos θ) [u]×², u a unit axis, constant along the path (not along p: a dual's rate).
template <class T>
JetR<T> about_axis(const JetT<T>& th, const std::array<T, 3>& u) {
  const T o(0.0);
  const T k[9] = {o, -u[2], u[1], u[2], o, -u[0], -u[1], u[0], o};
  T k2[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) k2[3 * i + j] = k[3 * i] * k[j] + k[3 * i + 1] * k[3 + j] + k[3 * i + 2] * k[6 + j];
  const JetT<T> s = sin(th), c1 = constant_jet<T>(1.0) - cos(th);
  JetR<T> r;
  for (int i = 0; i < 9; ++i) r[i] = constant_jet<T>(i % 4 == 0 ? 1.0 : 0.0) + scaled(k[i], s) + scaled(k2[i], c1);
  return r;
}

// The frame's origin and axes as jets along the path `p`, whose slot(Slot), natural(Attachment3) and
// expression(CompiledExpression) give its inputs as jets of T, and axis(PartFrame) a frame of expressions' axis.
template <class T, class Path>
std::pair<JetV<T>, JetR<T>> frame_jets(const PartFrame& f, const Path& p) {
  const JetT<T> zero = constant_jet<T>(0.0);
  switch (f.kind) {
    case PartFrameKind::kPlanarBody:
      return {{p.slot(f.planar.x), p.slot(f.planar.y), zero}, about_z(p.slot(f.planar.psi))};
    case PartFrameKind::kSpatialBody: {
      const Frame3& b = f.spatial;
      return {{p.slot(b.x), p.slot(b.y), p.slot(b.z)},
              from_euler<T>({p.slot(b.e0), p.slot(b.e1), p.slot(b.e2), p.slot(b.e3)})};
    }
    case PartFrameKind::kPoints: {
      const JetV<T> o = p.natural(f.origin);
      JetV<T> x = p.natural(f.x_toward);
      if (f.x_is_point) x = minus(x, o);
      x = times(inverse(sqrt(dot(x, x))), x);
      if (!f.spatial_frame) return {o, columns<T>(x, {zero - x[1], x[0], zero}, {zero, zero, constant_jet<T>(1.0)})};
      JetV<T> w = p.natural(f.y_toward);
      if (f.y_is_point) w = minus(w, o);
      JetV<T> y = minus(w, times(dot(w, x), x));
      y = times(inverse(sqrt(dot(y, y))), y);
      return {o, columns(x, y, cross(x, y))};
    }
    case PartFrameKind::kExpressions: {
      JetV<T> o{zero, zero, zero};
      for (std::size_t k = 0; k < f.at.size() && k < 3; ++k) o[k] = p.expression(*f.at[k]);
      return {o, about_axis(f.angle ? p.expression(*f.angle) : zero, p.axis(f))};
    }
  }
  return {};
}

// a bᵀ of two rotations' jets' parts: which(a) which(b)ᵀ.
template <class T>
void product_transposed(const JetR<T>& a, T JetT<T>::*pa, const JetR<T>& b, T JetT<T>::*pb, T out[9]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      T s(0.0);
      for (int l = 0; l < 3; ++l) s = s + a[3 * i + l].*pa * (b[3 * j + l].*pb);
      out[3 * i + j] = s;
    }
}

}  // namespace phiq::detail
