#pragma once
/// \file
/// Fixed chunking shared by every backend, so seq and omp split (and round) identically.

#include <algorithm>
#include <utility>

#include "../types.hpp"

namespace simsr::exec::detail {

/// Number of chunks actually used for `n` items when `requested` are asked for (at least 1).
inline Index chunk_count(Index n, Index requested) { return std::max<Index>(1, std::min(n, requested)); }

/// Half-open index range [begin, end) of chunk `c` of `chunks` over `n` items; sizes differ by ≤ 1.
inline std::pair<Index, Index> chunk_range(Index n, Index chunks, Index c) {
  const Index base = n / chunks, extra = n % chunks;
  const Index begin = c * base + std::min(c, extra);
  return {begin, begin + base + (c < extra ? 1 : 0)};
}

}  // namespace simsr::exec::detail
