#pragma once
/// \file
/// Sequential backend: the reference every other backend must agree with.

#include <utility>
#include <vector>

#include "chunks.hpp"
#include "policy.hpp"

namespace simsr::exec {

/// Calls `body(i)` for i = 0..n-1 in order.
template <class Body>
void parallel_for(seq_t, Index n, Body&& body) {
  for (Index i = 0; i < n; ++i) body(i);
}

/// Folds `map(i)` with `combine`, chunk by chunk from `identity`, then the chunk results in
/// order. The chunking is the omp backend's, so the two round identically.
template <class T, class Map, class Combine>
T parallel_reduce(seq_t, Index n, T identity, Map&& map, Combine&& combine, Index chunks = default_chunks) {
  const Index nc = chunk_count(n, chunks);
  T total = identity;
  for (Index c = 0; c < nc; ++c) {
    auto [b, e] = chunk_range(n, nc, c);
    T part = identity;
    for (Index i = b; i < e; ++i) part = combine(part, map(i));
    total = combine(total, part);
  }
  return total;
}

/// Per-chunk accumulators (libigl's three-phase parallel_for, made deterministic): each chunk
/// gets `make()`, `body(i, acc)` fills it, and `merge(total, std::move(acc))` folds the chunks in
/// order into the first. Used for FEM assembly (gradients, triplets) without atomics.
template <class Make, class Body, class Merge>
auto parallel_for_accumulate(seq_t, Index n, Make&& make, Body&& body, Merge&& merge, Index chunks = 16) {
  const Index nc = chunk_count(n, chunks);
  auto total = make();
  for (Index c = 0; c < nc; ++c) {
    auto [b, e] = chunk_range(n, nc, c);
    if (c == 0) {
      for (Index i = b; i < e; ++i) body(i, total);
    } else {
      auto acc = make();
      for (Index i = b; i < e; ++i) body(i, acc);
      merge(total, std::move(acc));
    }
  }
  return total;
}

}  // namespace simsr::exec
