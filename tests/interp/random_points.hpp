#pragma once
// Uniform random point sets for the interp tests (IDW, MLS).
#include <simsr/core/types.hpp>

#include <random>

namespace simsr::test {

/// n uniform random points in [lo, hi]³.
inline Points<> random_points(Index n, double lo, double hi, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(lo, hi);
  Points<> P(n, 3);
  for (Index i = 0; i < P.size(); ++i) P.data()[i] = u(rng);
  return P;
}

}  // namespace simsr::test
