#pragma once
/// \file
/// What every interpolator is fitted on: the LR rest volume mesh, the HR rest surface and (for the
/// neighbourhood-based methods) the §3.2 upsampling neighbourhoods, computed once and shared.
///
///     interp::UpsamplingProblem<> p{lr_rest, hr_rest};          // neighbourhoods computed on demand
///     p.neighborhoods = neighbors::load_upsampling_neighborhoods("N.npz");   // or reuse saved ones
///     interp::MLS<> mls;  mls.fit(p);  mls.apply(lr_displacement, hr_displacement);

#include <memory>
#include <optional>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/tri_mesh.hpp"
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

  Index num_lr() const { return lr.num_vertices(); }
  Index num_hr() const { return hr.num_vertices(); }

  /// The neighbourhoods, computed with k neighbours (assignment + k-label Dijkstra) if absent.
  /// Throws ArgumentError when saved ones have a different k or size than asked.
  template <exec::HostPolicy Policy = exec::seq_t>
  const neighbors::UpsamplingNeighborhoods& ensure_neighborhoods(Index k = 20, Policy policy = {}) {
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
