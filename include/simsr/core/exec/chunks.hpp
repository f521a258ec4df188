#pragma once
/// \file
/// Fixed chunking shared by every backend and every area, so seq and omp split (and round)
/// identically:
///
///     const Index nc = exec::chunk_count(n, 64);
///     exec::for_chunks(exec::omp, n, nc, exec::worker_count(exec::omp, nc),
///                      [&](Index worker, Index chunk, Index begin, Index end) { ... });
///
/// A chunk's arithmetic never depends on the worker that runs it; per-worker scratch is indexed by
/// `worker` (< worker_count).

#include <algorithm>
#include <type_traits>
#include <utility>

#include "../types.hpp"
#include "policy.hpp"

namespace simsr::exec {

/// Number of chunks actually used for `n` items when `requested` are asked for (at least 1).
inline Index chunk_count(Index n, Index requested) { return std::max<Index>(1, std::min(n, requested)); }

/// Half-open index range [begin, end) of chunk `c` of `chunks` over `n` items; sizes differ by ≤ 1.
inline std::pair<Index, Index> chunk_range(Index n, Index chunks, Index c) {
  const Index base = n / chunks, extra = n % chunks;
  const Index begin = c * base + std::min(c, extra);
  return {begin, begin + base + (c < extra ? 1 : 0)};
}

/// Size of the largest of `chunks` chunks over `n` items (for per-worker scratch).
inline Index max_chunk_size(Index n, Index chunks) { return chunks > 0 ? (n + chunks - 1) / chunks : 0; }

}  // namespace simsr::exec
