// A square system solved block by block (model_rows.hpp, solve_in_blocks()). The total degree multiplies the
// degrees of all equations; a spatial mechanism's system is block triangular (the driven crank's Euler parameters
// are fixed by the crank's own four equations, the rocker's then by its own), and the blocks' Bézout numbers add up
// instead, each block solved once for every real solution of those before it: the RSSR's 512 paths become
// 16 + 2 · 32. Complex solutions of a block are counted, not carried forward (they make no real assembly).
#include <algorithm>
#include <functional>
#include <map>

#include "modes/homotopy.hpp"
#include "modes/model_rows.hpp"

namespace phiq::modes_detail {

namespace {

struct Block {
  std::vector<int> equations, variables;
};

// The Dulmage–Mendelsohn blocks of a square system in solving order: a perfect matching of equations to variables
// (augmenting paths), then the strongly connected components (Tarjan) of "equation i reads the variable matched to
// equation j", which Tarjan emits dependencies first. Empty when there is no perfect matching.
std::vector<Block> system_blocks(const PolynomialSystem& s) {
  const int n = s.variables;
  std::vector<std::vector<int>> reads(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    std::vector<bool> seen(static_cast<std::size_t>(n), false);
    for (const PolynomialTerm& t : s.equations[static_cast<std::size_t>(i)].terms)
      for (int v = 0; v < n; ++v)
        if (t.exponent[static_cast<std::size_t>(v)] > 0 && !seen[static_cast<std::size_t>(v)])
          seen[static_cast<std::size_t>(v)] = true, reads[static_cast<std::size_t>(i)].push_back(v);
  }
  std::vector<int> equation_of(static_cast<std::size_t>(n), -1), variable_of(static_cast<std::size_t>(n), -1);
  std::vector<int> visited(static_cast<std::size_t>(n), -1);
  std::function<bool(int, int)> augment = [&](int i, int round) {
    for (int v : reads[static_cast<std::size_t>(i)]) {
      if (visited[static_cast<std::size_t>(v)] == round) continue;
      visited[static_cast<std::size_t>(v)] = round;
      const int other = equation_of[static_cast<std::size_t>(v)];
      if (other < 0 || augment(other, round)) {
        equation_of[static_cast<std::size_t>(v)] = i, variable_of[static_cast<std::size_t>(i)] = v;
        return true;
      }
    }
    return false;
  };
  for (int i = 0; i < n; ++i)
    if (!augment(i, i)) return {};
  std::vector<Block> blocks;
  std::vector<int> index(static_cast<std::size_t>(n), -1), low(static_cast<std::size_t>(n), 0), stack;
  std::vector<bool> on_stack(static_cast<std::size_t>(n), false);
  int counter = 0;
  std::function<void(int)> connect = [&](int i) {
    index[static_cast<std::size_t>(i)] = low[static_cast<std::size_t>(i)] = counter++;
    stack.push_back(i), on_stack[static_cast<std::size_t>(i)] = true;
    for (int v : reads[static_cast<std::size_t>(i)]) {
      const int j = equation_of[static_cast<std::size_t>(v)];
      if (index[static_cast<std::size_t>(j)] < 0) {
        connect(j);
        low[static_cast<std::size_t>(i)] = std::min(low[static_cast<std::size_t>(i)], low[static_cast<std::size_t>(j)]);
      } else if (on_stack[static_cast<std::size_t>(j)]) {
        low[static_cast<std::size_t>(i)] =
            std::min(low[static_cast<std::size_t>(i)], index[static_cast<std::size_t>(j)]);
      }
    }
    if (low[static_cast<std::size_t>(i)] != index[static_cast<std::size_t>(i)]) return;
    Block b;
    for (int j = -1; j != i;) {
      j = stack.back(), stack.pop_back(), on_stack[static_cast<std::size_t>(j)] = false;
      b.equations.push_back(j), b.variables.push_back(variable_of[static_cast<std::size_t>(j)]);
    }
    std::sort(b.equations.begin(), b.equations.end()), std::sort(b.variables.begin(), b.variables.end());
    blocks.push_back(std::move(b));
  };
  for (int i = 0; i < n; ++i)
    if (index[static_cast<std::size_t>(i)] < 0) connect(i);
  return blocks;
}

// The block's equations with the earlier variables' values `known` put in: a system in the block's variables.
PolynomialSystem substituted(const PolynomialSystem& s, const Block& b, const Eigen::VectorXd& known) {
  PolynomialSystem out;
  out.variables = static_cast<int>(b.variables.size());
  std::vector<int> local(static_cast<std::size_t>(s.variables), -1);
  for (std::size_t k = 0; k < b.variables.size(); ++k)
    local[static_cast<std::size_t>(b.variables[k])] = static_cast<int>(k);
  for (int v : b.variables) out.names.push_back(s.names.empty() ? "" : s.names[static_cast<std::size_t>(v)]);
  for (int i : b.equations) {
    std::map<std::vector<int>, cd> terms;
    double largest = 0.0;
    for (const PolynomialTerm& t : s.equations[static_cast<std::size_t>(i)].terms) {
      cd c = t.coefficient;
      std::vector<int> e(static_cast<std::size_t>(out.variables), 0);
      for (int v = 0; v < s.variables; ++v) {
        const int power = t.exponent[static_cast<std::size_t>(v)];
        if (power == 0) continue;
        if (local[static_cast<std::size_t>(v)] >= 0)
          e[static_cast<std::size_t>(local[static_cast<std::size_t>(v)])] = power;
        else
          c *= std::pow(known(v), power);
      }
      terms[e] += c;
      largest = std::max(largest, std::abs(c));
    }
    Polynomial p;
    for (const auto& [e, c] : terms)  // a cancellation's rounding is no term (it would raise the degree)
      if (std::abs(c) > 1e-13 * largest) p.terms.push_back({c, e});
    out.equations.push_back(std::move(p));
  }
  return out;
}

void add_counts(ModesSummary& to, const ModesSummary& from) {
  to.paths += from.paths, to.complex += from.complex, to.at_infinity += from.at_infinity;
  to.failed_paths += from.failed_paths, to.duplicate_paths += from.duplicate_paths;
  to.retracked_paths += from.retracked_paths, to.seconds += from.seconds;
  for (const Endpoint& e : from.endpoints)
    to.singular += e.kind == EndpointKind::kSingular && !(e.x.imag().cwiseAbs().maxCoeff() <= 1e-6);
}

}  // namespace

bool solve_in_blocks(const PolynomialSystem& system, const std::vector<std::array<int, 4>>& euler_variables,
                     const Eigen::VectorXd& offset, const ModesOptions& options, ModesSummary& out) {
  if (static_cast<int>(system.equations.size()) != system.variables) return false;
  const std::vector<Block> blocks = system_blocks(system);
  if (blocks.size() < 2) return false;
  out = ModesSummary{};
  struct Partial {
    Eigen::VectorXd x;
    bool singular = false;
    double residual = 0.0, condition = 0.0;
  };
  std::vector<Partial> partials{{Eigen::VectorXd::Zero(system.variables)}};
  for (const Block& b : blocks) {
    std::vector<Partial> next;
    for (const Partial& p : partials) {
      const ModesSummary part = solve_polynomial_system(substituted(system, b, p.x), options);
      if (part.status != ModesStatus::kSuccess) {
        out.status = part.status, out.message = part.message;
        return true;
      }
      add_counts(out, part);
      for (const Endpoint& e : part.endpoints) {
        const bool real_singular =
            e.kind == EndpointKind::kSingular &&
            e.x.imag().cwiseAbs().maxCoeff() <= 1e3 * options.real_tolerance * (1.0 + e.x.cwiseAbs().maxCoeff());
        if (e.kind != EndpointKind::kReal && !real_singular) continue;
        Partial q = p;
        for (std::size_t k = 0; k < b.variables.size(); ++k)
          q.x(b.variables[k]) = e.x(static_cast<Eigen::Index>(k)).real();
        // ±e: one sign carried forward (the largest component positive); e = offset + x
        for (const auto& body : euler_variables) {
          if (std::find(b.variables.begin(), b.variables.end(), body[0]) == b.variables.end()) continue;
          int largest = body[0];
          for (int v : body)
            if (std::abs(offset(v) + q.x(v)) > std::abs(offset(largest) + q.x(largest)) + 1e-9) largest = v;
          if (offset(largest) + q.x(largest) < 0.0)
            for (int v : body) q.x(v) = -2.0 * offset(v) - q.x(v);
        }
        const bool again = std::any_of(next.begin(), next.end(), [&](const Partial& o) {
          return (o.x - q.x).cwiseAbs().maxCoeff() <= options.duplicate_tolerance * (1.0 + q.x.cwiseAbs().maxCoeff());
        });
        if (again) continue;
        q.singular = q.singular || e.kind == EndpointKind::kSingular;
        q.residual = std::max(q.residual, e.residual), q.condition = std::max(q.condition, e.condition);
        next.push_back(std::move(q));
      }
    }
    partials = std::move(next);
  }
  std::sort(partials.begin(), partials.end(), [](const Partial& a, const Partial& b) {
    return std::lexicographical_compare(a.x.data(), a.x.data() + a.x.size(), b.x.data(), b.x.data() + b.x.size());
  });
  for (const Partial& p : partials) {
    Endpoint e;
    e.kind = p.singular ? EndpointKind::kSingular : EndpointKind::kReal;
    e.x = p.x.cast<cd>(), e.residual = p.residual, e.condition = p.condition;
    out.endpoints.push_back(std::move(e));
    (p.singular ? out.singular : out.real) += 1;
  }
  return true;
}

}  // namespace phiq::modes_detail
