// A square system solved block by block (model_rows.hpp, solve_in_blocks()). The total degree multiplies the
// degrees of all equations; a spatial mechanism's system is block triangular (the driven crank's Euler parameters
// are fixed by the crank's own four equations, the rocker's then by its own), and the blocks' Bézout numbers add up
// instead, each block solved once for every real solution of those before it: the RSSR's 512 paths become
// 16 + 4 · 32. Complex solutions of a block are counted, not carried forward (they make no real assembly).
//
// Only regular solutions are substituted: a singular one (a folded linkage's flat loop, where the next loop's two
// circles touch) is known to about √ε only, and the blocks after it, solved at that perturbed value, would split
// each of their double roots into two real or two complex ones — real modes lost or counted twice. Where a block
// has a singular or ill-conditioned solution for one solution p of those before it, that block and all after it
// are solved together for p (their multiple roots then whole, as the whole system sees them). A failed path, a
// degenerate block or the path limit abandons the block solve (the caller then solves the whole system and says
// why).
#include <algorithm>
#include <chrono>
#include <functional>
#include <map>
#include <string>

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

void block_add_counts(ModesSummary& to, const ModesSummary& from) {
  to.paths += from.paths, to.complex += from.complex, to.at_infinity += from.at_infinity;
  to.failed_paths += from.failed_paths, to.duplicate_paths += from.duplicate_paths;
  to.retracked_paths += from.retracked_paths, to.total_degree += from.total_degree;
  to.end_game_paths += from.end_game_paths;
  to.failures.insert(to.failures.end(), from.failures.begin(), from.failures.end());
  if (!from.start_system.empty()) to.start_system = from.start_system;
  for (const Endpoint& e : from.endpoints)
    to.singular += e.kind == EndpointKind::kSingular && !(e.x.imag().cwiseAbs().maxCoeff() <= 1e-6);
}

// A solution of the blocks so far (x: every variable, those of later blocks 0).
struct BlockPartial {
  Eigen::VectorXd x;
  bool singular = false;
};

// Whether endpoint e is a real solution (a singular one to the looser accuracy double precision gives it).
bool block_real_endpoint(const Endpoint& e, const ModesOptions& options) {
  if (e.kind == EndpointKind::kReal) return true;
  return e.kind == EndpointKind::kSingular &&
         e.x.imag().cwiseAbs().maxCoeff() <= 1e3 * options.real_tolerance * (1.0 + e.x.cwiseAbs().maxCoeff());
}

// ±e: one sign carried forward (the largest component positive); e = offset + x
void block_one_sign(const std::vector<std::array<int, 4>>& euler_variables, const Eigen::VectorXd& offset,
                    const Block& b, Eigen::VectorXd& x) {
  for (const auto& body : euler_variables) {
    if (std::find(b.variables.begin(), b.variables.end(), body[0]) == b.variables.end()) continue;
    int largest = body[0];
    for (int v : body)
      if (std::abs(offset(v) + x(v)) > std::abs(offset(largest) + x(largest)) + 1e-9) largest = v;
    if (offset(largest) + x(largest) < 0.0)
      for (int v : body) x(v) = -2.0 * offset(v) - x(v);
  }
}

bool block_near(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const ModesOptions& options) {
  return (a - b).cwiseAbs().maxCoeff() <= options.duplicate_tolerance * (1.0 + b.cwiseAbs().maxCoeff());
}

// Why a block's solve makes the block solve unsafe, or "" when it does not: it refused, or a path failed (a
// solution may be missing). (Paths that met another's regular end are counted, as the whole solve counts them.)
std::string unsafe_block(const ModesSummary& part) {
  if (part.status != ModesStatus::kSuccess) return part.message;
  if (part.failed_paths > 0) return std::to_string(part.failed_paths) + " paths failed";
  return "";
}

// Whether a block has a singular or ill-conditioned finite solution: known to too few digits for the blocks after
// it, which are then solved together with it.
bool block_singular(const ModesSummary& part, const ModesOptions& options) {
  return std::any_of(part.endpoints.begin(), part.endpoints.end(), [&](const Endpoint& e) {
    return e.kind != EndpointKind::kAtInfinity && e.kind != EndpointKind::kFailed &&
           (e.kind == EndpointKind::kSingular || !(e.condition <= options.multiple_root_condition));
  });
}

// Whether a block's system, with the values before it put in, is degenerate: an equation vanished (a continuum of
// solutions) or became a nonzero constant (none).
bool block_degenerate(const PolynomialSystem& block) {
  return std::any_of(block.equations.begin(), block.equations.end(),
                     [](const Polynomial& p) { return p.terms.empty() || p.degree() == 0; });
}

}  // namespace

bool solve_in_blocks(const PolynomialSystem& system, const std::vector<std::array<int, 4>>& euler_variables,
                     const Eigen::VectorXd& offset, const ModesOptions& options, ModesSummary& out,
                     std::string& unsafe) {
  unsafe.clear();
  if (static_cast<int>(system.equations.size()) != system.variables) return false;
  const std::vector<Block> blocks = system_blocks(system);
  if (blocks.size() < 2) return false;
  const auto start_time = std::chrono::steady_clock::now();
  out = ModesSummary{};
  std::vector<BlockPartial> partials{{Eigen::VectorXd::Zero(system.variables)}}, finished;
  // Block b solved for the solution p of those before it (why not safe into `unsafe`), its real solutions carried
  // into `into`
  auto solve_block = [&](const Block& b, const BlockPartial& p, const std::string& name, ModesSummary& part) {
    const PolynomialSystem block = substituted(system, b, p.x);
    std::string why;
    if (block_degenerate(block))
      why = "an equation vanishes or is a nonzero constant there";
    else {
      // the block's own start system (degrees lowered, the fewest paths) within what the blocks before it left
      ModesOptions within = options;
      within.max_paths = options.max_paths - out.paths;
      part = solve_polynomial_system(block, within);
      if (part.status == ModesStatus::kTooManyPaths)
        why = "the blocks' paths pass the limit of " + std::to_string(options.max_paths);
      else
        why = unsafe_block(part);
    }
    if (part.status != ModesStatus::kTooManyPaths) block_add_counts(out, part);
    if (!why.empty())
      unsafe = name + " of " + std::to_string(blocks.size()) + " (" + std::to_string(b.variables.size()) +
               " unknowns): " + why;
    return why.empty();
  };
  auto carry = [&](const ModesSummary& part, const Block& b, const BlockPartial& p, std::vector<BlockPartial>& into) {
    for (const Endpoint& e : part.endpoints) {
      if (!block_real_endpoint(e, options)) continue;
      BlockPartial q = p;
      for (std::size_t v = 0; v < b.variables.size(); ++v)
        q.x(b.variables[v]) = e.x(static_cast<Eigen::Index>(v)).real();
      block_one_sign(euler_variables, offset, b, q.x);
      if (std::any_of(into.begin(), into.end(), [&](const BlockPartial& o) { return block_near(o.x, q.x, options); }))
        continue;
      q.singular = q.singular || e.kind == EndpointKind::kSingular;
      into.push_back(std::move(q));
    }
  };
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const bool last = k + 1 == blocks.size();
    std::vector<BlockPartial> next;
    for (const BlockPartial& p : partials) {
      ModesSummary part;
      if (!solve_block(blocks[k], p, "block " + std::to_string(k + 1), part)) return false;
      if (last || !block_singular(part, options)) {
        carry(part, blocks[k], p, next);
        continue;
      }
      // A singular solution here: this block and all after it solved together, for this p (the whole system's
      // classification then sees the multiple roots whole)
      Block rest;
      for (std::size_t j = k; j < blocks.size(); ++j) {
        rest.equations.insert(rest.equations.end(), blocks[j].equations.begin(), blocks[j].equations.end());
        rest.variables.insert(rest.variables.end(), blocks[j].variables.begin(), blocks[j].variables.end());
      }
      std::sort(rest.equations.begin(), rest.equations.end()), std::sort(rest.variables.begin(), rest.variables.end());
      ModesSummary joint;
      if (!solve_block(rest, p, "blocks " + std::to_string(k + 1) + " to " + std::to_string(blocks.size()), joint))
        return false;
      carry(joint, rest, p, finished);
    }
    partials = std::move(next);
  }
  partials.insert(partials.end(), finished.begin(), finished.end());
  // Each solution refined by Newton on the whole system and classified there, as the whole solve classifies its
  // endpoints: its residual and condition those of all the equations (the Jacobian is block triangular: regular
  // where every block's is).
  const CompiledSystem whole(system);
  std::vector<Endpoint> found;
  for (const BlockPartial& p : partials) {
    Endpoint e;
    e.x = p.x.cast<cd>();
    e.residual = refine_endpoint(whole, e.x, &e.condition);
    if (!(e.residual <= 1e-8)) {
      unsafe = "a solution of the blocks is none of the whole system (residual " + std::to_string(e.residual) + ")";
      return false;
    }
    const bool singular = p.singular || !(e.condition <= options.singular_condition);
    e.kind = singular ? EndpointKind::kSingular : EndpointKind::kReal;
    if (!singular) e.x = e.x.real().cast<cd>();
    const Eigen::VectorXd at = e.x.real();
    if (std::any_of(found.begin(), found.end(), [&](const Endpoint& o) { return block_near(o.x.real(), at, options); }))
      continue;
    (singular ? out.singular : out.real) += 1;
    found.push_back(std::move(e));
  }
  std::sort(found.begin(), found.end(), [](const Endpoint& a, const Endpoint& b) {
    if (a.kind != b.kind) return a.kind < b.kind;
    const Eigen::VectorXd x = a.x.real(), y = b.x.real();
    return std::lexicographical_compare(x.data(), x.data() + x.size(), y.data(), y.data() + y.size());
  });
  out.endpoints = std::move(found);
  out.method = ModesMethod::kBlocks;
  out.blocks = static_cast<int>(blocks.size());
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return true;
}

}  // namespace phiq::modes_detail
