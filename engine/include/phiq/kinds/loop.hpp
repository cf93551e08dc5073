/// @file
/// The closure of a kinematic loop in relative coordinates. One constraint kind: its equation, derivatives, validation,
/// joint count, sketch and scene form (the contract is documented on DistanceSpec; kinds/registry.hpp lists every
/// kind).
#pragma once

#include <cmath>
#include <tuple>
#include <array>
#include <vector>

#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Loop closure in relative coordinates: the links of a kinematic loop, each a vector of length ℓ_k (a constant or
/// a coordinate, e.g. a slider travel) at angle θ_k = offset_k + Σ_j sign_kj q_j (absolute angles, or the running
/// sums of relative joint angles as in the notes: ψ2, ψ2 + ψ3, ψ2 + ψ3 + ψ4), add up to the constant closure vector c:
///   Φ = Σ_k ℓ_k (cos θ_k, sin θ_k) − c                  (2 rows, lengths)
struct LoopSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const LoopSpec&) const = default;
  static constexpr int kRows = 2;  ///< two rows: x and y of the closure error, lengths
  /// @copydoc DistanceSpec::kKind
  /// Scene type `loop`.
  static constexpr const char* kKind = "loop";
  /// One term sign · q_j of the angle θ_k of a link.
  struct Term {
    bool operator==(const Term&) const = default;  ///< the slot and its factor
    Slot angle;         ///< q_j, an angle (rad): usually a coordinate (absolute or relative joint angle)
    double sign = 1.0;  ///< its factor in θ_k: +1 or −1 (any finite factor is accepted)
  };
  /// One link of the loop: the vector ℓ_k (cos θ_k, sin θ_k), with θ_k = offset + Σ_terms sign · q_j.
  struct Link {
    bool operator==(const Link&) const = default;  ///< datum by datum
    Slot length;              ///< ℓ_k (m): a constant link length, or a coordinate (e.g. a slider travel)
    double offset = 0.0;      ///< constant part of θ_k (rad), finite
    std::vector<Term> terms;  ///< the variable part of θ_k; empty for a link of constant direction
  };
  std::vector<Link> links;  ///< the links of the loop, at least one (checked when the constraint is added)
  kin::V2 closure{0, 0};    ///< c, the constant closure vector (m): (0, 0) when the loop returns to its start

  /// @copydoc DistanceSpec::depends_on_time
  /// A loop is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// Both rows of a loop are lengths.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a loop: the largest of |c| and the constant link lengths |ℓ_k| (lengths that are coordinates are not
  /// data).
  double characteristic_length() const {
    double l = std::hypot(closure.x, closure.y);
    for (const Link& k : links)
      if (!k.length.is_coordinate()) l = std::max(l, std::fabs(k.length.value()));
    return l;
  }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Loop
  /// A loop reads, link by link, the length ℓ_k (a length) and then the angle of each term (angles); an angle shared
  /// by several links is reported once per link.
  template <class F>
  void for_each_slot(F&& f) const {
    for (const Link& k : links) {
      f(k.length, Unit::kLength);
      for (const Term& t : k.terms) f(t.angle, Unit::kAngle);
    }
  }
  /// θ_k = offset + Σ sign · q_j, the angle of link `k` at coordinates `q` (rad). Thread-safe.
  /// @pre `q` has at least max_coordinate(spec) + 1 entries.
  double angle_of(const Link& k, const double* q) const {
    double th = k.offset;
    for (const Term& t : k.terms) th += t.sign * t.angle.of(q);
    return th;
  }
  /// θ̇_k = Σ sign · q̇_j, the angular velocity of link `k` at velocities `qd` (rad/s); the offset is constant.
  /// Thread-safe.
  /// @pre `qd` has at least max_coordinate(spec) + 1 entries.
  double rate_of(const Link& k, const double* qd) const {
    double w = 0.0;
    for (const Term& t : k.terms) w += t.sign * t.angle.rate(qd);
    return w;
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    double sx = -closure.x, sy = -closure.y;
    for (const Link& k : links) {
      double th = angle_of(k, q), l = k.length.of(q);
      sx += l * std::cos(th);
      sy += l * std::sin(th);
    }
    phi[0] = sx;
    phi[1] = sy;
  }
  /// @copydoc DistanceSpec::jacobian
  /// @par Loop
  /// A loop emits, link by link, ∂Φ/∂ℓ_k (both rows) and then the two entries of each angle term; an angle shared
  /// by several links gets one pair of entries per link, and these add up.
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    for (const Link& k : links) {
      double th = angle_of(k, q), l = k.length.of(q), cs = std::cos(th), sn = std::sin(th);
      s(0, k.length, cs), s(1, k.length, sn);
      for (const Term& t : k.terms) s(0, t.angle, -t.sign * l * sn), s(1, t.angle, t.sign * l * cs);
    }
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    // Φ̈ = Σ ℓ̈ e + (ℓ θ̈ + 2 ℓ̇ θ̇) perp(e) − ℓ θ̇² e  ⇒  γ = Σ ℓ θ̇² e − 2 ℓ̇ θ̇ perp(e)
    double gx = 0.0, gy = 0.0;
    for (const Link& k : links) {
      double th = angle_of(k, q), w = rate_of(k, qd), l = k.length.of(q), ld = k.length.rate(qd);
      double cs = std::cos(th), sn = std::sin(th);
      gx += l * w * w * cs + 2.0 * ld * w * sn;
      gy += l * w * w * sn - 2.0 * ld * w * cs;
    }
    out[0] = gx;
    out[1] = gy;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the links (constant lengths, offsets, constant
  /// angle terms and their factors) and the closure vector.
  static constexpr auto data_members() { return std::tuple{&LoopSpec::links, &LoopSpec::closure}; }
  /// Derivatives along the data (DistanceSpec::data_derivative()). Per link, with u = (cos θ, sin θ), u⊥ its turn
  /// by +90°, ω = θ̇ and α = θ̈ (Σ sign · q̇, q̈), and the data's rates ℓ̂ (a constant length), θ̂ = ô + Σ (ŝign q +
  /// sign q̂) (q̂ of a constant angle), ∂ω = Σ ŝign q̇, ∂α = Σ ŝign q̈:
  ///
  ///   ∂Φ/∂p = Σ ℓ̂ u + ℓ θ̂ u⊥ − ĉ,   ∂(Φq q̇)/∂p = Σ ℓ̇ θ̂ u⊥ + (ℓ̂ ω + ℓ ∂ω) u⊥ − ℓ ω θ̂ u,
  ///   ∂(Φq q̈ − γ)/∂p = Σ ℓ̈ θ̂ u⊥ + 2 ℓ̇ (∂ω u⊥ − ω θ̂ u) + ℓ̂ (α u⊥ − ω² u) + ℓ (∂α u⊥ − 2 ω ∂ω u)
  ///                    − ℓ θ̂ (α u + ω² u⊥).
  /// @pre `rate` has the links and terms of this loop (what datum_rate() makes).
  void data_derivative(const LoopSpec& rate, int order, const double* q, const double* qd, const double* qdd, double,
                       double* out) const {
    kin::V2 sum = order == 0 ? -1.0 * rate.closure : kin::V2{0, 0};
    for (std::size_t i = 0; i < links.size(); ++i) {
      const Link& k = links[i];
      const Link& r = rate.links[i];
      const double th = angle_of(k, q), l = k.length.of(q);
      const double lh = k.length.is_coordinate() ? 0.0 : r.length.value();
      double thh = r.offset, dw = 0.0, da = 0.0;
      for (std::size_t j = 0; j < k.terms.size(); ++j) {
        const Term& t = k.terms[j];
        const Term& tr = r.terms[j];
        thh += tr.sign * t.angle.of(q) + (t.angle.is_coordinate() ? 0.0 : t.sign * tr.angle.value());
        if (order >= 1) dw += tr.sign * t.angle.rate(qd);
        if (order == 2) da += tr.sign * t.angle.rate(qdd);
      }
      const kin::V2 u{std::cos(th), std::sin(th)}, up = kin::perp(u);
      if (order == 0) {
        sum = sum + lh * u + (l * thh) * up;
        continue;
      }
      const double w = rate_of(k, qd), ld = k.length.rate(qd);
      if (order == 1) {
        sum = sum + (ld * thh + lh * w + l * dw) * up - (l * w * thh) * u;
        continue;
      }
      const double al = rate_of(k, qdd), ldd = k.length.rate(qdd);
      sum = sum + (ldd * thh + 2.0 * ld * dw + lh * al + l * da - l * thh * w * w) * up -
            (2.0 * ld * w * thh + lh * w * w + 2.0 * l * w * dw + l * thh * al) * u;
    }
    out[0] = sum.x, out[1] = sum.y;
  }

  /// @copydoc DistanceSpec::joint_count
  JointCount joint_count() const { return JointCount::other(); }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) const {
    detail::require(!links.empty(), "loop: needs at least one link");
    for (const auto& l : links) detail::require(std::isfinite(l.offset), "loop: link offset is not finite");
  }
  /// @copydoc DistanceSpec::sketch
  /// A loop has no points of the plane for the mechanism's sketch; on the parts, its links as an open chain from the
  /// origin, each starting where the one before it ends (the closure vector is the ground's).
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.open_chain(links);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "loop", 2,
       "- {name: closure, type: loop, links: [{length: L2, angles: [psi2]}, {length: L3, "
       "angles: [psi2, psi3]}, {length: L4, angles: [psi2, psi3, psi4]}], closure: [L1, "
       "0]}"}};
  /// @copydoc DistanceSpec::read
  /// A loop's `links` are maps {length, angles, offset}, the angles coordinate names with an optional sign.
  template <class Fields>
  static LoopSpec read(const Fields& f) {
    f.expect({"type", "name", "links", "closure"});
    LoopSpec spec;
    for (const auto& l : f.items("links")) {
      l.expect({"length", "angles", "offset"});
      Link link;
      link.length = l.slot("length");
      if (l.present("offset")) link.offset = l.number("offset");
      if (l.present("angles"))
        for (const auto& [j, sign] : l.signed_coordinates("angles")) link.terms.push_back({Slot::coordinate(j), sign});
      spec.links.push_back(std::move(link));
    }
    if (spec.links.empty()) f.fail("links", "a loop needs at least one link");
    if (f.present("closure")) spec.closure = f.vec2("closure");
    return spec;
  }
};

/// The rates of a loop's links along a design parameter (detail::datum_rate, LoopSpec::data_derivative()): link by
/// link its length's (a constant's rate, a coordinate none), its offset's, and its terms' angles and factors; false
/// where the four loops differ in links or terms.
inline bool datum_rate(std::vector<LoopSpec::Link>& rate, const std::array<const std::vector<LoopSpec::Link>*, 4>& v,
                       double h) {
  for (const auto* links : v)
    if (links->size() != rate.size()) return false;
  for (std::size_t i = 0; i < rate.size(); ++i) {
    LoopSpec::Link& r = rate[i];
    auto at = [&](std::size_t k) -> const LoopSpec::Link& { return (*v[k])[i]; };
    for (std::size_t k = 0; k < 4; ++k)
      if (at(k).terms.size() != r.terms.size()) return false;
    if (!detail::datum_rate(r.length, {&at(0).length, &at(1).length, &at(2).length, &at(3).length}, h) ||
        !detail::datum_rate(r.offset, {&at(0).offset, &at(1).offset, &at(2).offset, &at(3).offset}, h))
      return false;
    for (std::size_t j = 0; j < r.terms.size(); ++j) {
      auto term = [&](std::size_t k) -> const LoopSpec::Term& { return at(k).terms[j]; };
      if (!detail::datum_rate(r.terms[j].angle, {&term(0).angle, &term(1).angle, &term(2).angle, &term(3).angle}, h) ||
          !detail::datum_rate(r.terms[j].sign, {&term(0).sign, &term(1).sign, &term(2).sign, &term(3).sign}, h))
        return false;
    }
  }
  return true;
}

}  // namespace phiq
