#pragma once
/// \file
/// Polygon triangulation: every polygon of n corners becomes n−2 triangles with the polygon's
/// orientation. Convex polygons are fanned from their first corner (what OBJ loaders do, so
/// triangle lists match other tools); non-convex ones are ear-clipped in the plane of their
/// Newell normal.

#include <cmath>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "poly_mesh.hpp"
#include "tri_mesh.hpp"

namespace simsr {

namespace detail {

/// 2-D cross product of (b−a) and (c−a).
template <class S>
S cross2(const Eigen::Matrix<S, 2, 1>& a, const Eigen::Matrix<S, 2, 1>& b, const Eigen::Matrix<S, 2, 1>& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

/// Triangulates one polygon (corner vertex indices) into `out` (appending rows as triples).
template <class S>
void triangulate_polygon(const Points<S>& V, const VIndex* corners, Index n, Index face, std::vector<VIndex>& out) {
  if (n < 3) throw MeshError("polygon", face, "has " + std::to_string(n) + " corners; a face needs at least 3");
  if (n == 3) {
    out.insert(out.end(), corners, corners + 3);
    return;
  }
  // Newell normal: robust plane of a possibly non-planar polygon.
  Vec3<S> normal = Vec3<S>::Zero();
  for (Index i = 0; i < n; ++i) {
    const Vec3<S> p = V.row(corners[i]).transpose(), q = V.row(corners[(i + 1) % n]).transpose();
    normal += Vec3<S>((p.y() - q.y()) * (p.z() + q.z()), (p.z() - q.z()) * (p.x() + q.x()), (p.x() - q.x()) * (p.y() + q.y()));
  }
  // Project onto the plane dropping the dominant normal axis, keeping orientation counter-clockwise.
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const S sign = normal[axis] >= 0 ? S(1) : S(-1);
  std::vector<Eigen::Matrix<S, 2, 1>> P(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) P[i] = {V(corners[i], u), sign * V(corners[i], v)};
  // When projecting with u,v in cyclic order after `axis`, a polygon whose normal points along
  // +axis is counter-clockwise; `sign` mirrors v otherwise.
  bool convex = true;
  for (Index i = 0; i < n && convex; ++i)
    convex = cross2(P[i], P[(i + 1) % n], P[(i + 2) % n]) >= S(0);
  if (convex || normal.squaredNorm() == S(0)) {
    for (Index i = 1; i + 1 < n; ++i) out.insert(out.end(), {corners[0], corners[i], corners[i + 1]});
    return;
  }
  // Ear clipping, O(n^2) per polygon: fine for the small polygons of scanned meshes.
  std::vector<Index> ring(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) ring[i] = i;
  while (ring.size() > 3) {
    const Index m = static_cast<Index>(ring.size());
    bool clipped = false;
    for (Index k = 0; k < m && !clipped; ++k) {
      const Index a = ring[(k + m - 1) % m], b = ring[k], c = ring[(k + 1) % m];
      if (cross2(P[a], P[b], P[c]) <= S(0)) continue;  // reflex or flat corner
      bool empty = true;
      for (Index j = 0; j < m && empty; ++j) {
        const Index q = ring[j];
        if (q == a || q == b || q == c) continue;
        empty = !(cross2(P[a], P[b], P[q]) >= 0 && cross2(P[b], P[c], P[q]) >= 0 && cross2(P[c], P[a], P[q]) >= 0);
      }
      if (!empty) continue;
      out.insert(out.end(), {corners[a], corners[b], corners[c]});
      ring.erase(ring.begin() + k);
      clipped = true;
    }
    if (!clipped) {  // self-intersecting polygon: no ear exists; fall back to a fan of the rest.
      for (std::size_t i = 1; i + 1 < ring.size(); ++i) out.insert(out.end(), {corners[ring[0]], corners[ring[i]], corners[ring[i + 1]]});
      return;
    }
  }
  out.insert(out.end(), {corners[ring[0]], corners[ring[1]], corners[ring[2]]});
}

}  // namespace detail

/// Triangulates every polygon; also returns, in `face_of_triangle` if given, the polygon each
/// triangle came from. Throws MeshError for a polygon with < 3 corners or an out-of-range corner.
template <class S>
TriMesh<S> triangulate(const PolyMesh<S>& poly, std::vector<Index>* face_of_triangle = nullptr) {
  std::vector<VIndex> tri;
  tri.reserve(poly.indices.size() * 2);
  if (face_of_triangle) face_of_triangle->clear();
  for (Index f = 0; f < poly.num_faces(); ++f) {
    const Index n = poly.face_size(f);
    const VIndex* c = poly.indices.data() + poly.offsets[f];
    for (Index i = 0; i < n; ++i)
      if (c[i] < 0 || c[i] >= poly.num_vertices())
        throw MeshError("polygon", f, "corner index " + std::to_string(c[i]) + " outside [0, " + std::to_string(poly.num_vertices()) + ")");
    const std::size_t before = tri.size();
    detail::triangulate_polygon(poly.V, c, n, f, tri);
    if (face_of_triangle) face_of_triangle->insert(face_of_triangle->end(), (tri.size() - before) / 3, f);
  }
  TriMesh<S> out;
  out.V = poly.V;
  out.F = Eigen::Map<const Tris>(tri.data(), static_cast<Index>(tri.size() / 3), 3);
  return out;
}

}  // namespace simsr
