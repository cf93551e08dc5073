// The values a scene is made of, as the section readers read them (scene_reader.hpp): numbers (YAML numbers,
// constant expressions of the parameters, and in families expressions of the indices), slots (a coordinate or a
// constant), coordinates and the entries of the name tables looked up by name. Every section reads through these,
// on plain entries and on family members alike.
#include <cmath>

#include "phiq/text.hpp"
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

std::optional<double> SceneReader::parameter(const std::string& name) const {
  auto it = names_.parameters.find(name);
  if (it == names_.parameters.end()) return std::nullopt;
  return it->second;
}

// A constant expression of parameters and pi ("L2/2", "2*pi"), exactly (symbolic engine), with the hint that a
// coordinate is not a constant.
template <class C>
double SceneReader::constant_expression(const C& c, const std::string& s) const {
  try {
    return evaluate_constant_expression(s, [&](const std::string& n) { return parameter(n); });
  } catch (const Error& e) {
    if (builder_.find_coordinate(s) >= 0) c.fail("'" + s + "' is a coordinate; a constant is expected here");
    c.fail(e.what());
  }
}

// A number: a YAML number, or a constant expression of parameters and pi ("L2/2", "2*pi"); in a family, also of
// the indices ("i + 0.5", "0.1*i") and of templated parameter names ("L{i}").
template <class C>
double SceneReader::number(const C& c) const {
  if (!c.present()) c.fail("missing number");
  if constexpr (kInFamily<C>) {
    const std::string& s = c.raw();
    ScalarPlan& p = c.plan();
    if (!p.number_ready) {
      std::optional<double> v;
      try {
        v = plain_number(s);
      } catch (const Error& e) {
        c.fail(e.what());
      }
      if (v) {
        p.number_constant = true, p.number_value = *v;
      } else if (uses_member(c, s)) {
        try {
          p.number = std::make_shared<IndexExpr>(s, expression_label(s), member_meanings(c), true);
        } catch (const Error& e) {
          c.fail(e.what());
        }
      } else {
        p.number_constant = true, p.number_value = constant_expression(c, s);  // the same as outside a family
      }
      p.number_ready = true;
    }
    double v = p.number_value;
    if (!p.number_constant) {
      try {
        v = p.number->eval(c.families().env());
      } catch (const Error& e) {
        c.fail(e.what());
      }
    }
    if (!std::isfinite(v)) c.fail("'" + s + "' is not a finite number");
    return v;
  } else {
    const std::string s = c.text();
    double v;
    std::optional<double> p;
    try {
      p = plain_number(s);
    } catch (const Error& e) {
      c.fail(e.what());
    }
    v = p ? *p : constant_expression(c, s);
    if (!std::isfinite(v)) c.fail("'" + s + "' is not a finite number");
    return v;
  }
}

// True when a family text uses an index in scope or a template (then it is evaluated per member).
bool SceneReader::uses_member(const TCursor& c, const std::string& s) const {
  std::vector<NameToken> tokens;
  try {
    tokens = name_tokens(s, expression_label(s));
  } catch (const Error& e) {
    c.fail(e.what());
  }
  for (const NameToken& t : tokens) {
    if (t.templated) return true;
    const std::string n = s.substr(t.begin, t.end - t.begin);
    for (const auto& f : families_.frames)
      if (f.family->index == n) return true;
  }
  return false;
}

Meanings SceneReader::member_meanings(const TCursor& c) const {
  Meanings base = c.meanings();
  const ModelBuilder* b = &builder_;
  return [base, b](const std::string& n) {
    Meaning m = base(n);
    if (m.kind == Meaning::Kind::kUnknown && b->find_coordinate(n) >= 0)
      m.message = "'" + n + "' is a coordinate; a constant is expected here";
    return m;
  };
}

template <class C>
double SceneReader::positive(const C& c) const {
  double v = number(c);
  if (!(v > 0.0)) {
    // a name or an expression is shown with its value ("got L2 = -0.4"), a number as written
    std::string written;
    if constexpr (kInFamily<C>)
      written = c.raw();
    else
      written = c.text();
    if (!plain_number(written)) c.fail("must be positive, got " + written + " = " + shortest(v));
    c.fail("must be positive, got " + written);
  }
  return v;
}

template <class C>
std::vector<double> SceneReader::numbers(const C& c, std::size_t n) const {
  auto items = c.items();
  if (n && items.size() != n) c.fail("expected a list of " + std::to_string(n) + " numbers");
  std::vector<double> v;
  for (const auto& i : items) v.push_back(number(i));
  return v;
}

template <class C>
kin::V2 SceneReader::vec2(const C& c) const {
  if (!c.is_sequence()) c.fail("expected a list");
  if (c.size() != 2) c.fail("expected a list of 2 numbers");
  return {number(c.at(0)), number(c.at(1))};
}

template <class C>
kin3::V3 SceneReader::vec3(const C& c) const {
  if (!c.is_sequence() || c.size() != 3) c.fail("expected a list of 3 numbers");
  return {number(c.at(0)), number(c.at(1)), number(c.at(2))};
}

template <class C>
Index SceneReader::coordinate(const C& c) const {
  const std::string s = c.name();
  Index j = coordinate_at(c, s);
  if (j < 0) c.fail("unknown coordinate '" + s + "'");
  return j;
}

// The index of the entry `name` that the reference at c names, or -1. In a family, a reference written without
// template is looked up once; a templated one first tries the entry one step (the step between the last two
// found) after the last one found, verified by name: families mostly walk their tables in order, and a hash
// lookup in a table of millions of names costs cache misses.
template <class C, class Find, class NameAt>
Index SceneReader::lookup(const C& c, const std::string& name, Index size, const Find& find,
                          const NameAt& name_at) const {
  if constexpr (kInFamily<C>) {
    ScalarPlan& p = c.plan();
    if (!c.node()->templated) {
      if (p.entity == ScalarPlan::kNotLooked) p.entity = find(name);
      return p.entity;
    }
    if (p.last >= 0) {
      const Index k = p.last + p.stride;
      if (k >= 0 && k < size && name_at(k) == name) return p.last = k;
    }
    const Index j = find(name);
    if (j >= 0) {
      if (p.last >= 0) p.stride = j - p.last;
      p.last = j;
    }
    return j;
  } else {
    (void)c, (void)size, (void)name_at;
    return find(name);
  }
}

template <class C>
Index SceneReader::coordinate_at(const C& c, const std::string& name) const {
  return lookup(
      c, name, builder_.num_coordinates(), [&](const std::string& n) { return builder_.find_coordinate(n); },
      [&](Index k) -> const std::string& { return builder_.coordinate_name(k); });
}

template <class C, class T>
Index SceneReader::entry_at(const C& c, const std::string& name, const NameTable<T>& table) const {
  return lookup(
      c, name, table.size(), [&](const std::string& n) { return table.find(n); },
      [&](Index k) -> const std::string& { return table.name(k); });
}

// A slot: a coordinate name or a constant (number or constant expression).
template <class C>
Slot SceneReader::slot(const C& c) const {
  if (c.is_scalar()) {
    if constexpr (kInFamily<C>) {
      const Index j = c.node()->templated ? coordinate_at(c, c.text()) : coordinate_at(c, c.raw());
      if (j >= 0) return Slot::coordinate(j);
    } else {
      Index j = builder_.find_coordinate(c.text());
      if (j >= 0) return Slot::coordinate(j);
    }
  }
  return Slot::constant(number(c));
}

template <class C>
Unit SceneReader::unit(const C& c) const {
  if (!c.present()) return Unit::kNone;
  const std::string s = c.text();
  if (s == "length") return Unit::kLength;
  if (s == "angle") return Unit::kAngle;
  if (s == "none") return Unit::kNone;
  c.fail("unit is length, angle or none, got '" + s + "'");
}

// Used by the readers of every section, on plain entries and on family members.
template double SceneReader::number(const Cursor&) const;
template double SceneReader::number(const TCursor&) const;
template double SceneReader::positive(const Cursor&) const;
template double SceneReader::positive(const TCursor&) const;
template std::vector<double> SceneReader::numbers(const Cursor&, std::size_t) const;
template std::vector<double> SceneReader::numbers(const TCursor&, std::size_t) const;
template kin::V2 SceneReader::vec2(const Cursor&) const;
template kin::V2 SceneReader::vec2(const TCursor&) const;
template kin3::V3 SceneReader::vec3(const Cursor&) const;
template kin3::V3 SceneReader::vec3(const TCursor&) const;
template Index SceneReader::coordinate(const Cursor&) const;
template Index SceneReader::coordinate(const TCursor&) const;
template Index SceneReader::entry_at(const Cursor&, const std::string&, const NameTable<Point2>&) const;
template Index SceneReader::entry_at(const TCursor&, const std::string&, const NameTable<Point2>&) const;
template Index SceneReader::entry_at(const Cursor&, const std::string&, const NameTable<Frame2>&) const;
template Index SceneReader::entry_at(const TCursor&, const std::string&, const NameTable<Frame2>&) const;
template Index SceneReader::entry_at(const Cursor&, const std::string&, const NameTable<Point3>&) const;
template Index SceneReader::entry_at(const TCursor&, const std::string&, const NameTable<Point3>&) const;
template Index SceneReader::entry_at(const Cursor&, const std::string&, const NameTable<Frame3>&) const;
template Index SceneReader::entry_at(const TCursor&, const std::string&, const NameTable<Frame3>&) const;
template Slot SceneReader::slot(const Cursor&) const;
template Slot SceneReader::slot(const TCursor&) const;
template Unit SceneReader::unit(const Cursor&) const;
template Unit SceneReader::unit(const TCursor&) const;

}  // namespace phiq::detail::scene
