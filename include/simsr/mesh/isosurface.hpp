#pragma once
/// \file
/// Marching tetrahedra: the level set {φ = iso} of a field φ given at the vertices of a tet mesh
/// and linear in each tet, as a triangle mesh. On a tet mesh there are no ambiguous cases (unlike
/// marching cubes) and every crossing point is computed from its edge alone, so neighbouring tets
/// share their points: the surface is closed wherever the region {φ > iso} stays inside the mesh,
/// and consistently oriented, normals pointing out of {φ > iso}.
///
///     TriMesh<> skull = simsr::marching_tets(exec::seq, lattice.mesh, phi, 0.0, {.snap = 0.1});
///
/// The face scenario extracts its inner skull surface this way (the offset of the head surface).
/// A vertex whose value lies within `snap`·(edge length) of iso would put crossing points almost
/// onto that vertex, and tiny triangles around it (bad input for a mesher): such values are moved
/// to iso − snap·(its shortest edge), onto the negative side, which moves the surface by at most
/// that much and keeps every crossing at least `snap` of its edge away from both ends (for a field
/// that changes by no more than the edge length along an edge, as a distance does).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "tet_mesh.hpp"
#include "topology.hpp"
#include "tri_mesh.hpp"

namespace simsr {

/// How marching_tets treats values close to iso.
struct IsosurfaceOptions {
  double snap = 0.1;  ///< in [0, 0.5): values within snap × (shortest incident edge) of iso move below it
};

namespace detail {

inline bool odd_permutation(std::array<int, 4> p) {
  int swaps = 0;
  for (int i = 0; i < 4; ++i)
    while (p[std::size_t(i)] != i) {
      std::swap(p[std::size_t(i)], p[std::size_t(p[std::size_t(i)])]);
      ++swaps;
    }
  return swaps % 2 == 1;
}

}  // namespace detail

/// The iso-level set of `values` (one per vertex of `mesh`, finite) on `mesh` (positively oriented
/// tets, as TetMesh keeps them). ShapeError for a wrong number of values, ArgumentError for a
/// non-finite value or snap outside [0, 0.5).
template <exec::HostPolicy P, class S>
TriMesh<S> marching_tets(P policy, const TetMesh<S>& mesh, const VecX<S>& values, S iso, const IsosurfaceOptions& opt = {}) {
  const Index nv = mesh.V.rows(), nt = mesh.T.rows();
  if (values.size() != nv) throw ShapeError("marching_tets: values (one per mesh vertex)", {nv}, {values.size()});
  if (!values.allFinite() || !std::isfinite(double(iso))) throw ArgumentError("marching_tets: non-finite value or iso level");
  if (!(opt.snap >= 0 && opt.snap < 0.5)) throw ArgumentError("marching_tets: snap must be in [0, 0.5), got " + std::to_string(opt.snap));

  // shortest incident edge per vertex, for the snap
  VecX<S> phi = values;
  if (opt.snap > 0) {
    VecX<S> shortest = VecX<S>::Constant(nv, std::numeric_limits<S>::infinity());
    const Edges E = unique_edges(mesh.T);
    for (Index e = 0; e < E.rows(); ++e) {
      const S len = (mesh.V.row(E(e, 0)) - mesh.V.row(E(e, 1))).norm();
      shortest[E(e, 0)] = std::min(shortest[E(e, 0)], len);
      shortest[E(e, 1)] = std::min(shortest[E(e, 1)], len);
    }
    exec::parallel_for(policy, nv, [&](Index v) {
      if (std::isfinite(double(shortest[v])) && std::abs(phi[v] - iso) < S(opt.snap) * shortest[v]) phi[v] = iso - S(opt.snap) * shortest[v];
    });
  }
  auto positive = [&](VIndex v) { return phi[v] > iso; };

  // crossing edges, each once, in (min, max) order
  std::vector<std::pair<VIndex, VIndex>> crossing;
  for (Index t = 0; t < nt; ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        const VIndex u = mesh.T(t, a), w = mesh.T(t, b);
        if (positive(u) != positive(w)) crossing.emplace_back(std::min(u, w), std::max(u, w));
      }
  std::sort(crossing.begin(), crossing.end());
  crossing.erase(std::unique(crossing.begin(), crossing.end()), crossing.end());
  TriMesh<S> out;
  out.V.resize(Index(crossing.size()), 3);
  exec::parallel_for(policy, Index(crossing.size()), [&](Index i) {
    const auto [u, w] = crossing[std::size_t(i)];  // u < w: the same point from every tet
    const S s = (iso - phi[u]) / (phi[w] - phi[u]);
    out.V.row(i) = mesh.V.row(u) + s * (mesh.V.row(w) - mesh.V.row(u));
  });
  auto point_of = [&](VIndex u, VIndex w) {
    const std::pair<VIndex, VIndex> key{std::min(u, w), std::max(u, w)};
    return VIndex(std::lower_bound(crossing.begin(), crossing.end(), key) - crossing.begin());
  };

  static constexpr std::array<std::array<int, 3>, 4> outward_face{{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};
  std::vector<VIndex> tris;
  for (Index t = 0; t < nt; ++t) {
    std::array<int, 4> pos{}, neg{};
    int np = 0, nn = 0;
    for (int c = 0; c < 4; ++c) (positive(mesh.T(t, c)) ? pos[std::size_t(np++)] : neg[std::size_t(nn++)]) = c;
    if (np == 0 || np == 4) continue;
    auto vid = [&](int c) { return mesh.T(t, c); };
    if (np == 1 || np == 3) {
      // the lone vertex q and the face opposite it, oriented away from q
      const int q = np == 1 ? pos[0] : neg[0];
      const auto& f = outward_face[std::size_t(q)];
      std::array<VIndex, 3> tri{point_of(vid(q), vid(f[0])), point_of(vid(q), vid(f[1])), point_of(vid(q), vid(f[2]))};
      if (np == 3) std::swap(tri[1], tri[2]);  // lone negative vertex: the normal must point at it
      tris.insert(tris.end(), tri.begin(), tri.end());
    } else {
      // two and two: (A, B positive, C, D negative) ordered as an even permutation of the tet
      int A = pos[0], B = pos[1], C = neg[0], D = neg[1];
      if (detail::odd_permutation({A, B, C, D})) std::swap(C, D);
      const VIndex ac = point_of(vid(A), vid(C)), ad = point_of(vid(A), vid(D)), bd = point_of(vid(B), vid(D)), bc = point_of(vid(B), vid(C));
      // quad ac → ad → bd → bc; split along its shorter diagonal
      if ((out.V.row(ac) - out.V.row(bd)).squaredNorm() <= (out.V.row(ad) - out.V.row(bc)).squaredNorm())
        tris.insert(tris.end(), {ac, ad, bd, ac, bd, bc});
      else
        tris.insert(tris.end(), {ac, ad, bc, ad, bd, bc});
    }
  }
  out.F = Eigen::Map<const Tris>(tris.data(), Index(tris.size() / 3), 3);
  return out;
}

}  // namespace simsr
