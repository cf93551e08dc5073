// KLU's two index widths under one set of names, and what phiq adds to KLU's block triangular form: the parities
// of its permutations per block (a determinant's sign that does not depend on the pivots chosen), a key per block
// (block_signs()), and an order of the blocks that follows the pattern's own (resequence_blocks). Internal to
// klu_lu.cpp, which puts them behind the sparse LU interface; apart because they are about the analysis's
// permutations, not about factorising.
#pragma once

#include <klu.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <queue>
#include <utility>
#include <vector>

#include "linear/klu_lu.hpp"

namespace phiq::detail {
// KLU's two index widths under one set of names: klu_* (int) and klu_l_* (SuiteSparse_long).
template <class Int>
struct Klu;

template <>
struct Klu<int> {
  using Common = klu_common;
  using Symbolic = klu_symbolic;
  using Numeric = klu_numeric;
  static void defaults(Common* c) { klu_defaults(c); }
  static Symbolic* analyze(int n, int* ap, int* ai, Common* c) { return klu_analyze(n, ap, ai, c); }
  static void free_symbolic(Symbolic** s, Common* c) { klu_free_symbolic(s, c); }
  static Numeric* factor(int* ap, int* ai, double* ax, Symbolic* s, Common* c) { return klu_factor(ap, ai, ax, s, c); }
  static bool refactor(int* ap, int* ai, double* ax, Symbolic* s, Numeric* f, Common* c) {
    return klu_refactor(ap, ai, ax, s, f, c) != 0;
  }
  static bool solve(Symbolic* s, Numeric* f, int n, double* b, Common* c) { return klu_solve(s, f, n, 1, b, c) != 0; }
  static bool tsolve(Symbolic* s, Numeric* f, int n, double* b, Common* c) { return klu_tsolve(s, f, n, 1, b, c) != 0; }
  static void free_numeric(Numeric** f, Common* c) { klu_free_numeric(f, c); }
};

template <>
struct Klu<SuiteSparse_long> {
  using Int = SuiteSparse_long;
  using Common = klu_l_common;
  using Symbolic = klu_l_symbolic;
  using Numeric = klu_l_numeric;
  static void defaults(Common* c) { klu_l_defaults(c); }
  static Symbolic* analyze(Int n, Int* ap, Int* ai, Common* c) { return klu_l_analyze(n, ap, ai, c); }
  static void free_symbolic(Symbolic** s, Common* c) { klu_l_free_symbolic(s, c); }
  static Numeric* factor(Int* ap, Int* ai, double* ax, Symbolic* s, Common* c) {
    return klu_l_factor(ap, ai, ax, s, c);
  }
  static bool refactor(Int* ap, Int* ai, double* ax, Symbolic* s, Numeric* f, Common* c) {
    return klu_l_refactor(ap, ai, ax, s, f, c) != 0;
  }
  static bool solve(Symbolic* s, Numeric* f, Int n, double* b, Common* c) { return klu_l_solve(s, f, n, 1, b, c) != 0; }
  static bool tsolve(Symbolic* s, Numeric* f, Int n, double* b, Common* c) {
    return klu_l_tsolve(s, f, n, 1, b, c) != 0;
  }
  static void free_numeric(Numeric** f, Common* c) { klu_l_free_numeric(f, c); }
};

// Parity of a permutation of 0 … n−1 (+1 even, −1 odd), by its cycles. Once per pivot order, not per solve.
template <typename Int>
int permutation_sign(const Int* p, Index n) {
  std::vector<char> seen(static_cast<std::size_t>(n), 0);
  int sign = 1;
  for (Index i = 0; i < n; ++i) {
    if (seen[static_cast<std::size_t>(i)]) continue;
    Index len = 0;
    for (Index j = i; !seen[static_cast<std::size_t>(j)]; j = static_cast<Index>(p[j]))
      seen[static_cast<std::size_t>(j)] = 1, ++len;
    if (len % 2 == 0) sign = -sign;
  }
  return sign;
}

// For each block b of a block triangular form (rows or columns R[b] … R[b+1] − 1), whether the segment
// p[R[b]] … p[R[b+1] − 1] of a permutation is an odd rearrangement of its entries in increasing order (1) or an
// even one (0): what turns the determinant of a diagonal block as KLU factorises it into that of the same rows and
// columns of A in their own order, which does not depend on the pivots chosen. Once per pivot order.
template <typename Int>
std::vector<unsigned char> block_parities(const Int* p, const Int* R, Int nb) {
  std::vector<unsigned char> odd(static_cast<std::size_t>(nb), 0);
  std::vector<std::pair<Int, Int>> seg;  // (entry, position in the segment)
  std::vector<Int> where;                // a permutation of 0 … len − 1 with the segment's parity
  for (Int b = 0; b < nb; ++b) {
    const Int lo = R[b], len = R[b + 1] - R[b];
    if (len < 2) continue;
    if (len == 2) {
      odd[static_cast<std::size_t>(b)] = p[lo] > p[lo + 1];
      continue;
    }
    seg.clear();
    for (Int k = 0; k < len; ++k) seg.emplace_back(p[lo + k], k);
    std::sort(seg.begin(), seg.end());  // seg[j].second: where the j-th smallest entry sits
    where.resize(static_cast<std::size_t>(len));
    for (Int j = 0; j < len; ++j) where[static_cast<std::size_t>(j)] = seg[static_cast<std::size_t>(j)].second;
    odd[static_cast<std::size_t>(b)] = permutation_sign(where.data(), len) < 0;
  }
  return odd;
}

// A 64-bit key per block (a multiplication by an odd constant, its high bits folded into the low: distinct blocks
// get unrelated keys); block_signs() is the xor of the keys of the blocks whose determinant is negative.
inline std::uint64_t block_key(std::uint64_t b) {
  const std::uint64_t x = (b + 1) * 0x9E3779B97F4A7C15ull;
  return x ^ (x >> 29);
}

// Mean |p[k] − p[k−1]|: 1 for the identity or its reverse, about n/3 for a random permutation. How far apart in
// memory consecutive columns of the factorisation are.
template <class Int>
double mean_jump(const std::vector<Int>& p) {
  if (p.size() < 2) return 0.0;
  double sum = 0.0;
  for (std::size_t k = 1; k < p.size(); ++k)
    sum += static_cast<double>(std::llabs(static_cast<long long>(p[k]) - p[k - 1]));
  return sum / static_cast<double>(p.size() - 1);
}

// KLU finds the diagonal blocks of the block upper triangular form by Tarjan's depth-first search and keeps them in
// the order the search closes them. On a lattice (phiq generate grid) that order scatters neighbouring blocks
// across the matrix: each column of a refactorisation or a solve then reads A, X and the factors far from the last
// one and, once the factors outgrow the cache, misses it nearly every time (grid, 2·10⁶ coordinates: 178 ms per
// refactorisation in KLU's order, 71 ms in the lattice's). Any topological order of the blocks is the same block
// triangular form — the same blocks, pivots, factors and fill; only the order of the off-diagonal updates differs —
// so this takes the one that follows the pattern's own column order, which models number locally (a coordinate
// next to those of its neighbours) far more often than not: Kahn's algorithm, taking among the blocks whose
// predecessors are placed the one with the smallest first column (or, the other way round, the largest last
// column). The more local of the two replaces KLU's order if it halves KLU's mean jump between consecutive
// columns. O(nnz + blocks · log blocks), once per pattern.
template <class Int>
KluAnalysis resequence_blocks(const Int* ap, const Int* ai, typename Klu<Int>::Symbolic* s) {
  const Int n = s->n, nb = s->nblocks;
  KluAnalysis a;
  a.index_bits = 8 * static_cast<int>(sizeof(Int));
  a.blocks = nb;
  a.klu_jump = a.jump = mean_jump(std::vector<Int>(s->Q, s->Q + n));
  if (nb < 3) return a;
  Int* const P = s->P;
  Int* const Q = s->Q;
  Int* const R = s->R;
  std::vector<Int> block_of_row(static_cast<std::size_t>(n));
  for (Int b = 0; b < nb; ++b)
    for (Int k = R[b]; k < R[b + 1]; ++k) block_of_row[static_cast<std::size_t>(P[k])] = b;
  // An entry of block b's columns in another block's row r ties r's block before b (upper triangular): the
  // successors of each block, compressed by rows (duplicates kept: each is counted in the in-degree too).
  std::vector<Int> first(static_cast<std::size_t>(nb) + 1, 0), indegree(static_cast<std::size_t>(nb), 0);
  std::vector<Int> lo(static_cast<std::size_t>(nb), n), hi(static_cast<std::size_t>(nb), -1);
  auto each_tie = [&](auto&& f) {
    for (Int b = 0; b < nb; ++b)
      for (Int k = R[b]; k < R[b + 1]; ++k)
        for (Int p = ap[Q[k]]; p < ap[Q[k] + 1]; ++p)
          if (const Int rb = block_of_row[static_cast<std::size_t>(ai[p])]; rb != b) f(rb, b);
  };
  each_tie(
      [&](Int from, Int to) { ++first[static_cast<std::size_t>(from) + 1], ++indegree[static_cast<std::size_t>(to)]; });
  for (Int b = 0; b < nb; ++b) {
    first[static_cast<std::size_t>(b) + 1] += first[static_cast<std::size_t>(b)];
    for (Int k = R[b]; k < R[b + 1]; ++k) {
      lo[static_cast<std::size_t>(b)] = std::min(lo[static_cast<std::size_t>(b)], Q[k]);
      hi[static_cast<std::size_t>(b)] = std::max(hi[static_cast<std::size_t>(b)], Q[k]);
    }
  }
  std::vector<Int> successors(static_cast<std::size_t>(first[static_cast<std::size_t>(nb)]));
  {
    std::vector<Int> next(first.begin(), first.end() - 1);
    each_tie(
        [&](Int from, Int to) { successors[static_cast<std::size_t>(next[static_cast<std::size_t>(from)]++)] = to; });
  }
  // Kahn's algorithm by a priority: the blocks in the order taken.
  auto order_by = [&](const std::vector<Int>& key, bool ascending) {
    std::vector<Int> left = indegree, order;
    order.reserve(static_cast<std::size_t>(nb));
    using Item = std::pair<Int, Int>;  // (±key, block)
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> ready;
    auto push = [&](Int b) {
      ready.push({ascending ? key[static_cast<std::size_t>(b)] : -key[static_cast<std::size_t>(b)], b});
    };
    for (Int b = 0; b < nb; ++b)
      if (left[static_cast<std::size_t>(b)] == 0) push(b);
    while (!ready.empty()) {
      const Int b = ready.top().second;
      ready.pop();
      order.push_back(b);
      for (Int e = first[static_cast<std::size_t>(b)]; e < first[static_cast<std::size_t>(b) + 1]; ++e)
        if (--left[static_cast<std::size_t>(successors[static_cast<std::size_t>(e)])] == 0)
          push(successors[static_cast<std::size_t>(e)]);
    }
    return order;  // all nb blocks: the ties of a block triangular form have no cycle
  };
  auto columns_in = [&](const std::vector<Int>& order) {
    std::vector<Int> q;
    q.reserve(static_cast<std::size_t>(n));
    for (Int b : order) q.insert(q.end(), Q + R[b], Q + R[b + 1]);
    return q;
  };
  std::vector<Int> best;
  double best_jump = 0.5 * a.klu_jump;
  for (const bool ascending : {true, false}) {
    std::vector<Int> order = order_by(ascending ? lo : hi, ascending);
    if (static_cast<Int>(order.size()) != nb) return a;  // not a block triangular form: leave KLU's order
    if (const double j = mean_jump(columns_in(order)); j < best_jump) best_jump = j, best.swap(order);
  }
  if (best.empty()) return a;
  std::vector<Int> p2, q2, r2(static_cast<std::size_t>(nb) + 1);
  std::vector<double> lnz2(static_cast<std::size_t>(nb));
  p2.reserve(static_cast<std::size_t>(n)), q2.reserve(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < best.size(); ++i) {
    const Int b = best[i];
    r2[i] = static_cast<Int>(p2.size());
    lnz2[i] = s->Lnz[b];
    p2.insert(p2.end(), P + R[b], P + R[b + 1]);
    q2.insert(q2.end(), Q + R[b], Q + R[b + 1]);
  }
  r2[static_cast<std::size_t>(nb)] = n;
  std::copy(p2.begin(), p2.end(), P);
  std::copy(q2.begin(), q2.end(), Q);
  std::copy(r2.begin(), r2.end(), R);
  std::copy(lnz2.begin(), lnz2.end(), s->Lnz);
  a.resequenced = true;
  a.jump = best_jump;
  return a;
}

}  // namespace phiq::detail
