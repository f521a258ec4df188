#pragma once
/// \file
/// How often a predicted surface passes through itself where it must not: per frame, the number of
/// intersecting triangle pairs between two contact patches (the lips), by the exact test of
/// mesh/triangle_intersection.hpp. The evaluation reports it for the truth and every method
/// beside Table 1 (issue #12 item 7: the lip-contact loss against none).
///
///     auto counts = eval::intersecting_pairs_per_frame(exec::omp, predictions.positions, lips);
///     eval::IntersectionSummary s = eval::summarize_intersections(counts);

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../data/frame_set.hpp"
#include "../mesh/contact_patches.hpp"
#include "../mesh/triangle_intersection.hpp"

namespace simsr::eval {

/// The grid spacing of the exact test for coordinates up to `max_abs`: the smallest power of two
/// that keeps them within 2^37 quanta (the test takes up to 2^38).
inline double intersection_quantum(double max_abs) {
  if (!std::isfinite(max_abs)) throw ArgumentError("intersection_quantum: the coordinates are not finite");
  return std::ldexp(1.0, std::ilogb(std::max(max_abs, 1e-300)) + 1 - 37);
}

/// Per frame (row of F×3M `positions`, vertex v of frame f at columns 3v..3v+2), the intersecting
/// (a, b) triangle pairs of the patches. ArgumentError for a patch index outside [0, M) or a
/// non-finite coordinate (naming the frame).
template <exec::HostPolicy P, class Derived>
std::vector<std::int64_t> intersecting_pairs_per_frame(P policy, const Eigen::MatrixBase<Derived>& positions, const ContactPatches& patches) {
  if (positions.cols() % 3) throw ArgumentError("intersecting_pairs_per_frame: positions need 3 columns per vertex, got " + std::to_string(positions.cols()));
  const Index F = positions.rows(), M = positions.cols() / 3;
  patches.check(M, "intersecting_pairs_per_frame");
  std::vector<std::int64_t> counts(static_cast<std::size_t>(F), 0);
  std::vector<std::string> errors(static_cast<std::size_t>(F));
  exec::parallel_for(policy, F, [&](Index f) {
    Points<> X(M, 3);
    for (Index v = 0; v < M; ++v)
      for (Index k = 0; k < 3; ++k) X(v, k) = double(positions(f, 3 * v + k));
    if (!X.allFinite()) {
      errors[std::size_t(f)] = "intersecting_pairs_per_frame: frame " + std::to_string(f) + " has a non-finite position";
      return;
    }
    const double q = intersection_quantum(X.cwiseAbs().maxCoeff());
    counts[std::size_t(f)] = std::int64_t(intersecting_triangle_pairs(X, patches.a, patches.b, q).size());
  });
  for (const auto& e : errors)
    if (!e.empty()) throw ArgumentError(e);
  return counts;
}

/// What a method's per-frame counts add up to.
struct IntersectionSummary {
  Index frames = 0;                  ///< frames counted
  Index frames_with_intersections = 0;
  std::int64_t pairs_total = 0, pairs_max = 0;
};

inline IntersectionSummary summarize_intersections(const std::vector<std::int64_t>& counts) {
  IntersectionSummary s;
  s.frames = Index(counts.size());
  for (const auto c : counts) {
    s.frames_with_intersections += c > 0;
    s.pairs_total += c;
    s.pairs_max = std::max(s.pairs_max, c);
  }
  return s;
}

}  // namespace simsr::eval
