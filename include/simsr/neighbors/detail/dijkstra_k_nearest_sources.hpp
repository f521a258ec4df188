#pragma once
/// \file
/// Graph searches behind upsampling_neighborhoods: the edge graph of a surface with rest lengths,
/// the k-label multi-source Dijkstra (k nearest sources of every vertex) and the plain
/// single-source Dijkstra it is checked against.

#include <algorithm>
#include <limits>
#include <span>
#include <vector>

#include "../../core/types.hpp"
#include "../../mesh/topology.hpp"
#include "../surface_graph.hpp"
#include "assignment_knn.hpp"

namespace simsr::neighbors::detail {

using neighbors::WeightedGraph;

/// k-label Dijkstra: for every vertex its k nearest sources (source s sits at vertex
/// `source_vertex[s]`) by shortest-path distance, ordered by (distance, source id). Writes
/// `indices`/`distances` (row-major #V×k, rows with fewer reachable sources padded with −1/+inf)
/// and returns per-vertex label counts.
///
/// Each vertex settles at most k labels, one per source; a label (d, s) reaching vertex w is
/// kept only if s is not settled there yet. Pruning at full vertices is exact: if s is not among
/// the k nearest of u, the k sources nearer to u are also nearer (or tied with a smaller id) to
/// anything reached through u. Labels pop in (distance, source) order and floating-point
/// addition is monotone, so every settled distance equals, bit for bit, what a single-source
/// Dijkstra from s computes. O(V·k·deg·log(V·k·deg)) time, O(V·k) memory.
inline std::vector<Index> k_nearest_sources(const WeightedGraph& g, std::span<const VIndex> source_vertex, Index k,
                                            VIndex* indices, double* distances) {
  const Index nv = g.num_vertices();
  std::fill(indices, indices + nv * k, VIndex{-1});
  std::fill(distances, distances + nv * k, std::numeric_limits<double>::infinity());
  std::vector<Index> count(static_cast<std::size_t>(nv), 0);
  struct Label {
    double d;
    VIndex s, v;
  };
  const auto later = [](const Label& a, const Label& b) {
    if (a.d != b.d) return a.d > b.d;
    if (a.s != b.s) return a.s > b.s;
    return a.v > b.v;
  };
  const auto settled = [&](Index v, VIndex s) {
    const VIndex* row = indices + v * k;
    return std::find(row, row + count[v], s) != row + count[v];
  };
  std::vector<Label> heap;
  heap.reserve(static_cast<std::size_t>(nv * k));
  for (std::size_t s = 0; s < source_vertex.size(); ++s) heap.push_back({0.0, static_cast<VIndex>(s), source_vertex[s]});
  std::make_heap(heap.begin(), heap.end(), later);
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const Label l = heap.back();
    heap.pop_back();
    if (count[l.v] == k || settled(l.v, l.s)) continue;
    indices[l.v * k + count[l.v]] = l.s;
    distances[l.v * k + count[l.v]] = l.d;
    ++count[l.v];
    for (Index e = g.offsets[l.v]; e < g.offsets[l.v + 1]; ++e) {
      const VIndex w = g.neighbors[e];
      if (count[w] == k || settled(w, l.s)) continue;
      heap.push_back({l.d + g.weights[e], l.s, w});
      std::push_heap(heap.begin(), heap.end(), later);
    }
  }
  return count;
}

/// Shortest-path distances from vertex `source` to every vertex (+inf where unreachable).
inline std::vector<double> dijkstra(const WeightedGraph& g, VIndex source) {
  std::vector<double> dist(static_cast<std::size_t>(g.num_vertices()), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, VIndex>;
  std::vector<Item> heap{{0.0, source}};
  dist[source] = 0;
  const auto later = [](const Item& a, const Item& b) { return a > b; };
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const auto [d, v] = heap.back();
    heap.pop_back();
    if (d > dist[v]) continue;
    for (Index e = g.offsets[v]; e < g.offsets[v + 1]; ++e) {
      const double nd = d + g.weights[e];
      if (nd < dist[g.neighbors[e]]) {
        dist[g.neighbors[e]] = nd;
        heap.push_back({nd, g.neighbors[e]});
        std::push_heap(heap.begin(), heap.end(), later);
      }
    }
  }
  return dist;
}

}  // namespace simsr::neighbors::detail
