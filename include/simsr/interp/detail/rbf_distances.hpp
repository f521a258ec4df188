#pragma once
/// \file
/// Distances behind the RBF kernel matrices (A.2, Eq. 10–11):
///  - surface_rows: geodesic distances over the HR rest surface's edges from the HR vertices the
///    LR vertices are mapped onto (§3.2), one radius-limited Dijkstra per LR vertex; gives both
///    Φ_LL and Φ_HL of RbfDistance::geodesic in one metric;
///  - geodesic_rows: distances along the edges of the LR volume mesh (RbfDistance::lr_mesh_geodesic);
///  - euclidean_rows: straight-line distances within a radius (brute force).
/// Each source's row depends on that source only (per-chunk buffers reset through touched lists),
/// so every policy gives the same bits.

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <span>
#include <utility>
#include <vector>

#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/topology.hpp"
#include "../../neighbors/surface_graph.hpp"

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

/// Shortest-path rows of a CSR graph (offsets/neighbors/lengths, #V = offsets.size() − 1) from
/// vertex `source_vertex(s)` for s in [0, num_sources): all vertices within path length `radius`
/// (+inf: every reachable one) with their distances, sorted by vertex, handed to `sink(s, row)`
/// (called from several threads at once, for distinct s). Chunks of sources run under `policy`,
/// each with its own #V distance array, reset only where touched. A vertex within the radius
/// gets its exact shortest-path distance: every prefix of a shortest path is shorter still.
template <exec::HostPolicy Policy, class Graph, class SourceVertex, class Sink>
void dijkstra_rows(Policy policy, const Graph& g, const std::vector<double>& lengths, Index num_sources,
                   SourceVertex&& source_vertex, double radius, Sink&& sink) {
  const Index nv = Index(g.offsets.size()) - 1;
  const Index chunks = std::min<Index>(num_sources, 64);
  constexpr double inf = std::numeric_limits<double>::infinity();
  exec::parallel_for(policy, chunks, [&](Index c) {
    const Index b = num_sources * c / chunks, e = num_sources * (c + 1) / chunks;
    std::vector<double> dist(static_cast<std::size_t>(nv), inf);
    std::vector<VIndex> touched;
    using Item = std::pair<double, VIndex>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    DistanceRow row;
    for (Index s = b; s < e; ++s) {
      row.clear();
      const VIndex src = VIndex(source_vertex(s));
      dist[std::size_t(src)] = 0;
      touched.push_back(src);
      heap.push({0.0, src});
      while (!heap.empty()) {
        const auto [d, v] = heap.top();
        heap.pop();
        if (d > dist[std::size_t(v)]) continue;
        row.emplace_back(v, d);
        for (Index a = g.offsets[std::size_t(v)]; a < g.offsets[std::size_t(v) + 1]; ++a) {
          const VIndex w = g.neighbors[std::size_t(a)];
          const double nd = d + lengths[std::size_t(a)];
          if (nd <= radius && nd < dist[std::size_t(w)]) {
            if (dist[std::size_t(w)] == inf) touched.push_back(w);
            dist[std::size_t(w)] = nd;
            heap.push({nd, w});
          }
        }
      }
      for (VIndex v : touched) dist[std::size_t(v)] = inf;
      touched.clear();
      std::sort(row.begin(), row.end());
      sink(s, row);
    }
  });
}

/// For every vertex s of the LR mesh graph g, the vertices within path length `radius` (+inf: all
/// reachable ones) with their shortest-path distances (RbfDistance::lr_mesh_geodesic), handed to
/// `sink(s, row)` as dijkstra_rows does.
template <exec::HostPolicy Policy, class Sink>
void geodesic_rows(Policy policy, const RbfEdgeGraph& g, double radius, Sink&& sink) {
  dijkstra_rows(policy, g, g.lengths, g.num_vertices(), [](Index s) { return s; }, radius, sink);
}

/// For every LR vertex s (mapped onto HR vertex `lr_to_hr[s]`), the HR vertices within geodesic
/// distance `radius` over the HR surface edge graph g (neighbors::surface_edge_graph,
/// rest lengths) and their distances, handed to `sink(s, row)` as dijkstra_rows does. These are
/// the single-source distances the §3.2 neighbourhoods hold, bit for bit.
template <exec::HostPolicy Policy, class Sink>
void surface_rows(Policy policy, const neighbors::WeightedGraph& g, std::span<const VIndex> lr_to_hr,
                  double radius, Sink&& sink) {
  dijkstra_rows(policy, g, g.weights, Index(lr_to_hr.size()), [&](Index s) { return lr_to_hr[std::size_t(s)]; },
                radius, sink);
}

/// Mean over sources s of the geodesic distance from `lr_to_hr[s]` to the nearest other mapped
/// vertex over g: the spacing of the RBF centres in the metric of RbfDistance::geodesic. Each
/// search stops at the first other mapped vertex; a source that reaches none is skipped. 0 when
/// no source reaches another.
template <exec::HostPolicy Policy>
double mean_nearest_source_distance(Policy policy, const neighbors::WeightedGraph& g,
                                    std::span<const VIndex> lr_to_hr) {
  const Index ns = Index(lr_to_hr.size()), nv = g.num_vertices();
  std::vector<char> mapped(static_cast<std::size_t>(nv), 0);
  for (VIndex v : lr_to_hr) mapped[std::size_t(v)] = 1;
  std::vector<double> nearest(static_cast<std::size_t>(ns), -1);
  const Index chunks = std::min<Index>(ns, 64);
  constexpr double inf = std::numeric_limits<double>::infinity();
  exec::parallel_for(policy, chunks, [&](Index c) {
    std::vector<double> dist(static_cast<std::size_t>(nv), inf);
    std::vector<VIndex> touched;
    using Item = std::pair<double, VIndex>;
    std::vector<Item> heap;
    const auto later = [](const Item& a, const Item& b) { return a > b; };
    for (Index s = ns * c / chunks; s < ns * (c + 1) / chunks; ++s) {
      const VIndex src = lr_to_hr[std::size_t(s)];
      heap.assign(1, {0.0, src});
      dist[std::size_t(src)] = 0;
      touched.push_back(src);
      while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end(), later);
        const auto [d, v] = heap.back();
        heap.pop_back();
        if (d > dist[std::size_t(v)]) continue;
        if (v != src && mapped[std::size_t(v)]) {
          nearest[std::size_t(s)] = d;
          break;
        }
        for (Index a = g.offsets[std::size_t(v)]; a < g.offsets[std::size_t(v) + 1]; ++a) {
          const VIndex w = g.neighbors[std::size_t(a)];
          const double nd = d + g.weights[std::size_t(a)];
          if (nd < dist[std::size_t(w)]) {
            if (dist[std::size_t(w)] == inf) touched.push_back(w);
            dist[std::size_t(w)] = nd;
            heap.push_back({nd, w});
            std::push_heap(heap.begin(), heap.end(), later);
          }
        }
      }
      for (VIndex v : touched) dist[std::size_t(v)] = inf;
      touched.clear();
    }
  });
  double sum = 0;
  Index count = 0;
  for (double d : nearest)
    if (d >= 0) sum += d, ++count;
  return count ? sum / double(count) : 0.0;
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
