#pragma once
/// \file
/// The SoftDECA template's outer wrap at one surface resolution: the kit's wrap (ict_outer_wrap)
/// remeshed isotropically to a target edge length (mesh/isotropic_remesh.hpp, CGAL), its parts
/// (skin, mouth and eye sockets) and the neck cut kept, every new vertex put on the kit's surface
/// at its closest point and carrying that point's barycentric place on the kit, so expressions
/// interpolate linearly from the kit's vertices.
///
/// Why: the kit's triangles run from 0.2 mm at the lips' inner line to 5 mm on the scalp, and
/// the bending term E_curv (Laplacian, k/h² per vertex) is then four orders of magnitude stiffer
/// at the lips than elsewhere: there both solvers stall in the curved valleys of its
/// magnitude-only energy (README, "SoftDECA"). A uniform edge length removes the spread and is
/// the template's resolution as one parameter.
///
///     auto wrap = scenario::remeshed_outer_wrap(exec::omp, kit, 0.4);      // cm
///     auto tpl = scenario::softdeca_template(exec::omp, kit, wrap, {});
///
/// Optional: needs CGAL (-DSIMSR_WITH_CGAL=ON, target simsr::cgal).

#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/isotropic_remesh.hpp"
#include "../../neighbors/surface_distance.hpp"
#include "ict_template.hpp"

namespace simsr::scenario {

/// The kit's outer wrap remeshed to `edge_length` cm (see the file comment). ArgumentError for a
/// bad length; what isotropic_remesh throws.
template <exec::HostPolicy P>
IctOuterWrap remeshed_outer_wrap(P policy, const IctKit& kit, double edge_length, Index iterations = 5) {
  const IctOuterWrap source = ict_outer_wrap(policy, kit);
  std::vector<int> patch(source.part.size());
  for (std::size_t f = 0; f < patch.size(); ++f) patch[f] = int(source.part[f]);
  const RemeshedSurface r = isotropic_remesh(policy, source.mesh, patch, {.target_edge_length = edge_length, .iterations = iterations});
  IctOuterWrap wrap;
  wrap.closed = source.closed;
  wrap.mesh.F = r.mesh.F;
  wrap.part.resize(r.patch.size());
  for (std::size_t f = 0; f < r.patch.size(); ++f) wrap.part[f] = HeadPart(r.patch[f]);
  const Index nv = r.mesh.num_vertices();
  wrap.mesh.V.resize(nv, 3);
  wrap.kit_corners.resize(nv, 3);
  wrap.kit_weights.resize(nv, 3);
  const neighbors::SurfaceDistance<> dist(source.mesh);
  exec::parallel_for(policy, nv, [&](Index i) {
    const auto hit = dist.closest(r.mesh.V.row(i).transpose());
    Vec3<> x = Vec3<>::Zero();
    for (int c = 0; c < 3; ++c) {
      const VIndex s = source.mesh.F(hit.triangle, c);
      wrap.kit_corners(i, c) = source.kit_corners(s, 0);  // the kit wrap's vertices are kit vertices
      wrap.kit_weights(i, c) = hit.barycentric[c];
      x += hit.barycentric[c] * source.mesh.V.row(s).transpose();
    }
    wrap.mesh.V.row(i) = x.transpose();
  });
  return wrap;
}

}  // namespace simsr::scenario
