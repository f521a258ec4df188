#pragma once
/// \file
/// What every interpolator is fitted on: the LR rest volume mesh, the HR rest surface and (for the
/// neighbourhood-based methods) the §3.2 upsampling neighbourhoods, computed once and shared.
///
///     interp::UpsamplingProblem<> p{lr_rest, hr_rest};          // neighbourhoods computed on demand
///     p.neighborhoods = neighbors::load_upsampling_neighborhoods("N.npz");   // or reuse saved ones
///     interp::MLS<> mls;  mls.fit(exec::omp, p);  mls.apply(exec::omp, lr_displacement, hr_displacement);

#include <memory>
#include <optional>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/tri_mesh.hpp"
#include "../data/network_neighborhoods.hpp"
#include "../neighbors/geodesic_knn.hpp"
#include "../neighbors/upsampling_neighborhoods.hpp"

namespace simsr::interp {

/// Rest shapes of one LR→HR pair. `lr` is the LR volume mesh (N vertices, tets), `hr` the HR
/// surface (M vertices, triangles). Displacements are always relative to these rest positions.
template <class S = Scalar>
struct UpsamplingProblem {
  TetMesh<S> lr;
  TriMesh<S> hr;
  /// §3.2 neighbourhoods (M×k LR ids with geodesic distances); filled by `ensure_neighborhoods`.
  std::optional<neighbors::UpsamplingNeighborhoods> neighborhoods;
  /// N×k LR geodesic graph (self first): the first EdgeConv's graph of the network (§3.1);
  /// filled by `ensure_lr_graph` or from files by `use`.
  std::optional<data::NeighborIndices> lr_graph;

  /// Takes both neighbourhood sets from a network-neighbourhood source (the authors' files,
  /// `simsr neighbors`, or computed), checked against this problem's sizes.
  void use(const data::NetworkNeighborhoods& nb) {
    data::check_network_neighborhoods(nb, num_lr(), num_hr());
    neighborhoods = nb.upsampling;
    lr_graph = nb.lr_graph;
  }

  /// The LR graph with at least k columns, computed (geodesic kNN over the LR mesh edges) if absent.
  template <exec::HostPolicy Policy>
  const data::NeighborIndices& ensure_lr_graph(Policy policy, Index k) {
    if (!lr_graph) lr_graph = neighbors::geodesic_knn(policy, lr.V, lr.T, k).indices;
    if (lr_graph->rows() != num_lr() || lr_graph->cols() < k)
      throw ShapeError("upsampling problem: LR graph (N×≥k)", {num_lr(), k}, {lr_graph->rows(), lr_graph->cols()});
    return *lr_graph;
  }

  Index num_lr() const { return lr.num_vertices(); }
  Index num_hr() const { return hr.num_vertices(); }

  /// The neighbourhoods, computed with k neighbours (assignment + k-label Dijkstra) if absent.
  /// Throws ArgumentError when saved ones have a different k or size than asked.
  template <exec::HostPolicy Policy>
  const neighbors::UpsamplingNeighborhoods& ensure_neighborhoods(Policy policy, Index k = 20) {
    if (!neighborhoods) {
      neighbors::UpsamplingOptions o;
      o.k = k;
      neighborhoods = neighbors::upsampling_neighborhoods(policy, lr.V, hr.V, hr.F, o);
    }
    return checked_neighborhoods(k);
  }

  /// The neighbourhoods already present, checked against this problem's sizes and at least k columns.
  const neighbors::UpsamplingNeighborhoods& checked_neighborhoods(Index k) const {
    if (!neighborhoods) throw ArgumentError("upsampling problem: no neighbourhoods (call ensure_neighborhoods)");
    const auto& nb = *neighborhoods;
    if (nb.indices.rows() != num_hr())
      throw ShapeError("upsampling neighbourhoods", {num_hr(), k}, {nb.indices.rows(), nb.indices.cols()});
    if (nb.k() < k)
      throw ArgumentError("upsampling neighbourhoods have k = " + std::to_string(nb.k()) + ", " + std::to_string(k) + " needed");
    if (nb.indices.size() > 0 && (nb.indices.minCoeff() < 0 || nb.indices.maxCoeff() >= num_lr()))
      throw ArgumentError("upsampling neighbourhoods index LR vertices outside [0, " + std::to_string(num_lr()) + ")");
    return nb;
  }
};

}  // namespace simsr::interp
