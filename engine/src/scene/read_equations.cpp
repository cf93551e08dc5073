// Equation and law expressions of a scene (scene_reader.hpp): compiled by the symbolic front end with the names a
// scene gives them (t, coordinates, parameters); in a family, compiled once per body with placeholders for what
// changes between members, and rebound per member, so that no member costs symbolic work.
#include <map>

#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

template <class C>
std::shared_ptr<const CompiledExpression> SceneReader::compile(const C& c, bool allow_time, bool allow_rates) const {
  try {
    if constexpr (kInFamily<C>) {
      return family_expression(c, allow_time, true, allow_rates);
    } else {
      const std::string text = c.text();
      return CompiledExpression::compile(text, resolver(true, text), allow_time, allow_rates);
    }
  } catch (const Error& e) {
    c.fail(e.what());
  }
}

// Names of equation expressions: t, coordinates (when allowed), parameters. `text` is the expression, for the
// message that refuses a coordinate where none is allowed (a law: a function of t alone).
NameResolver SceneReader::resolver(bool coordinates, const std::string& text) const {
  return [this, coordinates, &text](const std::string& n) -> std::optional<NameBinding> {
    if (n == "t") return NameBinding{NameBinding::Kind::kTime};
    if (Index j = builder_.find_coordinate(n); j >= 0) {
      if (!coordinates) throw labelled(expression_label(text), coordinate_in_law(n));
      return NameBinding{NameBinding::Kind::kCoordinate, j};
    }
    if (auto p = parameter(n)) return NameBinding{NameBinding::Kind::kConstant, -1, *p};
    return std::nullopt;
  };
}

std::string coordinate_in_law(const std::string& name) {
  return "'" + name + "' is a coordinate: a law is a function of t alone (parameters, pi and t), not of coordinates";
}

// An equation (or law) expression of a family member: compiled once per body, rebound per member. Throws Error.
std::shared_ptr<const CompiledExpression> SceneReader::family_expression(const TCursor& c, bool allow_time,
                                                                         bool allow_coordinates,
                                                                         bool allow_rates) const {
  const std::string& text = c.raw();
  ScalarPlan& plan = c.plan();
  if (!plan.equation) {
    auto eq = std::make_shared<ScalarPlan::Equation>();
    eq->allow_coordinates = allow_coordinates;
    if (!uses_member(c, text)) {
      eq->shared = CompiledExpression::compile(text, resolver(allow_coordinates, text), allow_time, allow_rates);
    } else {
      // each templated name becomes a placeholder identifier that the text cannot already contain
      const std::vector<NameToken> tokens = name_tokens(text, expression_label(text));
      std::string prefix = "phiq_template_";
      while (text.find(prefix) != std::string::npos) prefix += "_";
      std::string rewritten;
      std::map<std::string, std::string> placeholder_of;      // token -> placeholder identifier
      std::vector<std::pair<std::string, std::string>> back;  // placeholder identifier -> token
      std::size_t last = 0;
      for (const NameToken& t : tokens) {
        if (!t.templated) continue;
        const std::string token = text.substr(t.begin, t.end - t.begin);
        if (t.call) throw labelled(expression_label(text), "'" + token + "' is not a function");
        auto [it, fresh] = placeholder_of.emplace(token, prefix + std::to_string(placeholder_of.size()) + "_");
        if (fresh) {
          eq->names.push_back(std::make_shared<NameTemplate>(token, c.meanings()));
          back.emplace_back(it->second, token);
        }
        rewritten += text.substr(last, t.begin - last) + it->second;
        last = t.end;
      }
      rewritten += text.substr(last);
      // compiled indices: one per placeholder, index and coordinate the text names
      std::map<std::string, Index> compiled_index;
      const Families& fx = c.families();
      auto add = [&](const std::string& n, ScalarPlan::Equation::Placeholder p) {
        auto [it, fresh] = compiled_index.emplace(n, static_cast<Index>(eq->placeholders.size()));
        if (fresh) eq->placeholders.push_back(p);
        return it->second;
      };
      NameResolver resolve = [&](const std::string& n) -> std::optional<NameBinding> {
        using P = ScalarPlan::Equation::Placeholder;
        for (std::size_t k = 0; k < back.size(); ++k)
          if (back[k].first == n)
            return NameBinding{NameBinding::Kind::kCoordinate, add(n, P{P::Kind::kTemplate, -1, 0, k})};
        for (std::size_t k = fx.frames.size(); k-- > 0;)
          if (fx.frames[k].family->index == n)
            return NameBinding{NameBinding::Kind::kCoordinate, add(n, P{P::Kind::kIndex, -1, static_cast<int>(k), 0})};
        if (n == "t") return NameBinding{NameBinding::Kind::kTime};
        if (Index j = builder_.find_coordinate(n); j >= 0) {
          if (!allow_coordinates) throw labelled(expression_label(text), coordinate_in_law(n));
          return NameBinding{NameBinding::Kind::kCoordinate, add(n, P{P::Kind::kCoordinate, j, 0, 0})};
        }
        if (auto p = parameter(n)) return NameBinding{NameBinding::Kind::kConstant, -1, *p};
        return std::nullopt;
      };
      try {
        eq->compiled = CompiledExpression::compile(rewritten, resolve, allow_time, allow_rates);
      } catch (const Error& e) {
        // say it with the text as written
        std::string m = e.what();
        for (const auto& [placeholder, token] : back)
          for (std::size_t p = m.find(placeholder); p != std::string::npos; p = m.find(placeholder, p + token.size()))
            m.replace(p, placeholder.size(), token);
        throw Error(m);
      }
    }
    plan.equation = eq;
  }
  const ScalarPlan::Equation& eq = *plan.equation;
  if (eq.shared) return eq.shared;
  const Families& fx = c.families();
  std::vector<Index> target(eq.placeholders.size(), -1);
  std::vector<double> value(eq.placeholders.size(), 0.0);
  std::string name;
  for (std::size_t k = 0; k < eq.placeholders.size(); ++k) {
    const auto& p = eq.placeholders[k];
    using K = ScalarPlan::Equation::Placeholder::Kind;
    if (p.kind == K::kCoordinate) {
      target[k] = p.coordinate;
    } else if (p.kind == K::kIndex) {
      value[k] = fx.index[static_cast<std::size_t>(p.depth)];
    } else {
      eq.names[p.name]->render(fx.env(), name);
      if (Index j = eq.allow_coordinates ? builder_.find_coordinate(name) : -1; j >= 0)
        target[k] = j;
      else if (auto v = parameter(name))
        value[k] = *v;
      else if (builder_.find_coordinate(name) >= 0)
        throw labelled(expression_label(text), coordinate_in_law(name));
      else
        throw labelled(expression_label(text), "unknown name '" + name + "'");
    }
  }
  return eq.compiled->rebind(target, value, text);
}

// Used by the constraint and driver readers.
template std::shared_ptr<const CompiledExpression> SceneReader::compile(const Cursor&, bool, bool) const;
template std::shared_ptr<const CompiledExpression> SceneReader::compile(const TCursor&, bool, bool) const;

}  // namespace phiq::detail::scene
