#pragma once
/// \file
/// Distances behind the RBF kernel matrices: geodesic LR–LR distances along the edges of the LR
/// volume mesh (Dijkstra from every LR vertex, optionally stopped at a radius, as A.2 asks for
/// "geodesically following §3.2") and Euclidean distances within a radius (brute force, rows in
/// parallel). Each source's row depends on that source only, so every policy gives the same result.

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/topology.hpp"

namespace simsr::interp::detail {

/// Undirected edge graph in CSR form, edge weights = Euclidean rest lengths.
struct RbfEdgeGraph {
  std::vector<Index> offsets;
  std::vector<VIndex> neighbors;
  std::vector<double> lengths;
  Index num_vertices() const { return Index(offsets.size()) - 1; }
};

/// The graph of all corner pairs of elements E (#E×2..4) over vertices V (#V×3).
template <class DV, class DE>
RbfEdgeGraph rbf_edge_graph(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DE>& E) {
  const Edges U = unique_edges(E);
  const Index nv = V.rows();
  RbfEdgeGraph g;
  g.offsets.assign(std::size_t(nv + 1), 0);
  for (Index e = 0; e < U.rows(); ++e) ++g.offsets[std::size_t(U(e, 0)) + 1], ++g.offsets[std::size_t(U(e, 1)) + 1];
  for (Index v = 0; v < nv; ++v) g.offsets[std::size_t(v + 1)] += g.offsets[std::size_t(v)];
  g.neighbors.resize(std::size_t(g.offsets.back()));
  g.lengths.resize(std::size_t(g.offsets.back()));
  std::vector<Index> fill(g.offsets.begin(), g.offsets.end() - 1);
  for (Index e = 0; e < U.rows(); ++e) {
    const VIndex a = U(e, 0), b = U(e, 1);
    const double len = (V.row(a).template cast<double>() - V.row(b).template cast<double>()).norm();
    g.neighbors[std::size_t(fill[std::size_t(a)])] = b, g.lengths[std::size_t(fill[std::size_t(a)]++)] = len;
    g.neighbors[std::size_t(fill[std::size_t(b)])] = a, g.lengths[std::size_t(fill[std::size_t(b)]++)] = len;
  }
  return g;
}

/// One row of a distance matrix within a radius: (column, distance), sorted by column.
using DistanceRow = std::vector<std::pair<VIndex, double>>;

/// For every vertex s of g, the vertices within path length `radius` (+inf: all reachable ones)
/// with their shortest-path distances, handed to `sink(s, row)` (sink may be called from several
/// threads at once, for distinct s). Chunks of sources run under `policy`, each chunk with its own
/// #V distance array reset only where touched.
template <exec::HostPolicy Policy, class Sink>
void geodesic_rows(Policy policy, const RbfEdgeGraph& g, double radius, Sink&& sink) {
  const Index nv = g.num_vertices();
  const Index chunks = std::min<Index>(nv, 64);
  exec::parallel_for(policy, chunks, [&](Index c) {
    const Index b = nv * c / chunks, e = nv * (c + 1) / chunks;
    std::vector<double> dist(static_cast<std::size_t>(nv), std::numeric_limits<double>::infinity());
    std::vector<VIndex> touched;
    using Item = std::pair<double, VIndex>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    DistanceRow row;
    for (Index s = b; s < e; ++s) {
      row.clear();
      dist[std::size_t(s)] = 0;
      touched.push_back(VIndex(s));
      heap.push({0.0, VIndex(s)});
      while (!heap.empty()) {
        const auto [d, v] = heap.top();
        heap.pop();
        if (d > dist[std::size_t(v)]) continue;
        row.emplace_back(v, d);
        for (Index a = g.offsets[std::size_t(v)]; a < g.offsets[std::size_t(v) + 1]; ++a) {
          const VIndex w = g.neighbors[std::size_t(a)];
          const double nd = d + g.lengths[std::size_t(a)];
          if (nd <= radius && nd < dist[std::size_t(w)]) {
            if (dist[std::size_t(w)] == std::numeric_limits<double>::infinity()) touched.push_back(w);
            dist[std::size_t(w)] = nd;
            heap.push({nd, w});
          }
        }
      }
      for (VIndex v : touched) dist[std::size_t(v)] = std::numeric_limits<double>::infinity();
      touched.clear();
      std::sort(row.begin(), row.end());
      sink(s, row);
    }
  });
}

/// For every row q of Q (#Q×3), the rows p of P (#P×3) with |q − p| ≤ radius and their distances,
/// sorted by p, handed to `sink(q, row)` as geodesic_rows does. Brute force O(#Q·#P).
template <exec::HostPolicy Policy, class S, class Sink>
void euclidean_rows(Policy policy, const Points<S>& Q, const Points<S>& P, double radius, Sink&& sink) {
  const double r2 = radius * radius;
  const Index nq = Q.rows(), chunks = std::min<Index>(nq, 64);
  exec::parallel_for(policy, chunks, [&](Index c) {
    DistanceRow row;
    for (Index q = nq * c / chunks; q < nq * (c + 1) / chunks; ++q) {
      row.clear();
      const Eigen::RowVector3d x = Q.row(q).template cast<double>();
      for (Index p = 0; p < P.rows(); ++p) {
        const double d2 = (P.row(p).template cast<double>() - x).squaredNorm();
        if (d2 <= r2) row.emplace_back(VIndex(p), std::sqrt(d2));
      }
      sink(q, row);
    }
  });
}

}  // namespace simsr::interp::detail
