// WorkShard's block partition: over many (n, count), the shards' ranges tile [0, n) in order,
// their sizes differ by at most one (the longer ones first); bad shards are refused.
#include <doctest/doctest.h>

#include <simsr/core/work_shard.hpp>

#include <random>

using namespace simsr;

TEST_CASE("WorkShard::range tiles [0, n) in shard order, sizes within one of each other") {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 500; ++trial) {
    const Index n = Index(rng() % 200), count = 1 + Index(rng() % 17);
    Index next = 0, smallest = n + 1, largest = -1, previous = n + 1;
    for (Index k = 0; k < count; ++k) {
      const auto [first, last] = WorkShard{k, count}.range(n);
      CHECK(first == next);
      CHECK(last >= first);
      const Index size = last - first;
      CHECK(size <= previous);  // the longer shards first
      previous = size;
      smallest = std::min(smallest, size);
      largest = std::max(largest, size);
      next = last;
    }
    CHECK(next == n);
    CHECK(largest - smallest <= 1);
  }
  CHECK(WorkShard{}.whole());
  CHECK(WorkShard{}.range(7) == std::pair<Index, Index>{0, 7});
  CHECK(WorkShard{3, 4}.range(3) == std::pair<Index, Index>{3, 3});  // more shards than items: empty ones
}

TEST_CASE("WorkShard: an index outside [0, count) or a count below 1 is refused") {
  CHECK_THROWS_WITH_AS(WorkShard({2, 2}).range(5), "WorkShard::range: shard 2 of 2 (need 0 <= index < count)", ArgumentError);
  CHECK_THROWS_AS(WorkShard({-1, 2}).range(5), ArgumentError);
  CHECK_THROWS_AS(WorkShard({0, 0}).range(5), ArgumentError);
  CHECK_THROWS_AS(WorkShard({0, 1}).range(-1), ArgumentError);
}
