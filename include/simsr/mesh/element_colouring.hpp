#pragma once
/// \file
/// A colouring of a mesh's elements (tets, triangles, any cells given as rows of vertex indices)
/// in which no two elements of one colour share a vertex: each colour's elements can then write
/// their vertices' data (a Hessian's blocks, nodal sums) side by side on many threads without
/// atomics, and in an order that does not depend on the thread count.
///
///     const ElementColouring c = greedy_element_colouring(mesh.T, mesh.num_vertices());
///     for (Index k = 0; k < c.num_colours(); ++k)
///       exec::parallel_for(exec::omp, c.size(k), [&](Index i) { scatter(c.element(k, i)); });
///
/// First-fit greedy in element order (Jones & Plassmann 1993 discuss the parallel variants): each
/// element takes the smallest colour none of its earlier vertex-sharing neighbours has: at most
/// 1 + the largest number of neighbours of one element colours. Cells of any size (CSR) colour
/// groups of elements alike: physics::ElasticEnergy colours chunks of consecutive tets.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "topology.hpp"

namespace simsr {

namespace detail {
/// Items 0..n−1 bucketed by key(i) ∈ [0, num_keys), each bucket in item order: bucket k is
/// items[offsets[k], offsets[k+1]) (a counting sort).
template <class Key>
void bucket_by_key(Index n, Index num_keys, Key key, std::vector<Index>& offsets, std::vector<Index>& items) {
  offsets.assign(std::size_t(num_keys) + 1, 0);
  for (Index i = 0; i < n; ++i) ++offsets[std::size_t(key(i)) + 1];
  for (Index k = 0; k < num_keys; ++k) offsets[std::size_t(k) + 1] += offsets[std::size_t(k)];
  items.resize(std::size_t(n));
  std::vector<Index> fill(offsets.begin(), offsets.end() - 1);
  for (Index i = 0; i < n; ++i) items[std::size_t(fill[std::size_t(key(i))]++)] = i;
}

/// First fit: the smallest colour that forbidden[colour] does not stamp with `stamp` (a neighbour
/// of the item being coloured has it), a new one where all are stamped.
inline Index first_free_colour(std::vector<Index>& forbidden, Index stamp) {
  Index colour = 0;
  while (colour < Index(forbidden.size()) && forbidden[std::size_t(colour)] == stamp) ++colour;
  if (colour == Index(forbidden.size())) forbidden.push_back(0);
  return colour;
}
}  // namespace detail

/// The elements of each colour, colour by colour, each colour's in increasing element order.
struct ElementColouring {
  std::vector<Index> offsets{0};  ///< colour k's elements are elements[offsets[k], offsets[k+1])
  std::vector<Index> elements;    ///< every element exactly once
  std::vector<Index> colour_of;   ///< element → its colour

  Index num_colours() const { return Index(offsets.size()) - 1; }
  Index num_elements() const { return Index(elements.size()); }
  /// Number of elements of colour k.
  Index size(Index k) const { return offsets[std::size_t(k) + 1] - offsets[std::size_t(k)]; }
  /// The i-th element of colour k.
  Index element(Index k, Index i) const { return elements[std::size_t(offsets[std::size_t(k)] + i)]; }
};

/// First-fit greedy colouring of cells of any sizes given as CSR: cell c's vertices are
/// vertices[offsets[c], offsets[c+1]), in [0, num_vertices) and distinct. No two cells of one
/// colour share a vertex. Sequential, O(Σ_c Σ_{v∈c} valence(v)). Throws MeshError naming the
/// first cell with an index out of range or a vertex repeated within it (such a cell would
/// conflict with itself), ArgumentError for offsets that do not start at 0, decrease or do not
/// end at vertices.size().
inline ElementColouring greedy_colouring(const std::vector<Index>& offsets, const std::vector<Index>& vertices, Index num_vertices) {
  if (num_vertices < 0) throw ArgumentError("greedy_colouring: negative vertex count " + std::to_string(num_vertices));
  if (offsets.empty() || offsets.front() != 0 || offsets.back() != Index(vertices.size()))
    throw ArgumentError("greedy_colouring: offsets must run from 0 to the " + std::to_string(vertices.size()) + " vertices listed");
  const Index nc = Index(offsets.size()) - 1;
  for (Index c = 0; c < nc; ++c)
    if (offsets[std::size_t(c) + 1] < offsets[std::size_t(c)]) throw ArgumentError("greedy_colouring: offsets decrease at cell " + std::to_string(c));
  std::vector<Index> mark(std::size_t(num_vertices), 0);
  for (Index c = 0; c < nc; ++c) {
    for (Index i = offsets[std::size_t(c)]; i < offsets[std::size_t(c) + 1]; ++i) {
      const Index v = vertices[std::size_t(i)];
      if (v < 0 || v >= num_vertices)
        throw MeshError("cell", c, "vertex index " + std::to_string(v) + " out of range [0, " + std::to_string(num_vertices) + ")");
      if (mark[std::size_t(v)] == c + 1) throw MeshError("cell", c, "vertex " + std::to_string(v) + " appears twice");
      mark[std::size_t(v)] = c + 1;
    }
  }
  // vertex → (cell, corner) entries; incident[j]'s cell is cell_of_entry[incident[j]]
  std::vector<Index> cell_of_entry(vertices.size());
  for (Index c = 0; c < nc; ++c)
    for (Index i = offsets[std::size_t(c)]; i < offsets[std::size_t(c) + 1]; ++i) cell_of_entry[std::size_t(i)] = c;
  std::vector<Index> first, incident;
  detail::bucket_by_key(Index(vertices.size()), num_vertices, [&](Index i) { return vertices[std::size_t(i)]; }, first, incident);
  ElementColouring out;
  out.colour_of.assign(std::size_t(nc), -1);
  // forbidden[colour] == c + 1: a neighbour of cell c has that colour (stamps: no clearing per cell)
  std::vector<Index> forbidden;
  for (Index c = 0; c < nc; ++c) {
    for (Index i = offsets[std::size_t(c)]; i < offsets[std::size_t(c) + 1]; ++i) {
      const std::size_t v = std::size_t(vertices[std::size_t(i)]);
      for (Index j = first[v]; j < first[v + 1]; ++j) {
        const Index col = out.colour_of[std::size_t(cell_of_entry[std::size_t(incident[std::size_t(j)])])];
        if (col >= 0) forbidden[std::size_t(col)] = c + 1;
      }
    }
    out.colour_of[std::size_t(c)] = detail::first_free_colour(forbidden, c + 1);
  }
  detail::bucket_by_key(nc, Index(forbidden.size()), [&](Index c) { return out.colour_of[std::size_t(c)]; }, out.offsets, out.elements);
  return out;
}

/// First-fit greedy colouring of the rows of `cells` (#C×k vertex indices) over `num_vertices`
/// vertices (greedy_colouring with k vertices per cell). An index outside [0, num_vertices) is a
/// MeshError naming the element by its kind ("tet 3: …", mesh/topology's check); a repeated
/// vertex, as greedy_colouring's.
template <class DC>
ElementColouring greedy_element_colouring(const Eigen::MatrixBase<DC>& cells, Index num_vertices) {
  if (num_vertices < 0) throw ArgumentError("greedy_element_colouring: negative vertex count " + std::to_string(num_vertices));
  detail::check_indices(cells, num_vertices);
  const Index nc = cells.rows(), k = cells.cols();
  std::vector<Index> offsets(std::size_t(nc) + 1), vertices(std::size_t(nc * k));
  for (Index c = 0; c <= nc; ++c) offsets[std::size_t(c)] = c * k;
  for (Index c = 0; c < nc; ++c)
    for (Index a = 0; a < k; ++a) vertices[std::size_t(c * k + a)] = Index(cells(c, a));
  return greedy_colouring(offsets, vertices, num_vertices);
}

/// First-fit greedy colouring of the nodes of a graph given as adjacency lists in CSR (node i's
/// neighbours are adjacent[offsets[i], offsets[i+1]); i itself may be listed, it is skipped): no
/// two adjacent nodes share a colour (distance-1, where greedy_colouring's cells conflict through a
/// shared vertex). For a symmetric sparsity pattern, its rows: the rows of one colour couple to
/// none of the others, so a Gauss–Seidel sweep updates them side by side (physics::Multigrid's
/// Smoother::gauss_seidel). The adjacency must be symmetric (j lists i where i lists j): an
/// entry without its mirror is an ArgumentError, as is an index out of range or bad offsets.
inline ElementColouring greedy_graph_colouring(const int* offsets, const int* adjacent, Index num_nodes) {
  if (num_nodes < 0) throw ArgumentError("greedy_graph_colouring: negative node count " + std::to_string(num_nodes));
  if (offsets[0] != 0) throw ArgumentError("greedy_graph_colouring: offsets must start at 0");
  ElementColouring out;
  out.colour_of.assign(std::size_t(num_nodes), -1);
  std::vector<Index> forbidden;  // forbidden[colour] == i + 1: a neighbour of node i has that colour
  for (Index i = 0; i < num_nodes; ++i) {
    if (offsets[i + 1] < offsets[i]) throw ArgumentError("greedy_graph_colouring: offsets decrease at node " + std::to_string(i));
    for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
      const Index j = adjacent[k];
      if (j < 0 || j >= num_nodes)
        throw ArgumentError("greedy_graph_colouring: node " + std::to_string(i) + " lists neighbour " + std::to_string(j) + " outside [0, " +
                            std::to_string(num_nodes) + ")");
      if (j < i && out.colour_of[std::size_t(j)] >= 0) forbidden[std::size_t(out.colour_of[std::size_t(j)])] = i + 1;
    }
    out.colour_of[std::size_t(i)] = detail::first_free_colour(forbidden, i + 1);
  }
  // symmetry: every listed pair is listed both ways (a one-sided entry would let two coupled nodes share a colour)
  for (Index i = 0; i < num_nodes; ++i)
    for (int k = offsets[i]; k < offsets[i + 1]; ++k) {
      const Index j = adjacent[k];
      if (j == i || out.colour_of[std::size_t(i)] != out.colour_of[std::size_t(j)]) continue;
      throw ArgumentError("greedy_graph_colouring: node " + std::to_string(i) + " lists " + std::to_string(j) + " but not the other way round: the adjacency must be symmetric");
    }
  detail::bucket_by_key(num_nodes, Index(forbidden.size()), [&](Index i) { return out.colour_of[std::size_t(i)]; }, out.offsets, out.elements);
  return out;
}

}  // namespace simsr
