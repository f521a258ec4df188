#pragma once
/// \file
/// Fixed row chunking for the layers: the same chunks under exec::seq and exec::omp, so per-chunk
/// products and per-chunk partial sums (merged in chunk order) round identically.

#include <algorithm>
#include <type_traits>

#include "../tensor.hpp"

namespace simsr::nn::detail {

/// Chunks of rows for block products (GEMM) and for reductions over rows.
inline constexpr Index product_chunks = 64;
inline constexpr Index reduction_chunks = 16;

/// Workers that `for_chunks` uses under `policy` for `chunks` chunks (1 under seq).
template <class Policy>
Index worker_count(Policy, Index chunks) {
  if constexpr (std::is_same_v<std::remove_cvref_t<Policy>, exec::omp_t>)
    return std::max<Index>(1, std::min<Index>(chunks, exec::omp_max_threads()));
  else
    return 1;
}

/// Number of chunks for n rows and the largest chunk's size.
inline Index chunk_count(Index n, Index requested) { return exec::detail::chunk_count(n, requested); }
inline Index max_chunk_rows(Index n, Index chunks) { return chunks > 0 ? (n + chunks - 1) / chunks : 0; }

/// Calls body(worker, chunk, begin, end) for each of the `chunks` row ranges of [0, n); worker w
/// takes chunks w, w + workers, … (a chunk's arithmetic never depends on its worker).
template <class Policy, class Body>
void for_chunks(Policy policy, Index n, Index chunks, Index workers, Body&& body) {
  exec::parallel_for(policy, workers, [&](Index w) {
    for (Index c = w; c < chunks; c += workers) {
      const auto [b, e] = exec::detail::chunk_range(n, chunks, c);
      body(w, c, b, e);
    }
  });
}

}  // namespace simsr::nn::detail
