#pragma once
/// \file
/// Isotropic remeshing of a triangle surface to a target edge length, by CGAL's
/// Polygon_mesh_processing::isotropic_remeshing (Botsch & Kobbelt 2004: split long edges,
/// collapse short ones, flip toward valence 6, tangential relaxation, projection back onto the
/// input), with patches kept: the polylines between triangles of different patch labels and the
/// open border stay where they are (their edges are split and collapsed along them, never
/// flipped, their vertices never smoothed off them), and every new triangle keeps its patch.
///
/// Why: a simulation mesh taken from an artist's model inherits its triangles, and those can
/// span two orders of magnitude (the ICT kit: 0.2 mm at the lips' inner line, 5 mm on the scalp).
/// Terms whose stiffness scales with a negative power of the local size (the Laplacian bending of
/// SoftDECA's E_curv: k/h²) then make the problem as stiff as its smallest triangle. A uniform
/// target length is the mesh's resolution as one parameter.
///
///     auto r = isotropic_remesh(exec::seq, surface, patch_of_triangle, {.target_edge_length = 0.3});
///
/// Optional: needs CGAL's headers (Debian's libcgal-dev, header-only with the Epick kernel); CMake's
/// -DSIMSR_WITH_CGAL=ON gives the target simsr::cgal. CGAL's remeshing is sequential whatever the
/// policy; the policy runs the checks.

#include <cmath>
#include <string>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "tri_mesh.hpp"

namespace simsr {

/// How isotropic_remesh works.
struct IsotropicRemeshOptions {
  double target_edge_length = 0;  ///< model units, > 0
  Index iterations = 5;           ///< split/collapse/flip/relax rounds (CGAL's number_of_iterations)
  Index relaxation_steps = 1;     ///< tangential smoothing steps per round
};

/// The remeshed surface and each triangle's patch label.
struct RemeshedSurface {
  TriMesh<> mesh;
  std::vector<int> patch;  ///< per triangle
};

/// `surface` (an oriented, edge-manifold triangle mesh; open borders allowed) remeshed to edge
/// lengths near `target_edge_length`, the patches of `patch` (one label per triangle) kept (see
/// the file comment). ShapeError for a patch list of the wrong size; ArgumentError for bad
/// options or non-finite vertices; MeshError naming the triangle that does not fit an
/// edge-manifold, oriented surface (a repeated corner, a third triangle on an edge, a flipped one).
template <exec::HostPolicy P>
RemeshedSurface isotropic_remesh(P policy, const TriMesh<>& surface, const std::vector<int>& patch, const IsotropicRemeshOptions& opt) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  if (!(opt.target_edge_length > 0) || !std::isfinite(opt.target_edge_length))
    throw ArgumentError("isotropic_remesh: target_edge_length must be finite and > 0, got " + std::to_string(opt.target_edge_length));
  if (opt.iterations < 1 || opt.relaxation_steps < 0)
    throw ArgumentError("isotropic_remesh: need iterations >= 1 and relaxation_steps >= 0");
  const Index nv = surface.num_vertices(), nf = surface.F.rows();
  if (Index(patch.size()) != nf) throw ShapeError("isotropic_remesh: patch labels", {nf}, {Index(patch.size())});
  if (nf == 0) throw ArgumentError("isotropic_remesh: the surface has no triangles");
  if (exec::parallel_reduce(policy, nv, Index(0), [&](Index i) { return Index(!surface.V.row(i).allFinite()); }, [](Index a, Index b) { return a + b; }) > 0)
    throw ArgumentError("isotropic_remesh: a vertex position is not finite");

  Mesh m;
  std::vector<Mesh::Vertex_index> vi(static_cast<std::size_t>(nv));
  for (Index i = 0; i < nv; ++i) vi[std::size_t(i)] = m.add_vertex(Kernel::Point_3(surface.V(i, 0), surface.V(i, 1), surface.V(i, 2)));
  auto label = m.add_property_map<Mesh::Face_index, int>("f:simsr_patch", 0).first;
  for (Index f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c)
      if (surface.F(f, c) < 0 || surface.F(f, c) >= nv)
        throw MeshError("triangle", f, "vertex index " + std::to_string(surface.F(f, c)) + " outside [0, " + std::to_string(nv) + ")");
    const Mesh::Face_index fi = m.add_face(vi[std::size_t(surface.F(f, 0))], vi[std::size_t(surface.F(f, 1))], vi[std::size_t(surface.F(f, 2))]);
    if (fi == Mesh::null_face())
      throw MeshError("triangle", f, "does not fit an oriented edge-manifold surface (a repeated corner, a third triangle on an edge, or opposite orientation)");
    label[fi] = patch[std::size_t(f)];
  }

  namespace PMP = CGAL::Polygon_mesh_processing;
  PMP::isotropic_remeshing(faces(m), opt.target_edge_length, m,
                           CGAL::parameters::number_of_iterations(unsigned(opt.iterations))
                               .number_of_relaxation_steps(unsigned(opt.relaxation_steps))
                               .face_patch_map(label)
                               .protect_constraints(false));
  m.collect_garbage();

  RemeshedSurface r;
  r.mesh.V.resize(Index(m.number_of_vertices()), 3);
  for (Mesh::Vertex_index v : m.vertices()) {
    const auto& p = m.point(v);
    r.mesh.V.row(Index(v.idx())) << p.x(), p.y(), p.z();
  }
  r.mesh.F.resize(Index(m.number_of_faces()), 3);
  r.patch.reserve(m.number_of_faces());
  Index f = 0;
  for (Mesh::Face_index fi : m.faces()) {
    int c = 0;
    for (Mesh::Vertex_index v : CGAL::vertices_around_face(m.halfedge(fi), m)) r.mesh.F(f, c++) = VIndex(v.idx());
    r.patch.push_back(label[fi]);
    ++f;
  }
  return r;
}

}  // namespace simsr
