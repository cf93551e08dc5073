// generalized_force_rate() (parts/force_rate.hpp): Q of add_generalized_forces() and add_applied_forces() again,
// term by term, in dual numbers whose ε part is the rate along p.
#include "parts/force_rate.hpp"

#include <algorithm>
#include <cmath>

#include "expression/dual.hpp"
#include "parts/expression_rate.hpp"
#include "parts/frame_jets.hpp"
#include "parts/frame_rates.hpp"
#include "parts/same_forces.hpp"
#include "phiq/applied_loads.hpp"
#include "phiq/output_joints.hpp"

namespace phiq::detail {

namespace {

using DJ = JetT<Dual>;

// A 3-vector of duals.
struct DV {
  Dual x, y, z;
};
DV operator+(const DV& a, const DV& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
DV operator-(const DV& a, const DV& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
DV operator*(Dual k, const DV& a) { return {k * a.x, k * a.y, k * a.z}; }
Dual dot(const DV& a, const DV& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
DV cross(const DV& a, const DV& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
DV constant_vector(kin3::V3 v, kin3::V3 rate = {}) { return {{v.x, rate.x}, {v.y, rate.y}, {v.z, rate.z}}; }
// R v, R row-major.
DV turned(const Dual r[9], const DV& v) {
  return {r[0] * v.x + r[1] * v.y + r[2] * v.z, r[3] * v.x + r[4] * v.y + r[5] * v.z,
          r[6] * v.x + r[7] * v.y + r[8] * v.z};
}
// Rᵀ v.
DV turned_back(const Dual r[9], const DV& v) {
  return {r[0] * v.x + r[3] * v.y + r[6] * v.z, r[1] * v.x + r[4] * v.y + r[7] * v.z,
          r[2] * v.x + r[5] * v.y + r[8] * v.z};
}
// The vector of the antisymmetric part of m.
DV vee(const Dual m[9]) { return {0.5 * (m[7] - m[5]), 0.5 * (m[2] - m[6]), 0.5 * (m[3] - m[1])}; }

// The path q + ε s (and q̇ + ε ṡ, q̈ + ε s̈) along the motion, or along coordinate k (a Jacobian column).
struct DualPath {
  const double *q, *qd, *qdd, *s, *sd, *sdd;
  double t = 0.0;
  Index k = -1;
  const FrameRates* rates = nullptr;  // the walked frame's data's rates along p (none: 0)

  DJ slot(const Slot& sl) const {
    if (!sl.is_coordinate()) return {Dual(sl.value(), rates ? rates->of(sl) : 0.0), Dual(), Dual()};
    const Index j = sl.coord();
    if (k >= 0) return {Dual(q[j], s[j]), Dual(j == k ? 1.0 : 0.0), Dual()};
    return {Dual(q[j], s[j]), Dual(qd[j], sd[j]), qdd ? Dual(qdd[j], sdd[j]) : Dual()};
  }
  JetV<Dual> natural(const Attachment3& a) const { return {slot(a.r[0]), slot(a.r[1]), slot(a.r[2])}; }
  std::array<Dual, 3> axis(const PartFrame& f) const {
    const kin3::V3 r = rates ? rates->axis : kin3::V3{};
    return {Dual(f.axis.x, r.x), Dual(f.axis.y, r.y), Dual(f.axis.z, r.z)};
  }
  // Along the motion through the expression's Taylor pass in dual numbers, along p through its copies' jets.
  DJ expression(const CompiledExpression& e) const {
    return expression_jet_rate(e, rates ? rates->copies_of(e) : nullptr, rates ? rates->step : 1.0,
                               {q, qd, qdd, s, sd, sdd, t}, k);
  }
  // This path over a frame whose constants move along p at `r`.
  DualPath over(const FrameRates& r) const {
    DualPath p = *this;
    p.rates = &r;
    return p;
  }
};

// A frame's pose and motion along the path, with their rates.
struct DualMotion {
  DV at, velocity, acceleration, omega, alpha;
  Dual rotation[9];
  // The velocity of the body point `s` (frame axes) and where it is, R s from the origin.
  DV arm(const DV& s) const { return turned(rotation, s); }
};

DualMotion dual_motion(const PartFrame& f, const DualPath& p) {
  const auto [o, r] = frame_jets<Dual>(f, p);
  DualMotion m;
  m.at = {o[0].v, o[1].v, o[2].v}, m.velocity = {o[0].d, o[1].d, o[2].d};
  m.acceleration = {o[0].dd, o[1].dd, o[2].dd};
  for (int i = 0; i < 9; ++i) m.rotation[i] = r[i].v;
  Dual w[9], a[9];
  product_transposed<Dual>(r, &DJ::d, r, &DJ::v, w);
  product_transposed<Dual>(r, &DJ::dd, r, &DJ::v, a);
  m.omega = vee(w), m.alpha = vee(a);
  return m;
}

// The frame's Jacobian columns with their rates: origin and angle per coordinate it reads.
struct DualJacobian {
  std::vector<Index> coordinates;
  std::vector<DV> d_origin, d_angle;
};

void dual_jacobian(const PartFrame& f, const DualPath& along, DualJacobian& j) {
  frame_coordinates(f, j.coordinates);
  j.d_origin.clear(), j.d_angle.clear();
  for (const Index k : j.coordinates) {
    DualPath p = along;
    p.k = k;
    const auto [o, r] = frame_jets<Dual>(f, p);
    Dual w[9];
    product_transposed<Dual>(r, &DJ::d, r, &DJ::v, w);
    j.d_origin.push_back({o[0].d, o[1].d, o[2].d});
    j.d_angle.push_back(vee(w));
  }
}

// dq_k += ε part of (∂x/∂q_k) · F + ∂θ/∂q_k · M for the force F at the arm R s from the frame's origin.
void add_force_rate(const DualJacobian& j, const DV& arm, const DV& force, const DV& moment, Eigen::VectorXd& dq) {
  for (std::size_t i = 0; i < j.coordinates.size(); ++i)
    dq[j.coordinates[i]] += (dot(j.d_origin[i] + cross(j.d_angle[i], arm), force) + dot(j.d_angle[i], moment)).e;
}

// The rate along p of the datum `get` reads of the four copies along p (the fourth-order difference over h: exact
// for a datum linear in p), `own` standing for a copy that is null.
template <class Source, class Get>
double datum_rate(const std::array<const Source*, 4>& along, const Source& own, double h, Get get) {
  double x[4];
  for (std::size_t k = 0; k < 4; ++k) x[k] = get(along[k] ? *along[k] : own);
  return copies_rate(x, h);
}

// The generalized inertia forces and weight of every part with mass, as add_generalized_forces() sums them.
bool add_parts_rate(const std::vector<Part>& parts, const Loads& loads, const ForcesAlong& along,
                    const DualPath& along_motion, Eigen::VectorXd& dq) {
  std::array<const std::vector<Part>*, 4> ap = along.parts;
  for (const auto* a : ap)
    if (a && a->size() != parts.size()) return false;
  const double h = along.step;
  const DV g = constant_vector(loads.gravity, vector_rate({(along.loads[0] ? *along.loads[0] : loads).gravity,
                                                           (along.loads[1] ? *along.loads[1] : loads).gravity,
                                                           (along.loads[2] ? *along.loads[2] : loads).gravity,
                                                           (along.loads[3] ? *along.loads[3] : loads).gravity},
                                                          h));
  thread_local DualJacobian jac;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Part& own = parts[i];
    std::array<const Part*, 4> copies{};
    bool massive = own.mass_source != MassSource::kNone && own.mass.mass != 0.0;
    std::array<const PartFrame*, 4> frames{};
    for (std::size_t k = 0; k < 4; ++k) {
      copies[k] = ap[k] ? &(*ap[k])[i] : nullptr;
      if (!copies[k]) continue;
      frames[k] = &copies[k]->frame;
      massive = massive || (copies[k]->mass_source != MassSource::kNone && copies[k]->mass.mass != 0.0);
    }
    if (!massive) continue;
    FrameRates rates;
    if (!frame_rates(own.frame, frames, h, rates)) return false;
    const DualPath path = along_motion.over(rates);
    const Dual m(own.mass.mass, datum_rate(copies, own, h, [](const Part& p) { return p.mass.mass; }));
    std::array<kin3::V3, 4> centres;
    for (std::size_t k = 0; k < 4; ++k) centres[k] = (copies[k] ? *copies[k] : own).mass.center;
    const DV centre = constant_vector(own.mass.center, vector_rate(centres, h));
    Dual inertia[9];
    for (std::size_t e = 0; e < 9; ++e)
      inertia[e] =
          Dual(own.mass.inertia[e], datum_rate(copies, own, h, [e](const Part& p) { return p.mass.inertia[e]; }));
    const DualMotion mo = dual_motion(own.frame, path);
    const DV c = mo.arm(centre);
    const DV ac = mo.acceleration + cross(mo.alpha, c) + cross(mo.omega, cross(mo.omega, c));
    const DV force = m * (g - ac);
    // R I Rᵀ v: the inertia about the centre in world axes
    auto world_inertia = [&](const DV& v) {
      const DV b = turned_back(mo.rotation, v);
      const DV ib{inertia[0] * b.x + inertia[1] * b.y + inertia[2] * b.z,
                  inertia[3] * b.x + inertia[4] * b.y + inertia[5] * b.z,
                  inertia[6] * b.x + inertia[7] * b.y + inertia[8] * b.z};
      return turned(mo.rotation, ib);
    };
    const DV moment = Dual(-1.0) * (world_inertia(mo.alpha) + cross(mo.omega, world_inertia(mo.omega)));
    dual_jacobian(own.frame, path, jac);
    add_force_rate(jac, c, force, moment, dq);
  }
  return true;
}

// The rates of the frame `frame_of` reads of `own` and of its copies along p (frame_rates()).
template <class Get>
bool load_frame_rates(const std::array<const AppliedLoads*, 4>& along, const PartFrame& own, double h, Get frame_of,
                      FrameRates& out) {
  std::array<const PartFrame*, 4> frames{};
  for (std::size_t k = 0; k < 4; ++k) frames[k] = &frame_of(*along[k]);
  return frame_rates(own, frames, h, out);
}

// An expression's value with its rate: ∇e · s + ∂e/∂q̇ · ṡ along the motion (a load's der() reads q̇; without q̇
// on the path, at rest, it reads 0), and the difference of its copies along p.
Dual expression_dual(const CompiledExpression& e, const std::array<const CompiledExpression*, 4>& copies, double h,
                     const DualPath& p) {
  thread_local std::vector<double> g;
  const std::vector<Index>& c = e.coordinates();
  g.resize(c.size());
  e.gradient(p.q, p.qd, p.t, g.data());
  double rate = 0.0, x[4];
  for (std::size_t i = 0; i < c.size(); ++i) rate += g[i] * p.s[c[i]];
  if (const std::vector<Index>& r = e.rate_coordinates(); !r.empty() && p.qd) {
    g.resize(r.size());
    e.rate_gradient(p.q, p.qd, p.t, g.data());
    for (std::size_t i = 0; i < r.size(); ++i) rate += g[i] * p.sd[r[i]];
  }
  for (std::size_t k = 0; k < 4; ++k) x[k] = copies[k]->value(p.q, p.qd, p.t);
  return {e.value(p.q, p.qd, p.t), rate + copies_rate(x, h)};
}

using Components = std::array<LoadValue, 3>;

// A law f of an argument u with their rates: f(u), f′(u) u̇ + the difference of the copies' laws at u along p.
Dual law_dual(const MotionLaw& f, const std::array<const MotionLaw*, 4>& copies, double h, Dual u) {
  const LawValue at = f.evaluate(u.v);
  double x[4];
  for (std::size_t k = 0; k < 4; ++k) x[k] = copies[k]->evaluate(u.v).f;
  return {at.f, at.df * u.e + copies_rate(x, h)};
}

// A spring's elastic tension or moment as its law of the deflection (its rate included), into `out`: false where a
// copy along p has no law.
template <class Get>
bool spring_law_dual(const MotionLaw& law, const std::array<const AppliedLoads*, 4>& along, double h, Dual deflection,
                     Dual& out, Get law_of) {
  std::array<const MotionLaw*, 4> copies{};
  for (std::size_t k = 0; k < 4; ++k)
    if (!(copies[k] = law_of(*along[k]))->has_value()) return false;
  out = law_dual(law, copies, h, deflection);
  return true;
}

// A load's value (LoadValue: an expression, or a law of one) with its rate, into `out` (0 where it has none):
// false where a copy along p has another form.
bool value_dual(const LoadValue& own, const std::array<const LoadValue*, 4>& copies, double h, const DualPath& p,
                Dual& out) {
  std::array<const CompiledExpression*, 4> exprs{};
  std::array<const MotionLaw*, 4> laws{};
  for (std::size_t k = 0; k < 4; ++k) {
    const LoadValue& x = *copies[k];
    if ((x.expr == nullptr) != (own.expr == nullptr) || x.law.has_value() != own.law.has_value()) return false;
    exprs[k] = x.expr.get(), laws[k] = &x.law;
  }
  out = Dual();
  if (!own.expr) return true;
  out = expression_dual(*own.expr, exprs, h, p);
  if (own.law.has_value()) out = law_dual(own.law, laws, h, out);
  return true;
}

// A spring's actuator with its rate, added to `out` (value_dual() over the copies' `value_of`).
template <class Get>
bool add_value_dual(const LoadValue& own, const std::array<const AppliedLoads*, 4>& along, double h, const DualPath& p,
                    Dual& out, Get value_of) {
  std::array<const LoadValue*, 4> copies{};
  for (std::size_t k = 0; k < 4; ++k) copies[k] = &value_of(*along[k]);
  Dual v;
  if (!value_dual(own, copies, h, p, v)) return false;
  out = out + v;
  return true;
}

// A force's or torque's components in world axes with their rates (world_components()); false where a component
// has another form in one copy along p.
bool components_dual(const Components& own, const std::array<const Components*, 4>& copies, LoadAxes axes,
                     const DualMotion& mo, double h, const DualPath& p, DV& out) {
  Dual v[3];
  for (std::size_t c = 0; c < 3; ++c) {
    std::array<const LoadValue*, 4> along{};
    for (std::size_t k = 0; k < 4; ++k) along[k] = &(*copies[k])[c];
    if (!value_dual(own[c], along, h, p, v[c])) return false;
  }
  out = {v[0], v[1], v[2]};
  if (axes == LoadAxes::kPart) out = turned(mo.rotation, out);
  return true;
}

// The rate of a datum of the k-th copy of an applied load (datum_rate() over AppliedLoads).
template <class Get>
double load_rate(const std::array<const AppliedLoads*, 4>& along, double h, Get get) {
  double x[4];
  for (std::size_t k = 0; k < 4; ++k) x[k] = get(*along[k]);
  return copies_rate(x, h);
}

kin3::V3 load_vector_rate(const std::array<const AppliedLoads*, 4>& along, double h,
                          kin3::V3 (*get)(const AppliedLoads&, std::size_t), std::size_t i) {
  return vector_rate({get(*along[0], i), get(*along[1], i), get(*along[2], i), get(*along[3], i)}, h);
}

bool add_forces_and_torques_rate(const AppliedLoads& loads, const std::array<const AppliedLoads*, 4>& along, double h,
                                 const DualPath& along_motion, Eigen::VectorXd& dq) {
  thread_local DualJacobian jac;
  for (std::size_t i = 0; i < loads.forces.size(); ++i) {
    const AppliedForce& f = loads.forces[i];
    FrameRates rates;
    if (!load_frame_rates(
            along, f.frame, h, [i](const AppliedLoads& a) -> const PartFrame& { return a.forces[i].frame; }, rates))
      return false;
    const DualPath path = along_motion.over(rates);
    std::array<const Components*, 4> copies{};
    for (std::size_t k = 0; k < 4; ++k) {
      if (along[k]->forces[i].axes != f.axes) return false;
      copies[k] = &along[k]->forces[i].components;
    }
    const DualMotion mo = dual_motion(f.frame, path);
    DV force;
    if (!components_dual(f.components, copies, f.axes, mo, h, path, force)) return false;
    const DV at =
        constant_vector(f.at, load_vector_rate(
                                  along, h, [](const AppliedLoads& a, std::size_t j) { return a.forces[j].at; }, i));
    dual_jacobian(f.frame, path, jac);
    add_force_rate(jac, mo.arm(at), force, DV{}, dq);
  }
  for (std::size_t i = 0; i < loads.torques.size(); ++i) {
    const AppliedTorque& m = loads.torques[i];
    FrameRates rates;
    if (!load_frame_rates(
            along, m.frame, h, [i](const AppliedLoads& a) -> const PartFrame& { return a.torques[i].frame; }, rates))
      return false;
    const DualPath path = along_motion.over(rates);
    std::array<const Components*, 4> copies{};
    for (std::size_t k = 0; k < 4; ++k) {
      if (along[k]->torques[i].axes != m.axes) return false;
      copies[k] = &along[k]->torques[i].components;
    }
    const DualMotion mo = dual_motion(m.frame, path);
    DV moment;
    if (!components_dual(m.components, copies, m.axes, mo, h, path, moment)) return false;
    dual_jacobian(m.frame, path, jac);
    add_force_rate(jac, DV{}, DV{}, moment, dq);
  }
  return true;
}

bool add_springs_rate(const AppliedLoads& loads, const std::array<const AppliedLoads*, 4>& along, double h,
                      const DualPath& along_motion, Eigen::VectorXd& dq) {
  thread_local DualJacobian jac;
  for (std::size_t i = 0; i < loads.springs.size(); ++i) {
    const LinearSpring& sp = loads.springs[i];
    FrameRates rates_a, rates_b;
    if (!load_frame_rates(
            along, sp.a.frame, h, [i](const AppliedLoads& a) -> const PartFrame& { return a.springs[i].a.frame; },
            rates_a) ||
        !load_frame_rates(
            along, sp.b.frame, h, [i](const AppliedLoads& a) -> const PartFrame& { return a.springs[i].b.frame; },
            rates_b))
      return false;
    const DualPath path_a = along_motion.over(rates_a), path_b = along_motion.over(rates_b);
    const DualMotion ma = dual_motion(sp.a.frame, path_a), mb = dual_motion(sp.b.frame, path_b);
    const DV ra = ma.arm(constant_vector(
                 sp.a.at, load_vector_rate(
                              along, h, [](const AppliedLoads&a, std::size_t j) { return a.springs[j].a.at; }, i))),
             rb = mb.arm(constant_vector(
                 sp.b.at, load_vector_rate(
                              along, h, [](const AppliedLoads&a, std::size_t j) { return a.springs[j].b.at; }, i)));
    const DV d = (mb.at + rb) - (ma.at + ra);
    const Dual length = sqrt(dot(d, d));
    if (length.v == 0.0) continue;  // no direction: no force (LinearSpring)
    const DV unit = (1.0 / length) * d;
    const Dual rate =
        along_motion.qd ? dot(unit, (mb.velocity + cross(mb.omega, rb)) - (ma.velocity + cross(ma.omega, ra))) : Dual();
    auto datum = [&](double LinearSpring::*field) {
      return Dual(sp.*field, load_rate(along, h, [&](const AppliedLoads& a) { return a.springs[i].*field; }));
    };
    const Dual stretch = length - datum(&LinearSpring::free_length);
    Dual elastic = datum(&LinearSpring::stiffness) * stretch;
    if (sp.law.has_value() &&
        !spring_law_dual(sp.law, along, h, stretch, elastic, [i](const AppliedLoads& a) { return &a.springs[i].law; }))
      return false;
    // a dry friction's f sign(L̇): its rate along p f′ sign(L̇) (sign's own is 0 wherever it is defined)
    const Dual dry(friction_direction(rate.v));
    Dual tension = elastic + datum(&LinearSpring::damping) * rate + datum(&LinearSpring::friction) * dry +
                   datum(&LinearSpring::preload);
    if (!add_value_dual(sp.tension, along, h, along_motion, tension,
                        [i](const AppliedLoads& a) -> const LoadValue& { return a.springs[i].tension; }))
      return false;
    dual_jacobian(sp.a.frame, path_a, jac);
    add_force_rate(jac, ra, tension * unit, DV{}, dq);
    dual_jacobian(sp.b.frame, path_b, jac);
    add_force_rate(jac, rb, Dual(-1.0) * (tension * unit), DV{}, dq);
  }
  return true;
}

// γ(q, a) − γ(q, b) − …: the polarisation of γ, quadratic in q̇ at fixed q: −8 aᵀ H b, H the Hessian of e (its
// linear and constant terms, ∂t∇e and ∂²e/∂t², cancel).
double hessian_form(const CompiledExpression& e, const double* q, double t, const std::vector<double>& a,
                    const std::vector<double>& b, std::vector<double>& scratch) {
  const double sign[4][2] = {{1, 1}, {-1, -1}, {1, -1}, {-1, 1}};
  double g[4];
  for (int k = 0; k < 4; ++k) {
    for (std::size_t i = 0; i < a.size(); ++i) scratch[i] = sign[k][0] * a[i] + sign[k][1] * b[i];
    g[k] = e.gamma(q, scratch.data(), t);
  }
  return -((g[0] + g[1]) - (g[2] + g[3])) / 8.0;
}

// A torsional spring's θ, θ̇ and ∂θ/∂q over its coordinates, each with its rate along p.
struct AngleRates {
  Dual angle, rate;
  std::vector<Dual> gradient;
};

// θ an expression: ∂θ/∂q's rate H s by the polarisation of γ, θ̇'s from γ at q̇ ± s.
bool expression_angle_rates(const TorsionalSpring& ts, std::size_t i, const std::array<const AppliedLoads*, 4>& along,
                            double h, const DualPath& path, Index n, AngleRates& out) {
  thread_local std::vector<double> a, b, scratch, g;
  a.assign(static_cast<std::size_t>(n), 0.0), b.assign(a.size(), 0.0), scratch.assign(a.size(), 0.0);
  std::array<const CompiledExpression*, 4> copies{};
  for (std::size_t k = 0; k < 4; ++k)
    if (!(copies[k] = along[k]->torsional_springs[i].angle.get())) return false;
  const CompiledExpression& e = *ts.angle;
  const std::vector<Index>& c = e.coordinates();
  g.resize(c.size());
  e.gradient(path.q, path.t, g.data());
  double smax = 0.0;
  for (Index j = 0; j < n; ++j) smax = std::max(smax, std::fabs(path.s[j]));
  const double alpha = smax > 0.0 ? 1.0 / smax : 0.0;  // s scaled to unit size: γ's rounding near its own
  for (Index j = 0; j < n; ++j) a[static_cast<std::size_t>(j)] = alpha * path.s[j];
  // ∂θ/∂q with its rate: H s, and the difference of the copies' gradients along p
  out.gradient.resize(c.size());
  thread_local std::array<std::vector<double>, 4> along_g;  // capacity kept from row to row
  for (std::size_t k = 0; k < 4; ++k) {
    along_g[k].resize(c.size());
    if (copies[k]->coordinates() != c) return false;
    copies[k]->gradient(path.q, path.t, along_g[k].data());
  }
  for (std::size_t l = 0; l < c.size(); ++l) {
    b[static_cast<std::size_t>(c[l])] = 1.0;
    const double hs = alpha > 0.0 ? hessian_form(e, path.q, path.t, a, b, scratch) / alpha : 0.0;
    b[static_cast<std::size_t>(c[l])] = 0.0;
    const double x[4] = {along_g[0][l], along_g[1][l], along_g[2][l], along_g[3][l]};
    out.gradient[l] = Dual(g[l], hs + copies_rate(x, h));
  }
  out.angle = expression_dual(e, copies, h, path);
  out.rate = Dual();
  if (path.qd) {
    // θ̇ = ∂e/∂t + ∇e · q̇; along the motion ∂t∇e · s + sᵀ H q̇ + ∇e · ṡ, the first two −[γ(q̇ + s) − γ(q̇ − s)]/4
    auto theta_dot = [&](const CompiledExpression& x, const std::vector<double>& grad) {
      double r = x.partial_t(path.q, path.t);
      for (std::size_t l = 0; l < c.size(); ++l) r += grad[l] * path.qd[c[l]];
      return r;
    };
    double along_rate = 0.0;
    for (std::size_t l = 0; l < c.size(); ++l) along_rate += g[l] * path.sd[c[l]];
    for (Index j = 0; j < n; ++j) scratch[static_cast<std::size_t>(j)] = path.qd[j] + path.s[j];
    const double plus = e.gamma(path.q, scratch.data(), path.t);
    for (Index j = 0; j < n; ++j) scratch[static_cast<std::size_t>(j)] = path.qd[j] - path.s[j];
    along_rate -= (plus - e.gamma(path.q, scratch.data(), path.t)) / 4.0;
    double x[4];
    for (std::size_t k = 0; k < 4; ++k) x[k] = theta_dot(*copies[k], along_g[k]);
    out.rate = Dual(theta_dot(e, g), along_rate + copies_rate(x, h));
  }
  return true;
}

// θ a spatial joint's angle: evaluate_joint()'s acceleration at q̈ = 0 is q̇ᵀ H q̇ exactly (the part of Ẍ without q̈
// is quadratic in q̇), so uᵀ H v = [θ̈(u + v) − θ̈(u − v)]/4, with no step; along p the copies' joints.
bool joint_angle_rates(const TorsionalSpring& ts, std::size_t i, const std::array<const AppliedLoads*, 4>& along,
                       double h, const DualPath& path, Index n, AngleRates& out) {
  const std::vector<Index>& c = ts.joint_coordinates;
  std::array<const OutputJoint*, 4> copies{};
  for (std::size_t k = 0; k < 4; ++k) {
    const TorsionalSpring& x = along[k]->torsional_springs[i];
    if (!x.joint || x.joint_coordinates != c) return false;
    copies[k] = &*x.joint;
  }
  const OutputJoint& joint = *ts.joint;
  thread_local std::vector<double> u, w, zero, g;  // (only the entries at c are read)
  u.assign(static_cast<std::size_t>(n), 0.0), w.assign(u.size(), 0.0), zero.assign(u.size(), 0.0);
  auto quadratic = [&] { return evaluate_joint(joint, path.q, w.data(), zero.data()).acceleration; };
  // uᵀ H v over c for the directions x, y scaled to unit size (the rounding of θ̈ near its own); 0 if either is 0
  auto hessian = [&](const double* x, const double* y) {
    double xm = 0.0, ym = 0.0;
    for (const Index j : c) xm = std::max(xm, std::fabs(x[j])), ym = std::max(ym, std::fabs(y[j]));
    if (xm == 0.0 || ym == 0.0) return 0.0;
    for (const Index j : c) w[static_cast<std::size_t>(j)] = x[j] / xm + y[j] / ym;
    const double plus = quadratic();
    for (const Index j : c) w[static_cast<std::size_t>(j)] = x[j] / xm - y[j] / ym;
    return (plus - quadratic()) * xm * ym / 4.0;
  };
  g.resize(c.size()), out.gradient.resize(c.size());
  double x[4], along_angle = 0.0;
  for (std::size_t l = 0; l < c.size(); ++l) {
    u[static_cast<std::size_t>(c[l])] = 1.0;
    g[l] = evaluate_joint(joint, path.q, u.data(), nullptr).rate;
    for (std::size_t k = 0; k < 4; ++k) x[k] = evaluate_joint(*copies[k], path.q, u.data(), nullptr).rate;
    out.gradient[l] = Dual(g[l], hessian(path.s, u.data()) + copies_rate(x, h));
    u[static_cast<std::size_t>(c[l])] = 0.0;
    along_angle += g[l] * path.s[c[l]];
  }
  // the copies' angles from the own one, within a turn
  const double theta = evaluate_joint(joint, path.q, nullptr, nullptr).value;
  for (std::size_t k = 0; k < 4; ++k)
    x[k] = std::remainder(evaluate_joint(*copies[k], path.q, nullptr, nullptr).value - theta, 2.0 * M_PI);
  out.angle = Dual(theta, along_angle + copies_rate(x, h));
  out.rate = Dual();
  if (path.qd) {
    // θ̇ = ∇θ · q̇ (add_applied_forces()); along the motion sᵀ H q̇ + ∇θ · ṡ
    double rate = 0.0, along_rate = hessian(path.s, path.qd);
    for (std::size_t l = 0; l < c.size(); ++l) rate += g[l] * path.qd[c[l]], along_rate += g[l] * path.sd[c[l]];
    for (std::size_t k = 0; k < 4; ++k) x[k] = evaluate_joint(*copies[k], path.q, path.qd, nullptr).rate;
    out.rate = Dual(rate, along_rate + copies_rate(x, h));
  }
  return true;
}

// A rotor's J θ̈ with its rate, added to `moment`: θ̈ from the angle's jet along the motion, exact with its third
// derivatives (parts/expression_rate.hpp); false for a spatial joint's angle (its θ̈'s rate along p reads the
// joint's third derivatives, which it has not: Q is differenced) or without q̈.
bool add_rotor_dual(const TorsionalSpring& ts, std::size_t i, const std::array<const AppliedLoads*, 4>& along, double h,
                    const DualPath& path, Dual inertia, Dual& moment) {
  if (inertia.v == 0.0 && inertia.e == 0.0) return true;
  if (!ts.angle || !path.qd || !path.qdd) return false;
  std::array<const CompiledExpression*, 4> copies{};
  for (std::size_t k = 0; k < 4; ++k)
    if (!(copies[k] = along[k]->torsional_springs[i].angle.get()) ||
        copies[k]->coordinates() != ts.angle->coordinates())
      return false;
  const MotionRates m{path.q, path.qd, path.qdd, path.s, path.sd, path.sdd, path.t};
  moment = moment + inertia * expression_jet_rate(*ts.angle, &copies, h, m, -1).dd;
  return true;
}

bool add_torsional_rate(const AppliedLoads& loads, const std::array<const AppliedLoads*, 4>& along, double h,
                        const DualPath& path, Index n, Eigen::VectorXd& dq) {
  thread_local AngleRates st;
  for (std::size_t i = 0; i < loads.torsional_springs.size(); ++i) {
    const TorsionalSpring& ts = loads.torsional_springs[i];
    if (!(ts.angle ? expression_angle_rates(ts, i, along, h, path, n, st)
                   : joint_angle_rates(ts, i, along, h, path, n, st)))
      return false;
    auto datum = [&](double TorsionalSpring::*field) {
      return Dual(ts.*field, load_rate(along, h, [&](const AppliedLoads& x) { return x.torsional_springs[i].*field; }));
    };
    Dual angle = st.angle - datum(&TorsionalSpring::free_angle);
    if (!ts.angle) angle.v = std::remainder(angle.v, 2.0 * M_PI);  // a joint's: within a turn (angle_from_free())
    Dual elastic = datum(&TorsionalSpring::stiffness) * angle;
    if (ts.law.has_value() && !spring_law_dual(ts.law, along, h, angle, elastic,
                                               [i](const AppliedLoads& a) { return &a.torsional_springs[i].law; }))
      return false;
    const Dual dry(friction_direction(st.rate.v));  // (as a spring's friction)
    Dual moment = elastic + datum(&TorsionalSpring::damping) * st.rate + datum(&TorsionalSpring::friction) * dry;
    if (!add_rotor_dual(ts, i, along, h, path, datum(&TorsionalSpring::inertia), moment)) return false;
    if (!add_value_dual(ts.moment, along, h, path, moment,
                        [i](const AppliedLoads& a) -> const LoadValue& { return a.torsional_springs[i].moment; }))
      return false;
    const std::vector<Index>& c = ts.angle ? ts.angle->coordinates() : ts.joint_coordinates;
    for (std::size_t l = 0; l < c.size(); ++l) dq[c[l]] -= (moment * st.gradient[l]).e;
  }
  return true;
}

bool add_applied_rate(const AppliedLoads& loads, const std::array<const AppliedLoads*, 4>& along, double h,
                      const DualPath& path, Index n, Eigen::VectorXd& dq) {
  for (const AppliedLoads* a : along)
    if (a->forces.size() != loads.forces.size() || a->torques.size() != loads.torques.size() ||
        a->springs.size() != loads.springs.size() || a->torsional_springs.size() != loads.torsional_springs.size())
      return false;
  return add_forces_and_torques_rate(loads, along, h, path, dq) && add_springs_rate(loads, along, h, path, dq) &&
         add_torsional_rate(loads, along, h, path, n, dq);
}

}  // namespace

bool generalized_force_rate(const std::vector<Part>& parts, const Loads& loads, const ForcesAlong& along,
                            const double* q, const double* qd, const double* qdd, const double* s, const double* sd,
                            const double* sdd, double t, Eigen::VectorXd& dq) {
  dq.setZero();
  const DualPath path{q, qd, qdd, s, sd, sdd, t};
  if (!add_parts_rate(parts, loads, along, path, dq)) return false;
  std::array<const AppliedLoads*, 4> applied{};
  for (std::size_t k = 0; k < 4; ++k) {
    const Loads* l = along.loads[k] ? along.loads[k] : &loads;
    applied[k] = l->applied.get();
    if ((applied[k] == nullptr || applied[k]->empty()) != (!loads.applied || loads.applied->empty())) return false;
  }
  if (!loads.applied || loads.applied->empty()) return true;
  return add_applied_rate(*loads.applied, applied, along.step, path, dq.size(), dq);
}

}  // namespace phiq::detail
