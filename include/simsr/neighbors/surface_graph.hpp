#pragma once
/// \file
/// The edge graph of a triangle surface with rest edge lengths, in CSR form: what geodesic
/// searches over the HR surface walk (the §3.2 k-label Dijkstra, RBF's surface distances).
///
///     const neighbors::WeightedGraph g = neighbors::surface_edge_graph(hr.V, hr.F);

#include <algorithm>
#include <vector>

#include "../core/types.hpp"
#include "../mesh/topology.hpp"
#include "detail/assignment_knn.hpp"

namespace simsr::neighbors {

/// Undirected graph in CSR form with non-negative edge weights (both directions stored).
struct WeightedGraph {
  std::vector<Index> offsets{0};
  std::vector<VIndex> neighbors;
  std::vector<double> weights;
  Index num_vertices() const { return static_cast<Index>(offsets.size()) - 1; }
};

/// Edge graph of the triangles F (#F×3) over the #V×3 vertices V, weighted by Euclidean edge
/// length in V.
template <class DV, class DF>
WeightedGraph surface_edge_graph(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F) {
  const Adjacency adj = vertex_adjacency(F, V.rows());
  WeightedGraph g;
  g.offsets = adj.offsets;
  g.neighbors = adj.neighbors;
  g.weights.resize(g.neighbors.size());
  for (Index v = 0; v < adj.num_vertices(); ++v)
    for (Index e = g.offsets[v]; e < g.offsets[v + 1]; ++e) {
      const Index a = std::min<Index>(v, g.neighbors[e]), b = std::max<Index>(v, g.neighbors[e]);
      g.weights[e] = detail::assignment_distance(V, a, V, b);  // same bits in both directions
    }
  return g;
}

}  // namespace simsr::neighbors
