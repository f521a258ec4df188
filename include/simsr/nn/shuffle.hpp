#pragma once
/// \file
/// The shuffling of every training loop (nn::Trainer, the β-VAE baseline): a Fisher–Yates
/// permutation drawn from the 64-bit Mersenne twister with unbiased integers (rejection on the
/// top of the range), so a seed fixes the order of every epoch on every platform.
///
///     std::vector<Index> order;
///     nn::shuffled_order(rng, frames, order);   // a fresh permutation of 0..frames-1

#include <cstdint>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "tensor.hpp"

namespace simsr::nn {

/// An unbiased integer in [0, n) from `rng` (n ≥ 1).
inline Index uniform_index(Rng& rng, Index n) {
  if (n < 1) throw ArgumentError("nn::uniform_index: n must be ≥ 1, got " + std::to_string(n));
  const std::uint64_t un = std::uint64_t(n), limit = UINT64_MAX - UINT64_MAX % un;
  std::uint64_t x;
  do x = rng();
  while (x >= limit);
  return Index(x % un);
}

/// order = a Fisher–Yates permutation of 0..n-1 (resized to n; no allocation once warm).
inline void shuffled_order(Rng& rng, Index n, std::vector<Index>& order) {
  order.resize(std::size_t(n));
  for (Index i = 0; i < n; ++i) order[std::size_t(i)] = i;
  for (Index i = n - 1; i > 0; --i) std::swap(order[std::size_t(i)], order[std::size_t(uniform_index(rng, i + 1))]);
}

}  // namespace simsr::nn
