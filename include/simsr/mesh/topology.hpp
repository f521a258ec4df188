#pragma once
/// \file
/// Combinatorics of element lists (no coordinates): unique edges, vertex adjacency in CSR form,
/// the outward boundary of a tet mesh, connected components, and the boundary edges and loops of
/// a triangle mesh. Elements are rows of vertex indices: #E×2 edges, #F×3 triangles, #T×4 tets.

#include <algorithm>
#include <array>
#include <numeric>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "detail/elements.hpp"
#include "tet_mesh.hpp"
#include "tri_mesh.hpp"

namespace simsr {

namespace detail {

/// Throws MeshError for the first negative index, or one ≥ `num_vertices` when that is ≥ 0.
template <class DE>
void check_indices(const Eigen::MatrixBase<DE>& E, Index num_vertices) {
  for (Index e = 0; e < E.rows(); ++e)
    for (Index k = 0; k < E.cols(); ++k) {
      const Index v = E(e, k);
      if (v < 0 || (num_vertices >= 0 && v >= num_vertices))
        throw MeshError(element_kind(E.cols()), e,
                        "vertex index " + std::to_string(v) + " outside [0, " +
                            (num_vertices >= 0 ? std::to_string(num_vertices) : std::string("inf")) + ")");
    }
}

/// 1 + the largest index in `E` (0 when empty).
template <class DE>
Index vertex_count_of(const Eigen::MatrixBase<DE>& E) {
  return E.size() ? Index(E.maxCoeff()) + 1 : 0;
}

}  // namespace detail

/// Unique undirected edges of elements E (#E×k, k = 2, 3 or 4: every pair of corners of an
/// element is an edge; a pair of equal corners is skipped). Returns #U×2 with first < second,
/// rows sorted lexicographically. Throws MeshError for a negative index.
template <class DE>
Edges unique_edges(const Eigen::MatrixBase<DE>& E) {
  detail::require_cols_between("unique_edges: elements", E, 2, 4);
  detail::check_indices(E, -1);
  const Index k = E.cols();
  std::vector<std::uint64_t> keys;
  keys.reserve(static_cast<std::size_t>(E.rows() * k * (k - 1) / 2));
  for (Index e = 0; e < E.rows(); ++e)
    for (Index i = 0; i < k; ++i)
      for (Index j = i + 1; j < k; ++j) {
        VIndex a = E(e, i), b = E(e, j);
        if (a == b) continue;
        if (a > b) std::swap(a, b);
        keys.push_back(detail::pair_key(a, b));
      }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  Edges out(static_cast<Index>(keys.size()), 2);
  for (Index i = 0; i < out.rows(); ++i) {
    out(i, 0) = static_cast<VIndex>(keys[i] >> 32);
    out(i, 1) = static_cast<VIndex>(keys[i] & 0xffffffffu);
  }
  return out;
}

/// Vertex-to-vertex adjacency in CSR form: the neighbours of v are
/// `neighbors[offsets[v] .. offsets[v+1])`, sorted ascending, never v itself.
struct Adjacency {
  std::vector<Index> offsets{0};  ///< #V+1 entries, offsets[0] = 0
  std::vector<VIndex> neighbors;  ///< 2·#unique edges entries

  Index num_vertices() const { return static_cast<Index>(offsets.size()) - 1; }
  Index degree(Index v) const { return offsets[v + 1] - offsets[v]; }
  std::span<const VIndex> operator[](Index v) const {
    return {neighbors.data() + offsets[v], static_cast<std::size_t>(degree(v))};
  }
};

/// Adjacency of the vertex graph whose edges are all corner pairs of elements E (#E×k, k = 2..4).
/// `num_vertices` = #V (vertices referenced by no element get no neighbours); −1 means
/// 1 + the largest index. Throws MeshError for an index outside [0, num_vertices).
template <class DE>
Adjacency vertex_adjacency(const Eigen::MatrixBase<DE>& E, Index num_vertices = -1) {
  detail::require_cols_between("vertex_adjacency: elements", E, 2, 4);
  detail::check_indices(E, num_vertices);
  if (num_vertices < 0) num_vertices = detail::vertex_count_of(E);
  const Edges U = unique_edges(E);
  Adjacency A;
  A.offsets.assign(static_cast<std::size_t>(num_vertices + 1), 0);
  for (Index e = 0; e < U.rows(); ++e) ++A.offsets[U(e, 0) + 1], ++A.offsets[U(e, 1) + 1];
  std::partial_sum(A.offsets.begin(), A.offsets.end(), A.offsets.begin());
  A.neighbors.resize(static_cast<std::size_t>(2 * U.rows()));
  std::vector<Index> fill(A.offsets.begin(), A.offsets.end() - 1);
  // Edges are sorted by (first, second): every vertex receives its smaller neighbours (as
  // `second`) before its larger ones (as `first`), each group ascending, so lists come out sorted.
  for (Index e = 0; e < U.rows(); ++e) {
    const VIndex a = U(e, 0), b = U(e, 1);
    A.neighbors[fill[a]++] = b;
    A.neighbors[fill[b]++] = a;
  }
  return A;
}

/// Outward local faces of a positively oriented tet (v0..v3): face i is opposite corner i and
/// is counter-clockwise seen from outside.
inline constexpr std::array<std::array<int, 3>, 4> tet_faces{{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

/// Boundary of a tet mesh: the faces that belong to exactly one tet, #B×3, oriented outward
/// (counter-clockwise seen from outside) for positively oriented tets, ordered by (tet, local
/// face). T is #T×4. Throws MeshError (kind "tet", naming the third tet) when a face is shared by
/// more than two tets (non-manifold).
template <class DT>
Tris boundary_faces(const Eigen::MatrixBase<DT>& T) {
  detail::require_cols("boundary_faces: tets", T, 4);
  detail::check_indices(T, -1);
  struct Face {
    std::array<VIndex, 3> key;
    Index id;  // 4·tet + local face
  };
  std::vector<Face> faces(static_cast<std::size_t>(4 * T.rows()));
  for (Index t = 0; t < T.rows(); ++t)
    for (int f = 0; f < 4; ++f) {
      std::array<VIndex, 3> k{T(t, tet_faces[f][0]), T(t, tet_faces[f][1]), T(t, tet_faces[f][2])};
      std::sort(k.begin(), k.end());
      faces[4 * t + f] = {k, 4 * t + f};
    }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) { return a.key != b.key ? a.key < b.key : a.id < b.id; });
  std::vector<Index> boundary;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i == 1) boundary.push_back(faces[i].id);
    if (j - i > 2) {
      const auto& k = faces[i].key;
      throw MeshError("tet", faces[i + 2].id / 4,
                      "face (" + std::to_string(k[0]) + ", " + std::to_string(k[1]) + ", " + std::to_string(k[2]) +
                          ") is shared by " + std::to_string(j - i) + " tets (non-manifold; at most 2 may share a face)");
    }
    i = j;
  }
  std::sort(boundary.begin(), boundary.end());
  Tris B(static_cast<Index>(boundary.size()), 3);
  for (Index b = 0; b < B.rows(); ++b) {
    const Index t = boundary[b] / 4, f = boundary[b] % 4;
    for (int c = 0; c < 3; ++c) B(b, c) = T(t, tet_faces[f][c]);
  }
  return B;
}

/// Boundary surface of a tet mesh as a triangle mesh over the same vertices (unreferenced ones kept).
template <class S>
TriMesh<S> boundary_surface(const TetMesh<S>& mesh) {
  return TriMesh<S>{mesh.V, boundary_faces(mesh.T)};
}

/// Connected components of a vertex graph: `labels[v]` ∈ [0, count), numbered in order of each
/// component's smallest vertex; `sizes[c]` = number of vertices with label c.
struct Components {
  IndexVector labels;
  Index count = 0;
  std::vector<Index> sizes;
};

/// Components of the graph joining the corners of each element of E (#E×k, k = 2..4) over
/// `num_vertices` vertices (−1: 1 + the largest index). A vertex referenced by no element is a
/// component of its own. Throws MeshError for an index outside [0, num_vertices).
template <class DE>
Components connected_components(const Eigen::MatrixBase<DE>& E, Index num_vertices = -1) {
  detail::require_cols_between("connected_components: elements", E, 2, 4);
  detail::check_indices(E, num_vertices);
  if (num_vertices < 0) num_vertices = detail::vertex_count_of(E);
  std::vector<Index> parent(static_cast<std::size_t>(num_vertices));
  std::iota(parent.begin(), parent.end(), Index(0));
  auto find = [&](Index v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (Index e = 0; e < E.rows(); ++e)
    for (Index k = 1; k < E.cols(); ++k) {
      Index a = find(E(e, 0)), b = find(E(e, k));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the root is the smallest vertex
    }
  Components C;
  C.labels.resize(num_vertices);
  for (Index v = 0; v < num_vertices; ++v) {
    const Index r = find(v);
    if (r == v) {
      C.labels[v] = static_cast<VIndex>(C.count++);
      C.sizes.push_back(0);
    } else {
      C.labels[v] = C.labels[r];  // r < v: already labelled
    }
    ++C.sizes[C.labels[v]];
  }
  return C;
}

/// Boundary edges of a triangle mesh F (#F×3): edges used by exactly one triangle, oriented as
/// in that triangle (so they run counter-clockwise around the holes of an outward-oriented
/// surface), ordered by (triangle, corner). Returns #B×2. Edges shared by > 2 triangles are not
/// boundary.
template <class DF>
Edges boundary_edges(const Eigen::MatrixBase<DF>& F) {
  detail::require_cols("boundary_edges: triangles", F, 3);
  detail::check_indices(F, -1);
  std::vector<std::pair<std::uint64_t, Index>> half(static_cast<std::size_t>(3 * F.rows()));
  for (Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const VIndex a = F(f, c), b = F(f, (c + 1) % 3);
      half[3 * f + c] = {detail::pair_key(std::min(a, b), std::max(a, b)), 3 * f + c};
    }
  std::sort(half.begin(), half.end());
  std::vector<Index> ids;
  for (std::size_t i = 0; i < half.size();) {
    std::size_t j = i + 1;
    while (j < half.size() && half[j].first == half[i].first) ++j;
    if (j - i == 1) ids.push_back(half[i].second);
    i = j;
  }
  std::sort(ids.begin(), ids.end());
  Edges B(static_cast<Index>(ids.size()), 2);
  for (Index b = 0; b < B.rows(); ++b) {
    const Index f = ids[b] / 3, c = ids[b] % 3;
    B(b, 0) = F(f, c);
    B(b, 1) = F(f, (c + 1) % 3);
  }
  return B;
}

/// The vertices on the boundary of a triangle mesh F (#F×3): the ends of its boundary_edges,
/// each once, ascending (pinning a sheet's rim, holding an open cut).
template <class DF>
IndexVector boundary_vertices(const Eigen::MatrixBase<DF>& F) {
  const Edges B = boundary_edges(F);
  std::vector<VIndex> ids(B.data(), B.data() + B.size());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return Eigen::Map<const IndexVector>(ids.data(), Index(ids.size()));
}

/// Boundary loops of a triangle mesh F (#F×3): each loop lists its vertices in the direction of
/// `boundary_edges`, starting from the loop's first edge in that order. Throws MeshError (kind
/// "vertex") when the boundary edges do not close into loops (inconsistently oriented faces).
template <class DF>
std::vector<std::vector<VIndex>> boundary_loops(const Eigen::MatrixBase<DF>& F) {
  const Edges B = boundary_edges(F);
  std::vector<std::pair<VIndex, Index>> out_edges(static_cast<std::size_t>(B.rows()));  // (start vertex, edge)
  for (Index e = 0; e < B.rows(); ++e) out_edges[e] = {B(e, 0), e};
  std::sort(out_edges.begin(), out_edges.end());
  std::vector<char> used(static_cast<std::size_t>(B.rows()), 0);
  auto next_edge = [&](VIndex v) -> Index {
    auto it = std::lower_bound(out_edges.begin(), out_edges.end(), std::pair<VIndex, Index>{v, Index(-1)});
    for (; it != out_edges.end() && it->first == v; ++it)
      if (!used[it->second]) return it->second;
    return -1;
  };
  std::vector<std::vector<VIndex>> loops;
  for (Index e0 = 0; e0 < B.rows(); ++e0) {
    if (used[e0]) continue;
    std::vector<VIndex> loop{B(e0, 0)};
    used[e0] = 1;
    VIndex v = B(e0, 1);
    while (v != loop.front()) {
      loop.push_back(v);
      const Index e = next_edge(v);
      if (e < 0) throw MeshError("vertex", v, "boundary edges do not close into a loop here (inconsistently oriented triangles?)");
      used[e] = 1;
      v = B(e, 1);
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace simsr
