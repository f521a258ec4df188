#pragma once
/// \file
/// Geodesic k-nearest neighbours along a mesh's edges (rest pose): Dijkstra from every vertex
/// over edge lengths, stopped once k vertices are settled. This is the first k-NN graph of the
/// feature encoder (§3.1: "geodesic distances based on the edge information of the LR mesh in the
/// rest pose"; k = 5 with the vertex itself first, as in DGCNN's reference code).
///
///     auto r = simsr::neighbors::geodesic_knn(simsr::exec::omp, lr.V, lr.T, 5);   // #V×5, r.indices(i,0) == i

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "../core/parallel.hpp"
#include "../mesh/topology.hpp"
#include "knn_result.hpp"

namespace simsr::neighbors {

/// Edge graph of a mesh with Euclidean edge lengths, queried for the k geodesically nearest
/// vertices of every vertex (itself first, at distance 0).
///
/// Distances are shortest-path lengths along edges (an upper bound of the true surface or volume
/// geodesic). Ties come by ascending index (the heap orders (distance, vertex)). The graph is
/// copied at build, so V and E may go away afterwards.
///
/// Cost: one Dijkstra per source that stops after k settled vertices, O(k·deg·log) each. Every
/// worker owns a distance array of #V entries set to +inf once; after a source only the entries
/// it touched are reset, so no O(#V) work per source. seq and omp give identical results (each
/// row depends on its source only). One object must not run two queries at once.
template <class S = Scalar>
class GeodesicKnn {
 public:
  using scalar_type = S;

  GeodesicKnn() = default;
  template <class DV, class DE>
  GeodesicKnn(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DE>& E) {
    build(V, E);
  }

  /// Graph of the edges of elements E (#E×c: c = 2 edges, 3 triangles, 4 tets; every corner pair
  /// is an edge) over vertices V (#V×3). MeshError for an index outside [0, #V); ArgumentError
  /// for non-finite positions; ShapeError for V not #V×3.
  template <class DV, class DE>
  void build(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DE>& E) {
    constexpr const char* where = "neighbors::GeodesicKnn::build";
    detail::check_cols(where, "vertices", V, 3);
    detail::check_finite_rows(where, "vertices", V);
    if (V.rows() > Index(std::numeric_limits<VIndex>::max())) throw ArgumentError(std::string(where) + ": too many vertices for 32-bit indices");
    Adjacency A = vertex_adjacency(E, V.rows());
    offsets_ = std::move(A.offsets);
    neighbors_ = std::move(A.neighbors);
    lengths_.resize(neighbors_.size());
    for (Index v = 0; v + 1 < static_cast<Index>(offsets_.size()); ++v)
      for (Index e = offsets_[v]; e < offsets_[v + 1]; ++e)
        lengths_[static_cast<std::size_t>(e)] =
            static_cast<S>((V.row(v).template cast<double>() - V.row(neighbors_[static_cast<std::size_t>(e)]).template cast<double>()).norm());
    ws_.clear();
  }

  /// Graph of `num_vertices` vertices with the given undirected edges (#E×2) and lengths (#E,
  /// finite, ≥ 0), e.g. lengths measured on another pose or an ideal lattice. A repeated edge
  /// keeps its shortest length. MeshError for an index outside [0, num_vertices); ArgumentError
  /// for a negative or non-finite length; ShapeError when the counts differ.
  template <class DE, class DL>
  void build_graph(Index num_vertices, const Eigen::MatrixBase<DE>& E, const Eigen::MatrixBase<DL>& lengths) {
    constexpr const char* where = "neighbors::GeodesicKnn::build_graph";
    detail::check_cols(where, "edges", E, 2);
    if (lengths.size() != E.rows()) throw ShapeError(std::string(where) + ": lengths", {E.rows()}, {lengths.size()});
    simsr::detail::check_indices(E, num_vertices);
    std::vector<std::pair<std::uint64_t, S>> arcs;  // (from << 32 | to, length), both directions
    arcs.reserve(static_cast<std::size_t>(2 * E.rows()));
    for (Index e = 0; e < E.rows(); ++e) {
      const S len = static_cast<S>(lengths(e));
      if (!(len >= 0) || !std::isfinite(len))
        throw ArgumentError(std::string(where) + ": edge " + std::to_string(e) + " has length " + std::to_string(len) + " (must be finite and >= 0)");
      const std::uint64_t a = static_cast<std::uint64_t>(E(e, 0)), b = static_cast<std::uint64_t>(E(e, 1));
      if (a == b) continue;
      arcs.emplace_back(a << 32 | b, len);
      arcs.emplace_back(b << 32 | a, len);
    }
    std::sort(arcs.begin(), arcs.end());
    offsets_.assign(static_cast<std::size_t>(num_vertices + 1), 0);
    neighbors_.clear();
    lengths_.clear();
    for (std::size_t i = 0; i < arcs.size(); ++i) {
      if (i > 0 && arcs[i].first == arcs[i - 1].first) continue;  // sorted: the first copy is the shortest
      ++offsets_[static_cast<std::size_t>(arcs[i].first >> 32) + 1];
      neighbors_.push_back(static_cast<VIndex>(arcs[i].first & 0xffffffffu));
      lengths_.push_back(arcs[i].second);
    }
    for (std::size_t v = 1; v < offsets_.size(); ++v) offsets_[v] += offsets_[v - 1];
    ws_.clear();
  }

  Index size() const { return static_cast<Index>(offsets_.size()) - 1; }

  /// The k geodesically nearest vertices of every vertex into `out` (#V×k, self first).
  /// ArgumentError when k < 1 or a vertex reaches fewer than k vertices along edges.
  template <exec::HostPolicy Policy>
  void query_into(Policy policy, Index k, KnnResult<S>& out) {
    constexpr const char* where = "neighbors::GeodesicKnn::query";
    const Index n = size();
    detail::check_k(where, k, n, "vertices");
    out.resize(n, k);
    Index workers = 1;
    if constexpr (std::is_same_v<Policy, exec::omp_t>) workers = std::min<Index>(n, exec::omp_max_threads());
    if (static_cast<Index>(ws_.size()) < workers) ws_.resize(static_cast<std::size_t>(workers));
    for (Index w = 0; w < workers; ++w) ws_[static_cast<std::size_t>(w)].reserve(n);
    exec::parallel_for(policy, workers, [&](Index w) {
      Workspace& ws = ws_[static_cast<std::size_t>(w)];
      const auto [s0, s1] = exec::chunk_range(n, workers, w);
      for (Index s = s0; s < s1; ++s) dijkstra(static_cast<VIndex>(s), k, ws, out, where);
    });
  }

  template <exec::HostPolicy Policy>
  KnnResult<S> query(Policy policy, Index k) {
    KnnResult<S> r;
    query_into(policy, k, r);
    return r;
  }

 private:
  struct alignas(64) Workspace {  // one cache line apart: workers push to their own vectors
    std::vector<S> dist;           // +inf except for touched vertices of the current source
    std::vector<std::uint8_t> settled;
    std::vector<VIndex> touched;
    std::vector<std::pair<S, VIndex>> heap;  // min-heap on (distance, vertex), lazy deletion

    void reserve(Index n) {
      if (static_cast<Index>(dist.size()) != n) {
        dist.assign(static_cast<std::size_t>(n), std::numeric_limits<S>::infinity());
        settled.assign(static_cast<std::size_t>(n), 0);
      }
    }
  };

  void dijkstra(VIndex source, Index k, Workspace& ws, KnnResult<S>& out, const char* where) const {
    constexpr auto later = [](const std::pair<S, VIndex>& a, const std::pair<S, VIndex>& b) { return detail::closer(b.first, b.second, a.first, a.second); };
    auto relax = [&](VIndex v, S d) {
      S& dv = ws.dist[static_cast<std::size_t>(v)];
      if (!(d < dv)) return;
      if (dv == std::numeric_limits<S>::infinity()) ws.touched.push_back(v);
      dv = d;
      ws.heap.emplace_back(d, v);
      std::push_heap(ws.heap.begin(), ws.heap.end(), later);
    };
    relax(source, S(0));
    Index found = 0;
    while (found < k && !ws.heap.empty()) {
      std::pop_heap(ws.heap.begin(), ws.heap.end(), later);
      const auto [d, v] = ws.heap.back();
      ws.heap.pop_back();
      if (ws.settled[static_cast<std::size_t>(v)]) continue;
      ws.settled[static_cast<std::size_t>(v)] = 1;
      out.indices(source, found) = v;
      out.distances(source, found) = d;
      if (++found == k) break;
      for (Index e = offsets_[v]; e < offsets_[v + 1]; ++e)
        if (!ws.settled[static_cast<std::size_t>(neighbors_[static_cast<std::size_t>(e)])])
          relax(neighbors_[static_cast<std::size_t>(e)], d + lengths_[static_cast<std::size_t>(e)]);
    }
    for (VIndex t : ws.touched) ws.dist[static_cast<std::size_t>(t)] = std::numeric_limits<S>::infinity(), ws.settled[static_cast<std::size_t>(t)] = 0;
    ws.touched.clear();
    ws.heap.clear();
    if (found < k)
      throw ArgumentError(std::string(where) + ": vertex " + std::to_string(source) + " reaches only " + std::to_string(found) +
                          " vertices (itself included) along edges, fewer than k = " + std::to_string(k));
  }

  std::vector<Index> offsets_{0};
  std::vector<VIndex> neighbors_;
  std::vector<S> lengths_;
  std::vector<Workspace> ws_;
};

/// The k geodesically nearest vertices (self first) of every vertex of V (#V×3) along the edges
/// of elements E (#E×2, ×3 or ×4). Builds a GeodesicKnn and queries it once.
template <class S = Scalar, exec::HostPolicy Policy, class DV, class DE>
KnnResult<S> geodesic_knn(Policy policy, const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DE>& E, Index k) {
  GeodesicKnn<S> g(V, E);
  return g.query(policy, k);
}

}  // namespace simsr::neighbors
