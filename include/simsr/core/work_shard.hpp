#pragma once
/// \file
/// Which part of a run's work one process does: shard `index` of `count`, the contiguous block
/// partition of n items (the first n mod count shards one item longer). The datagen functions take
/// one (SoftDecaDatagenOptions::shard, ...) so that several processes can share a run without the
/// library depending on how they were started; simsr::mpi hands each rank its shard.
///
///     const auto [first, last] = WorkShard{1, 4}.range(10);   // items 3, 4, 5: [3, 6)

#include <algorithm>
#include <string>
#include <utility>

#include "error.hpp"
#include "types.hpp"

namespace simsr {

struct WorkShard {
  Index index = 0;  ///< this process's shard, 0 ≤ index < count
  Index count = 1;  ///< how many shards the work is split into (1: all of it)

  /// True for the whole run (one shard).
  bool whole() const { return count == 1; }

  /// ArgumentError unless 0 ≤ index < count.
  void check(const std::string& who) const {
    if (count < 1 || index < 0 || index >= count)
      throw ArgumentError(who + ": shard " + std::to_string(index) + " of " + std::to_string(count) + " (need 0 <= index < count)");
  }

  /// [first, last) of n items: the block of this shard.
  std::pair<Index, Index> range(Index n) const {
    check("WorkShard::range");
    if (n < 0) throw ArgumentError("WorkShard::range: " + std::to_string(n) + " items");
    const Index base = n / count, extra = n % count;
    const Index first = index * base + std::min(index, extra);
    return {first, first + base + (index < extra ? 1 : 0)};
  }
};

}  // namespace simsr
