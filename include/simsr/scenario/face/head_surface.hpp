#pragma once
/// \file
/// The closed outer boundary of the face's flesh (core paper §4, "closed where the scan is open").
/// The kit's skin is open at the mouth, the eyes and the neck; its mouth socket joins the skin
/// along the lips' inner edge and each eye socket along an eyelid rim, so skin + sockets is one
/// surface whose only hole is the neck. A fan about the neck loop's centroid closes it.
///
///     auto head = simsr::scenario::head_surface(exec::seq, kit, rest_positions);
///     head.mesh;          // closed, outward oriented, edge-manifold
///     head.part[f];       // HeadPart of triangle f: skin, mouth socket, eye socket, neck cap
///     head.kit_vertex[v]; // the kit vertex of mesh vertex v (−1: the cap's centre)

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../mesh/topology.hpp"
#include "../../mesh/triangulate.hpp"
#include "../../mesh/volume.hpp"
#include "ict_kit.hpp"

namespace simsr::scenario {

/// Which part of the head a boundary triangle belongs to.
enum class HeadPart : int { skin = 0, mouth_socket = 1, eye_socket = 2, neck_cap = 3 };

/// The closed head surface and where each piece came from.
struct HeadSurface {
  TriMesh<> mesh;                   ///< closed, outward oriented, every edge in exactly two triangles
  std::vector<VIndex> kit_vertex;   ///< mesh vertex → kit vertex (−1 for the neck cap's centre)
  std::vector<HeadPart> part;       ///< per triangle
  std::vector<VIndex> neck_loop;    ///< the neck's boundary loop (mesh vertices), as closed by the cap
};

/// Skin (face, head_and_neck), mouth socket and eye sockets of `kit` at `positions` (the kit's
/// V×3 vertex positions: the neutral, or a pre-deformed rest pose), triangulated, compacted to
/// the vertices they use, oriented outward, and closed at the neck. ArgumentError when the parts
/// leave other than one hole, when the neck loop is not star-shaped about its centroid (the fan
/// would fold), or when the result is not a closed edge-manifold surface; ShapeError for
/// positions of the wrong size.
template <exec::HostPolicy P>
HeadSurface head_surface(P policy, const IctKit& kit, const Points<>& positions) {
  if (positions.rows() != kit.num_vertices())
    throw ShapeError("head_surface: positions (the kit's vertices)", {kit.num_vertices(), 3}, {positions.rows(), 3});
  if (!positions.allFinite()) throw ArgumentError("head_surface: non-finite vertex positions");
  const std::vector<std::pair<std::string, HeadPart>> parts{{"face", HeadPart::skin},
                                                            {"head_and_neck", HeadPart::skin},
                                                            {"mouth_socket", HeadPart::mouth_socket},
                                                            {"eye_socket_left", HeadPart::eye_socket},
                                                            {"eye_socket_right", HeadPart::eye_socket}};
  std::vector<std::string> names;
  for (const auto& p : parts) names.push_back(p.first);
  PolyMesh<> poly = kit.faces_within(names);
  poly.V = positions;
  std::vector<Index> face_of;
  const TriMesh<> all = triangulate(poly, &face_of);

  // compact to the used vertices
  std::vector<VIndex> new_index(std::size_t(kit.num_vertices()), -1);
  HeadSurface h;
  for (Index f = 0; f < all.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const VIndex v = all.F(f, c);
      if (new_index[std::size_t(v)] < 0) {
        new_index[std::size_t(v)] = VIndex(h.kit_vertex.size());
        h.kit_vertex.push_back(v);
      }
    }
  const Index n_used = Index(h.kit_vertex.size());
  Tris F(all.F.rows(), 3);
  for (Index f = 0; f < all.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) F(f, c) = new_index[std::size_t(all.F(f, c))];
  auto part_of_vertex = [&](VIndex kv) {
    for (const auto& [name, part] : parts)
      if (kit.region(name).contains(kv)) return part;
    return HeadPart::skin;
  };
  // a triangle belongs to the part of its first corner that is not skin (the seams are skin–socket)
  h.part.resize(std::size_t(F.rows()), HeadPart::skin);
  for (Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const HeadPart p = part_of_vertex(h.kit_vertex[std::size_t(F(f, c))]);
      if (p != HeadPart::skin) h.part[std::size_t(f)] = p;
    }

  const auto loops = boundary_loops(F);
  if (loops.size() != 1)
    throw ArgumentError("head_surface: skin and sockets should leave one hole (the neck), found " + std::to_string(loops.size()) +
                        " boundary loops");
  h.neck_loop = loops[0];

  // the fan about the loop's centroid, checked in the loop's best-fit plane
  Points<> V(n_used + 1, 3);
  for (Index v = 0; v < n_used; ++v) V.row(v) = positions.row(h.kit_vertex[std::size_t(v)]);
  const Index m = Index(h.neck_loop.size());
  Points<> L(m, 3);
  for (Index i = 0; i < m; ++i) L.row(i) = V.row(h.neck_loop[std::size_t(i)]);
  const Eigen::RowVector3d centre = L.colwise().mean();
  V.row(n_used) = centre;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(L.rowwise() - centre, Eigen::ComputeThinV);
  const Vec3<> normal = svd.matrixV().col(2);
  double turning = 0;
  for (Index i = 0; i < m; ++i) {
    const Vec3<> a = (L.row(i) - centre).transpose(), b = (L.row((i + 1) % m) - centre).transpose();
    turning += std::atan2(a.cross(b).dot(normal), a.dot(b));
  }
  const double dir = turning > 0 ? 1 : -1;
  for (Index i = 0; i < m; ++i) {
    const Vec3<> a = (L.row(i) - centre).transpose(), b = (L.row((i + 1) % m) - centre).transpose();
    if (!(dir * a.cross(b).dot(normal) > 0))
      throw ArgumentError("head_surface: the neck loop is not star-shaped about its centroid (at loop vertex " + std::to_string(i) +
                          "): a fan would fold");
  }
  // boundary edges run a→b in their triangle; the cap uses b→a
  Tris cap(m, 3);
  for (Index i = 0; i < m; ++i)
    cap.row(i) << h.neck_loop[std::size_t((i + 1) % m)], h.neck_loop[std::size_t(i)], VIndex(n_used);
  h.mesh.V = V;
  h.mesh.F.resize(F.rows() + m, 3);
  h.mesh.F << F, cap;
  h.kit_vertex.push_back(-1);
  h.part.insert(h.part.end(), std::size_t(m), HeadPart::neck_cap);

  if (boundary_edges(h.mesh.F).rows() != 0) throw ArgumentError("head_surface: the capped surface still has a boundary");
  // edge-manifold: every undirected edge in exactly two triangles, once each way
  {
    std::vector<std::pair<std::pair<VIndex, VIndex>, int>> half;
    half.reserve(std::size_t(3 * h.mesh.F.rows()));
    for (Index f = 0; f < h.mesh.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) {
        const VIndex a = h.mesh.F(f, c), b = h.mesh.F(f, (c + 1) % 3);
        half.push_back({{std::min(a, b), std::max(a, b)}, a < b ? 1 : -1});
      }
    std::sort(half.begin(), half.end());
    for (std::size_t i = 0; i < half.size();) {
      std::size_t j = i;
      int sum = 0;
      while (j < half.size() && half[j].first == half[i].first) sum += half[j++].second;
      if (j - i != 2 || sum != 0)
        throw ArgumentError("head_surface: edge (" + std::to_string(half[i].first.first) + ", " + std::to_string(half[i].first.second) +
                            ") is in " + std::to_string(j - i) + " triangles" + (j - i == 2 ? " oriented alike" : "") +
                            ": not a closed, consistently oriented surface");
      i = j;
    }
  }
  // outward: the enclosed volume (tets from the centroid) is positive
  Tets T(h.mesh.F.rows(), 4);
  Points<> W(h.mesh.V.rows() + 1, 3);
  W << h.mesh.V, h.mesh.V.colwise().mean();
  for (Index f = 0; f < h.mesh.F.rows(); ++f) T.row(f) << VIndex(W.rows() - 1), h.mesh.F(f, 0), h.mesh.F(f, 1), h.mesh.F(f, 2);
  if (total_volume(policy, W, T) < 0) {
    for (Index f = 0; f < h.mesh.F.rows(); ++f) std::swap(h.mesh.F(f, 1), h.mesh.F(f, 2));
    std::reverse(h.neck_loop.begin(), h.neck_loop.end());
  }
  return h;
}

}  // namespace simsr::scenario
