#pragma once
/// \file
/// The inner skull surface under the face's flesh (core paper §4; issue: "an inward offset,
/// regionally varying thickness, smoothed, free of self-intersection").
///
/// The flesh is the part of the head within a thickness t(x) of its closed surface C (skin +
/// mouth and eye sockets + neck cap, head_surface.hpp); the skull is the rest of the inside:
///
///     skull = { x inside C : dist(x, C) > t(x) }.
///
/// This is an offset surface, but defined by distance rather than by moving vertices along
/// normals, so it cannot fold or self-intersect: where two offset fronts meet (behind the lips,
/// in the nose, the eyelids: anything thinner than 2t) there is simply no skull, and those parts
/// are flesh through and through, as they are in a face. The surface is extracted by marching
/// tetrahedra over a BCC lattice (mesh/isosurface.hpp); small islands (thin bony bits the
/// thickness happens to leave, below `min_component_volume`) are dropped, so they become flesh.
///
/// t(x) is smooth: a base thickness (scalp, forehead, temples) plus Gaussian bumps at landmarks
/// the kit gives (the cheeks below each eyeball, the mouth, the chin, the neck), after the
/// soft-tissue depths of craniofacial anatomy (forehead ≈ 5–6 mm, mid-cheek ≈ 15–20 mm, chin ≈
/// 10–12 mm, upper lip ≈ 12 mm; the lips are thinner than 2t and come out all flesh).

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../discretize/bcc_lattice.hpp"
#include "../../mesh/isosurface.hpp"
#include "../../mesh/topology.hpp"
#include "../../neighbors/surface_distance.hpp"
#include "head_surface.hpp"
#include "ict_kit.hpp"

namespace simsr::scenario {

/// One Gaussian bump of extra flesh: amplitude (cm) at `centre`, width `sigma` (cm).
struct ThicknessBump {
  Vec3<> centre = Vec3<>::Zero();
  double amplitude = 0;
  double sigma = 1;
};

/// t(x) = min(max_thickness, base + Σ bumps). All in cm.
struct FleshThickness {
  double base = 0.6;
  double max_thickness = 3.0;
  std::vector<ThicknessBump> bumps;

  double operator()(const Vec3<>& x) const {
    double t = base;
    for (const auto& b : bumps) t += b.amplitude * std::exp(-(x - b.centre).squaredNorm() / (2 * b.sigma * b.sigma));
    return std::min(t, max_thickness);
  }
};

/// The default thickness for the ICT head at `positions` (the kit's vertices): base 0.6 cm; +1.2
/// cm (σ 2 cm) at each cheek, 3 cm below and 0.5 cm behind its eyeball's centre; +0.6 cm (σ 2)
/// 1 cm behind the mouth (the mouth socket's front); +0.5 cm (σ 1.5) 1 cm behind the chin; +1.5
/// cm (σ 4) at the neck loop's centre.
inline FleshThickness default_flesh_thickness(const IctKit& kit, const Points<>& positions, const HeadSurface& head) {
  auto centroid = [&](const VertexRange& r) { return Vec3<>(positions.middleRows(r.first, r.size()).colwise().mean().transpose()); };
  FleshThickness t;
  for (const char* eye : {"eyeball_left", "eyeball_right"})
    t.bumps.push_back({centroid(kit.region(eye)) + Vec3<>(0, -3.0, -0.5), 1.2, 2.0});
  // the mouth: the front of the mouth socket (its most forward tenth)
  const VertexRange ms = kit.region("mouth_socket");
  double zmax = -1e300;
  for (Index v = ms.first; v <= ms.last; ++v) zmax = std::max(zmax, positions(v, 2));
  Vec3<> mouth = Vec3<>::Zero();
  Index n = 0;
  for (Index v = ms.first; v <= ms.last; ++v)
    if (positions(v, 2) > zmax - 1.0) mouth += positions.row(v).transpose(), ++n;
  mouth /= double(std::max<Index>(n, 1));
  t.bumps.push_back({mouth + Vec3<>(0, 0, -1.0), 0.6, 2.0});
  // the chin: the lowest skin vertex of the face region near the midline, in front
  const VertexRange face = kit.region("face");
  Index chin = -1;
  for (Index v = face.first; v <= face.last; ++v)
    if (std::abs(positions(v, 0)) < 1.0 && positions(v, 2) > mouth.z() - 3.0 && positions(v, 1) < mouth.y() &&
        (chin < 0 || positions(v, 1) < positions(chin, 1)))
      chin = v;
  if (chin >= 0) t.bumps.push_back({positions.row(chin).transpose() + Vec3<>(0, 0.5, -1.0), 0.5, 1.5});
  Vec3<> neck = Vec3<>::Zero();
  for (auto v : head.neck_loop) neck += head.mesh.V.row(v).transpose();
  neck /= double(head.neck_loop.size());
  t.bumps.push_back({neck, 1.5, 4.0});
  return t;
}

/// How the skull is extracted.
struct SkullOptions {
  double lattice_h = 0.25;             ///< cm: spacing of the BCC lattice the level set is taken on
  double snap = 0.1;                   ///< marching_tets' snap (IsosurfaceOptions)
  double min_component_volume = 1.0;   ///< cm³: smaller skull islands become flesh
};

/// The skull surface and what it is made of.
struct Skull {
  TriMesh<> surface;                    ///< closed, outward (normals point into the flesh)
  std::vector<Index> component_of_triangle;
  std::vector<double> component_volume; ///< cm³, per kept component
  std::vector<Vec3<>> inside_point;     ///< a point inside each kept component (tetgen's holes)
  Index dropped_components = 0;
  double min_flesh = 0;                 ///< smallest distance from a skull vertex to the head surface (cm)
};

/// The skull under `head` for thickness `t` (see the file comment). ArgumentError when no skull
/// is left (the thickness exceeds the head) or the level set comes out open (it touches the
/// lattice's edge, which a head surface inside the lattice cannot cause).
template <exec::HostPolicy P>
Skull skull_surface(P policy, const HeadSurface& head, const FleshThickness& t, const SkullOptions& opt = {}) {
  const auto lattice = discretize::bcc_lattice(head.mesh, opt.lattice_h);
  const auto inside = discretize::lattice_nodes_inside(lattice, head.mesh);
  const neighbors::SurfaceDistance<> dist(head.mesh);
  const VecX<> d = dist.distances(policy, lattice.mesh.V);
  VecX<> phi(lattice.mesh.V.rows());
  exec::parallel_for(policy, phi.size(), [&](Index v) {
    const double tv = t(lattice.mesh.V.row(v).transpose());
    phi[v] = inside[std::size_t(v)] ? d[v] - tv : -d[v] - tv;
  });
  TriMesh<> raw = marching_tets(policy, lattice.mesh, phi, 0.0, {.snap = opt.snap});
  if (raw.F.rows() == 0) throw ArgumentError("skull_surface: the flesh thickness leaves no skull inside the head");
  if (boundary_edges(raw.F).rows() != 0) throw ArgumentError("skull_surface: the skull level set is open (it reaches the lattice's edge)");

  // components, their enclosed volumes; keep the big ones
  const Components comp = connected_components(raw.F, raw.V.rows());
  std::vector<double> vol(std::size_t(comp.count), 0.0);
  for (Index f = 0; f < raw.F.rows(); ++f)
    vol[std::size_t(comp.labels[raw.F(f, 0)])] +=
        raw.V.row(raw.F(f, 0)).dot(raw.V.row(raw.F(f, 1)).cross(raw.V.row(raw.F(f, 2)))) / 6.0;
  // marching_tets' normals point out of {φ > 0}, the skull: the enclosed volume is positive
  std::vector<Index> new_comp(std::size_t(comp.count), -1);
  Skull s;
  for (Index c = 0; c < comp.count; ++c)
    if (vol[std::size_t(c)] >= opt.min_component_volume) {
      new_comp[std::size_t(c)] = Index(s.component_volume.size());
      s.component_volume.push_back(vol[std::size_t(c)]);
    } else {
      ++s.dropped_components;
    }
  if (s.component_volume.empty()) throw ArgumentError("skull_surface: every skull component is below min_component_volume");
  std::vector<VIndex> vmap(std::size_t(raw.V.rows()), -1);
  std::vector<VIndex> tris;
  VIndex kept = 0;
  for (Index f = 0; f < raw.F.rows(); ++f) {
    const Index c = new_comp[std::size_t(comp.labels[raw.F(f, 0)])];
    if (c < 0) continue;
    for (int k = 0; k < 3; ++k) {
      VIndex& m = vmap[std::size_t(raw.F(f, k))];
      if (m < 0) m = kept++;
      tris.push_back(m);
    }
    s.component_of_triangle.push_back(c);
  }
  s.surface.V.resize(kept, 3);
  for (Index v = 0; v < raw.V.rows(); ++v)
    if (vmap[std::size_t(v)] >= 0) s.surface.V.row(vmap[std::size_t(v)]) = raw.V.row(v);
  s.surface.F = Eigen::Map<const Tris>(tris.data(), Index(tris.size() / 3), 3);

  // a point inside each component: behind its largest triangle, by a quarter of that triangle's
  // shortest edge (normals point out of the skull)
  s.inside_point.assign(s.component_volume.size(), Vec3<>::Zero());
  std::vector<double> best_area(s.component_volume.size(), -1);
  for (Index f = 0; f < s.surface.F.rows(); ++f) {
    const Vec3<> a = s.surface.V.row(s.surface.F(f, 0)).transpose(), b = s.surface.V.row(s.surface.F(f, 1)).transpose(),
                 c = s.surface.V.row(s.surface.F(f, 2)).transpose();
    const Vec3<> n = (b - a).cross(c - a);
    const double area = 0.5 * n.norm();
    const std::size_t k = std::size_t(s.component_of_triangle[std::size_t(f)]);
    if (area > best_area[k]) {
      best_area[k] = area;
      const double edge = std::min({(b - a).norm(), (c - b).norm(), (a - c).norm()});
      s.inside_point[k] = (a + b + c) / 3.0 - 0.25 * edge * n.normalized();
    }
  }
  const VecX<> flesh = dist.distances(policy, s.surface.V);
  s.min_flesh = flesh.minCoeff();
  return s;
}

}  // namespace simsr::scenario
