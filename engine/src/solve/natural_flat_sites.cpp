// JointReactions' flat natural sites (phiq/joint_reactions.hpp, NaturalSite::flat): a point on a body whose force
// the whole model's Q computed and that has no load of its own, whose reaction is a few sums of Φq's entries times λ
// less a few of the part's PlanarForce values. Found once at set-up (find_flat_sites(), add_flat_sums()) and summed
// at every row (evaluate_flat(), and evaluate()'s simple sites), in the general path's order, bit for bit.
#include <array>
#include <bit>
#include <cstdint>
#include <limits>
#include <map>
#include <vector>

#include "phiq/joint_reactions.hpp"
#include "solve/part_forces.hpp"

namespace phiq {

void JointReactions::find_flat_sites(const Model& model, const std::vector<BarForm>& forms) {
  if (set_->natural->spatial) return;
  std::map<std::array<std::uint64_t, 8>, std::uint32_t> shared;  // a BarSum's bits → its index in bar_sums
  std::vector<Index> moving[2];  // a fixed component's moving points' coordinates (its capacity kept)
  for (NaturalSite& s : set_->natural_sites) {
    const BodyPart& part = set_->body_parts[s.body];
    s.flat = false;
    if (part.part == BodyPart::kNone || part.applied) continue;
    bool fits = true;
    s.count[0] = s.count[1] = 0;
    const NaturalBody& body = set_->natural->bodies[s.body];
    for (int k = 0; k < 2; ++k) {  // a fixed component's moving points, as evaluate_natural() sums them
      moving[k].clear(), s.shared[k] = false;
      if (s.at[k] < model.num_coordinates()) continue;
      for (const Attachment3& o : body.points) {
        const Index c = o.r[k].coord();
        if (c >= model.num_coordinates())
          s.shared[k] = s.shared[k] || &o != &body.points[s.point];
        else
          moving[k].push_back(c);
      }
    }
    detail::for_each_planar_term(part.frame(), [&](const Slot& slot, int field, bool negated) {
      for (int k = 0; k < 2; ++k) {
        if (!slot.is_coordinate() || slot.coord() != s.at[k]) continue;
        if (s.count[k] == NaturalSite::kMaxTerms) {
          fits = false;
          continue;
        }
        s.terms[k][s.count[k]++] = static_cast<std::uint8_t>(field + (negated ? 8 : 0));
      }
    });
    s.part = part.part, s.flat = fits;
    if (fits) add_flat_sums(s, model.num_coordinates(), moving);
    if (!fits || !s.simple || !forms[s.body].bar) continue;
    // a rigid bar's simple site: its sums' numbers, shared with the sites whose numbers are the same bits
    SimpleSite& at = set_->simple_sites[static_cast<std::size_t>(&s - set_->natural_sites.data())];
    const BarSum sum = bar_sum(at, part, forms[s.body], model.num_coordinates());
    std::array<std::uint64_t, 8> key;
    for (std::size_t k = 0; k < 2; ++k) {
      key[4 * k] = std::bit_cast<std::uint64_t>(sum.weight[k]);
      for (std::size_t i = 0; i < 3; ++i) key[4 * k + 1 + i] = std::bit_cast<std::uint64_t>(sum.m[k][i]);
    }
    const auto [it, added] = shared.try_emplace(key, static_cast<std::uint32_t>(set_->bar_sums.size()));
    if (added) set_->bar_sums.push_back(sum);
    at.form = it->second, at.bar = true;
  }
}

void JointReactions::add_flat_sums(NaturalSite& s, Index n, const std::vector<Index> (&moving)[2]) {
  FlatSums& sums = set_->body_rows.flat;
  const BodyRows& rows = set_->body_rows;
  auto add_group = [&](Index column) {  // the body's entries in `column`, in their order
    for (std::size_t k = rows.entries_first[s.body]; k < rows.entries_first[s.body + 1]; ++k)
      if (rows.entries[k].column == column) sums.terms.push_back(rows.entries[k]);
    sums.term_first.push_back(static_cast<std::uint32_t>(sums.terms.size()));
  };
  for (int k = 0; k < 2; ++k) {
    s.group_first[k] = static_cast<std::uint32_t>(sums.term_first.size() - 1);
    if (s.at[k] < n)
      add_group(s.at[k]);
    else
      for (Index c : moving[k]) add_group(c);
  }
  s.group_first[2] = static_cast<std::uint32_t>(sums.term_first.size() - 1);
  s.simple = true;
  for (int k = 0; k < 2; ++k)
    s.simple = s.simple && s.at[k] < n && s.count[k] == 1 &&
               sums.term_first[s.group_first[k] + 1] - sums.term_first[s.group_first[k]] == 1;
  if (!s.simple) return;
  set_->simple_sites.resize(set_->natural_sites.size());  // (one per site, at its index)
  SimpleSite& at = set_->simple_sites[static_cast<std::size_t>(&s - set_->natural_sites.data())];
  for (int k = 0; k < 2; ++k) {
    const OwnEntry& e = sums.terms[sums.term_first[s.group_first[k]]];
    s.simple = s.simple && e.slot <= UINT32_MAX && e.row <= UINT32_MAX && s.part <= UINT32_MAX;
    at.slot[k] = static_cast<std::uint32_t>(e.slot), at.row[k] = static_cast<std::uint32_t>(e.row);
    at.term[k] = s.terms[k][0];
  }
  at.part = static_cast<std::uint32_t>(s.part), at.simple = s.simple;
}

JointReactions::BarSum JointReactions::bar_sum(SimpleSite& at, const BodyPart& part, const BarForm& form,
                                               Index n) const {
  const Slot* slots[4] = {&part.slots[0], &part.slots[1], &part.slots[3], &part.slots[4]};  // (kBarFields' a_k)
  BarSum sum;
  for (int k = 0; k < 2; ++k) {
    const int field = at.term[k] & 7;
    const detail::BarField& f = detail::kBarFields[field];
    sum.weight[k] = form.weights[field];
    for (int i = 0; i < f.count; ++i) {
      const detail::BarFieldTerm& term = f.terms[i];
      const Slot& slot = *slots[term.accel];
      if (!slot.is_coordinate() || slot.coord() >= n) continue;  // a constant's acceleration: 0 (m 0, a ±0)
      const double number = form.numbers[term.number];
      at.a[k][i] = static_cast<std::uint32_t>(slot.coord()), sum.m[k][i] = term.minus ? -number : number;
    }
  }
  return sum;
}

bool JointReactions::evaluate_flat(const NaturalSite& s, const double* q, double t, const Eigen::VectorXd& lambda,
                                   const detail::PlanarForce* planar, double* out) {
  if (!planar || !planar[s.part].valid) return false;
  const FlatSums& sums = set_->body_rows.flat;
  auto group_sum = [&](std::uint32_t g) {  // g_ at a column, as add_body_constraint_forces() sums it (from +0)
    double sum = 0.0;
    for (std::uint32_t k = sums.term_first[g]; k < sums.term_first[g + 1]; ++k)
      sum += own_values_[static_cast<std::size_t>(sums.terms[k].slot)] * lambda(sums.terms[k].row);
    return sum;
  };
  const detail::PlanarForce& f = planar[s.part];
  for (int k = 0; k < 2; ++k) {
    double qb = 0.0;  // Q_b at the component, as body_forces() sums it into qb_ (from +0)
    for (int i = 0; i < s.count[k]; ++i) {
      const double v = f.*detail::kPlanarFields[s.terms[k][i] & 7];
      qb += (s.terms[k][i] & 8) ? -v : v;
    }
    if (s.at[k] < static_cast<Index>(g_.size())) {
      out[k] = group_sum(s.group_first[k]) - qb;
      continue;
    }
    double moving = 0.0;  // a fixed component: as evaluate_natural() sums it
    for (std::uint32_t g = s.group_first[k]; g < s.group_first[k + 1]; ++g) moving += group_sum(g);
    out[k] = s.shared[k] ? std::numeric_limits<double>::quiet_NaN() : -moving - qb;
  }
  out[2] = 0.0;
  if (set_->joint_axes) turn_natural(s, q, t, out);
  return true;
}

}  // namespace phiq
