#pragma once
/// \file
/// Exact distances from points to a triangle surface, with the closest triangle and point.
///
///     simsr::neighbors::SurfaceDistance<> dist(head_surface);          // copies the surface (not copyable)
///     auto hit = dist.closest(q);                                       // distance, triangle, barycentric
///     VecX<> d = dist.distances(exec::omp, Q);                          // one per row of Q
///
/// Candidates come from a kd-tree over the vertices: if the nearest vertex is d_v away, the
/// closest triangle has a corner within d_v + L of the query, L being the longest distance from a
/// triangle's corner to any point of it (its longest edge). Triangles much larger than the rest
/// (a fan cap, say) would make L useless for all: those above 4× the median edge length are
/// checked for every query instead, and L is taken over the others. Each candidate's distance is
/// exact (closest_point_on_triangle); ties go to the lower triangle index.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/closest_point.hpp"
#include "../mesh/tri_mesh.hpp"
#include "kd_tree.hpp"
#include "knn_result.hpp"

namespace simsr::neighbors {

template <class S = Scalar>
class SurfaceDistance {
 public:
  /// The closest point of the surface to a query.
  struct Hit {
    S distance = std::numeric_limits<S>::infinity();
    Index triangle = -1;
    Vec3<S> barycentric = Vec3<S>::Zero();  ///< of the triangle's corners F(triangle, 0..2)
  };

  /// Indexes `surface` (copied). ArgumentError for an empty surface, a corner index out of range
  /// or a non-finite vertex.
  explicit SurfaceDistance(const TriMesh<S>& surface) : V_(surface.V), F_(surface.F) {
    if (F_.rows() == 0) throw ArgumentError("SurfaceDistance: the surface has no triangles");
    for (Index i = 0; i < F_.size(); ++i)
      if (F_.data()[i] < 0 || F_.data()[i] >= V_.rows())
        throw ArgumentError("SurfaceDistance: corner index " + std::to_string(F_.data()[i]) + " outside [0, " + std::to_string(V_.rows()) + ")");
    if (!V_.allFinite()) throw ArgumentError("SurfaceDistance: non-finite vertex coordinates");
    std::vector<S> longest(std::size_t(F_.rows()));
    for (Index f = 0; f < F_.rows(); ++f) {
      S m = 0;
      for (int c = 0; c < 3; ++c) m = std::max(m, (V_.row(F_(f, c)) - V_.row(F_(f, (c + 1) % 3))).norm());
      longest[std::size_t(f)] = m;
    }
    std::vector<S> sorted = longest;
    std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(sorted.size() / 2), sorted.end());
    const S large = S(4) * sorted[sorted.size() / 2];
    std::vector<Index> count(std::size_t(V_.rows()) + 1, 0);
    for (Index f = 0; f < F_.rows(); ++f) {
      if (longest[std::size_t(f)] > large) {
        always_.push_back(f);
        continue;
      }
      reach_ = std::max(reach_, longest[std::size_t(f)]);
      for (int c = 0; c < 3; ++c) ++count[std::size_t(F_(f, c)) + 1];
    }
    for (std::size_t v = 1; v < count.size(); ++v) count[v] += count[v - 1];
    offsets_ = count;
    incident_.resize(std::size_t(offsets_.back()));
    for (Index f = 0; f < F_.rows(); ++f) {
      if (longest[std::size_t(f)] > large) continue;
      for (int c = 0; c < 3; ++c) incident_[std::size_t(count[std::size_t(F_(f, c))]++)] = f;
    }
    // the tree holds the vertices some triangle uses (an unused one would give no bound)
    std::vector<char> used(std::size_t(V_.rows()), 0);
    for (Index i = 0; i < F_.size(); ++i) used[std::size_t(F_.data()[i])] = 1;
    for (Index v = 0; v < V_.rows(); ++v)
      if (used[std::size_t(v)]) tree_vertex_.push_back(v);
    P_.resize(Index(tree_vertex_.size()), 3);
    for (Index i = 0; i < P_.rows(); ++i) P_.row(i) = V_.row(tree_vertex_[std::size_t(i)]);
    tree_.build(P_);
  }

  SurfaceDistance(const SurfaceDistance&) = delete;  // the tree points into this object
  SurfaceDistance& operator=(const SurfaceDistance&) = delete;

  const Points<S>& vertices() const { return V_; }
  const Tris& triangles() const { return F_; }

  /// The closest point of the surface to q.
  Hit closest(const Vec3<S>& q) const {
    if (!q.allFinite()) throw ArgumentError("SurfaceDistance: non-finite query point");
    Hit best;
    auto consider = [&](Index f) {
      const Vec3<S> a = V_.row(F_(f, 0)).transpose(), b = V_.row(F_(f, 1)).transpose(), c = V_.row(F_(f, 2)).transpose();
      const Vec3<S> w = closest_point_on_triangle(q, a, b, c);
      const S d = (w[0] * a + w[1] * b + w[2] * c - q).norm();
      if (d < best.distance || (d == best.distance && f < best.triangle)) best = {d, f, w};
    };
    for (Index f : always_) consider(f);
    if (offsets_.back() > 0) {
      thread_local Eigen::Matrix<S, 1, 3> row;
      thread_local KnnResult<S> knn;
      row = q.transpose();
      tree_.query_into(exec::seq, row, 1, knn);
      const S dv = S(knn.distances(0, 0));
      thread_local std::vector<std::pair<VIndex, S>> near;
      // strictly-closer search: nudge the radius so a corner exactly at d_v + L still counts
      tree_.radius_into(q, (dv + reach_) * (S(1) + S(1e-12)) + std::numeric_limits<S>::min(), near);
      for (const auto& [i, dist] : near) {
        const Index v = tree_vertex_[std::size_t(i)];
        for (Index k = offsets_[std::size_t(v)]; k < offsets_[std::size_t(v) + 1]; ++k) consider(incident_[std::size_t(k)]);
      }
    }
    return best;
  }

  /// Distance of every row of Q (#Q×3) to the surface.
  template <exec::HostPolicy P>
  VecX<S> distances(P policy, const Points<S>& Q) const {
    VecX<S> d(Q.rows());
    exec::parallel_for(policy, Q.rows(), [&](Index i) { d[i] = closest(Q.row(i).transpose()).distance; });
    return d;
  }

 private:
  Points<S> V_;
  Tris F_;
  std::vector<Index> always_;    ///< the large triangles, checked for every query
  std::vector<Index> offsets_;   ///< vertex → its (ordinary) triangles, CSR
  std::vector<Index> incident_;
  S reach_ = 0;
  std::vector<Index> tree_vertex_;  ///< tree point → vertex
  Points<S> P_;                     ///< the tree's points (borrowed by tree_)
  KdTree<S> tree_;
};

}  // namespace simsr::neighbors
