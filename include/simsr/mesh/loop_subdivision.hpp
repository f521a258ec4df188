#pragma once
/// \file
/// Loop subdivision (Loop 1987) of a triangle mesh, as the linear map it is: every level splits
/// each triangle into four and places vertices by fixed stencils, so the fine positions are
/// S·V for one sparse matrix S (#V_fine × #V) that depends on the connectivity (and, for the
/// corners kept, the rest shape) only. Chen et al. 2023 make the fine rest mesh this way from the
/// coarse one, and the subdivided coarse simulation is their baseline: both are S·V.
///
///     const LoopSubdivision sub = loop_subdivision(rest_V, F, 3);   // 81 → 4,225 vertices
///     Points<> fine_rest = sub.S * rest_V;                          // and per frame: sub.S * V_t
///
/// Stencils (Loop 1987; Warren & Weimer's β): a new vertex on an interior edge (a, b) with
/// opposite vertices c, d: 3/8 (a + b) + 1/8 (c + d); on a boundary edge: 1/2 (a + b). An old
/// interior vertex of valence n: (1 − nβ) v + β Σ neighbours with
/// β = (5/8 − (3/8 + cos(2π/n)/4)²)/n. An old boundary vertex: 3/4 v + 1/8 (b₁ + b₂), its two
/// boundary neighbours (the cubic B-spline of the boundary curve). A boundary corner, where the
/// boundary turns by more than `corner_degrees`, keeps its position (a square sheet keeps its
/// corners). New vertices are numbered after the old ones, in unique_edges order.

#include <Eigen/SparseCore>
#include <cmath>
#include <numbers>
#include <string>
#include <unordered_map>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "detail/elements.hpp"
#include "topology.hpp"

namespace simsr {

/// The result of loop_subdivision: the fine triangles and the fine-from-coarse map.
struct LoopSubdivision {
  Tris F;                          ///< fine triangles, orientation kept
  Eigen::SparseMatrix<double> S;   ///< #V_fine × #V_coarse, rows sum to 1
};

struct LoopSubdivisionOptions {
  /// A boundary vertex whose boundary edges turn by more than this (degrees) is a corner and is
  /// interpolated. 180 or more: no corners.
  double corner_degrees = 30.0;
};

namespace detail {

/// One level of Loop subdivision: the fine triangles and the map from this level's vertices.
/// Throws MeshError for a non-manifold edge (more than two triangles) or a boundary vertex with
/// other than two boundary edges.
template <class S>
LoopSubdivision loop_level(const Points<S>& V, const Tris& F, double corner_degrees) {
  const Index n = V.rows();
  const Edges E = unique_edges(F);
  std::unordered_map<std::uint64_t, Index> edge_id;
  edge_id.reserve(static_cast<std::size_t>(E.rows()));
  for (Index e = 0; e < E.rows(); ++e) edge_id.emplace(pair_key(E(e, 0), E(e, 1)), e);
  auto id = [&](VIndex a, VIndex b) { return edge_id.at(a < b ? pair_key(a, b) : pair_key(b, a)); };
  // the vertices opposite each edge (−1 where there is none)
  std::vector<std::array<VIndex, 2>> opposite(static_cast<std::size_t>(E.rows()), {-1, -1});
  for (Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const Index e = id(F(f, (c + 1) % 3), F(f, (c + 2) % 3));
      auto& o = opposite[static_cast<std::size_t>(e)];
      if (o[0] < 0)
        o[0] = F(f, c);
      else if (o[1] < 0)
        o[1] = F(f, c);
      else
        throw MeshError("edge", e, "(" + std::to_string(E(e, 0)) + ", " + std::to_string(E(e, 1)) +
                                       ") is shared by more than two triangles: Loop subdivision needs a manifold mesh");
    }
  const Adjacency A = vertex_adjacency(F, n);
  std::vector<std::vector<VIndex>> boundary_neighbors(static_cast<std::size_t>(n));
  for (Index e = 0; e < E.rows(); ++e)
    if (opposite[static_cast<std::size_t>(e)][1] < 0) {
      boundary_neighbors[E(e, 0)].push_back(E(e, 1));
      boundary_neighbors[E(e, 1)].push_back(E(e, 0));
    }
  std::vector<Eigen::Triplet<double, Index>> trip;
  trip.reserve(static_cast<std::size_t>(7 * n + 4 * E.rows()));
  const double cos_corner = std::cos(corner_degrees * std::numbers::pi / 180.0);
  for (Index v = 0; v < n; ++v) {
    const auto& bn = boundary_neighbors[static_cast<std::size_t>(v)];
    if (bn.empty()) {
      const Index k = A.degree(v);
      if (k == 0) {  // a vertex in no triangle stays where it is
        trip.emplace_back(v, v, 1.0);
        continue;
      }
      const double t = 3.0 / 8.0 + std::cos(2 * std::numbers::pi / double(k)) / 4.0;
      const double beta = (5.0 / 8.0 - t * t) / double(k);
      trip.emplace_back(v, v, 1.0 - double(k) * beta);
      for (const VIndex w : A[v]) trip.emplace_back(v, w, beta);
    } else if (bn.size() == 2) {
      const Vec3<S> p = point(V, v), d1 = (p - point(V, bn[0])).normalized(), d2 = (point(V, bn[1]) - p).normalized();
      if (d1.dot(d2) < cos_corner) {  // the boundary turns by more than corner_degrees
        trip.emplace_back(v, v, 1.0);
      } else {
        trip.emplace_back(v, v, 0.75);
        trip.emplace_back(v, bn[0], 0.125);
        trip.emplace_back(v, bn[1], 0.125);
      }
    } else {
      throw MeshError("vertex", v, "has " + std::to_string(bn.size()) +
                                       " boundary edges (2 expected): Loop subdivision needs a manifold boundary");
    }
  }
  for (Index e = 0; e < E.rows(); ++e) {
    const auto& o = opposite[static_cast<std::size_t>(e)];
    const Index row = n + e;
    if (o[1] < 0) {
      trip.emplace_back(row, E(e, 0), 0.5);
      trip.emplace_back(row, E(e, 1), 0.5);
    } else {
      trip.emplace_back(row, E(e, 0), 0.375);
      trip.emplace_back(row, E(e, 1), 0.375);
      trip.emplace_back(row, o[0], 0.125);
      trip.emplace_back(row, o[1], 0.125);
    }
  }
  LoopSubdivision out;
  out.S.resize(n + E.rows(), n);
  out.S.setFromTriplets(trip.begin(), trip.end());
  out.F.resize(4 * F.rows(), 3);
  for (Index f = 0; f < F.rows(); ++f) {
    const VIndex a = F(f, 0), b = F(f, 1), c = F(f, 2);
    const VIndex ab = VIndex(n + id(a, b)), bc = VIndex(n + id(b, c)), ca = VIndex(n + id(c, a));
    out.F.row(4 * f + 0) << a, ab, ca;
    out.F.row(4 * f + 1) << ab, b, bc;
    out.F.row(4 * f + 2) << ca, bc, c;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }
  return out;
}

}  // namespace detail

/// `levels` levels of Loop subdivision of (V #V×3, F #F×3); V locates the corners (the map is
/// otherwise independent of it). levels = 0 gives F and the identity. Throws ArgumentError for
/// levels < 0 and MeshError as detail::loop_level does.
template <class S>
LoopSubdivision loop_subdivision(const Points<S>& V, const Tris& F, Index levels, LoopSubdivisionOptions options = {}) {
  if (levels < 0) throw ArgumentError("loop_subdivision: levels must be >= 0, got " + std::to_string(levels));
  detail::check_indices(F, V.rows());
  LoopSubdivision total;
  total.F = F;
  total.S.resize(V.rows(), V.rows());
  total.S.setIdentity();
  Points<S> current = V;
  for (Index l = 0; l < levels; ++l) {
    LoopSubdivision step = detail::loop_level(current, total.F, options.corner_degrees);
    current = (step.S.template cast<S>() * current).eval();
    total.S = (step.S * total.S).pruned();
    total.F = std::move(step.F);
  }
  return total;
}

}  // namespace simsr
