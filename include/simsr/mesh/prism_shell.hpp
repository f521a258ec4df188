#pragma once
/// \file
/// The tet mesh of a shell between nested surfaces of one topology ("wraps"), prism by prism:
/// triangle f of wrap w and the same triangle of wrap w + 1 bound a prism, cut into 3 tets whose
/// quad-side diagonals depend on the side alone (mesh/generators.hpp's split_prism rule), so
/// neighbouring prisms conform and the whole shell is one conforming tet mesh. SoftDECA's layered
/// template is built this way (supplement §3: "the triangle prisms between the wraps"; refining
/// means more wraps or finer wraps).
///
///     auto shell = simsr::prism_shell(exec::omp, skin.F, {skin.V, muscle_wrap, bone_wrap});
///     shell.mesh;                 // vertex w·#nv + i = vertex i of wrap w
///     shell.tet_layer[t];         // w: the tet lies between wraps w and w + 1
///
/// Wrap 0 is the outer one: triangles counter-clockwise seen from outside, later wraps further
/// in. A prism whose wraps cross (an offset folded over itself) has tets of the wrong
/// orientation: prism_shell throws a MeshError naming it, folded_prisms lists all of them (so a
/// caller can thin the shell there and try again).

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "detail/elements.hpp"
#include "tet_mesh.hpp"

namespace simsr {

/// A prism shell and the layer of each tet.
template <class S = Scalar>
struct PrismShell {
  TetMesh<S> mesh;
  IndexVector tet_layer;    ///< per tet: the wrap index w of its outer side
  Index wrap_vertices = 0;  ///< #nv: vertex w·#nv + i is vertex i of wrap w
};

namespace detail {

/// The 3 tets of the prism over triangle (a, b, c) between wraps w and w + 1, as vertex indices
/// into the shell (split_prism's rule: corners sorted by index), each oriented positively for an
/// unfolded prism whose inner wrap lies on the inner side (−normal) of the outer triangle.
inline std::array<std::array<VIndex, 4>, 3> prism_tets(const std::array<VIndex, 3>& tri, Index w, Index nv) {
  std::array<VIndex, 3> s = tri;
  std::sort(s.begin(), s.end());
  const VIndex o = VIndex(w * nv), i = VIndex((w + 1) * nv);
  std::array<std::array<VIndex, 4>, 3> t{{{o + s[0], o + s[1], o + s[2], i + s[0]},
                                          {o + s[1], o + s[2], i + s[0], i + s[1]},
                                          {o + s[2], i + s[0], i + s[1], i + s[2]}}};
  // sorted order an even permutation of (a, b, c): (s1 − s0)×(s2 − s0) is the outward normal and
  // the inner corners lie below it, so each tet as listed has negative volume; flip it.
  const bool even = (s[0] == tri[0] && s[1] == tri[1]) || (s[0] == tri[1] && s[1] == tri[2]) || (s[0] == tri[2] && s[1] == tri[0]);
  if (even)
    for (auto& q : t) std::swap(q[2], q[3]);
  return t;
}

template <class S>
void require_wraps(const Tris& F, const std::vector<Points<S>>& wraps) {
  if (wraps.size() < 2) throw ArgumentError("prism_shell: needs at least 2 wraps, got " + std::to_string(wraps.size()));
  const Index nv = wraps[0].rows();
  for (std::size_t w = 0; w < wraps.size(); ++w)
    if (wraps[w].rows() != nv || wraps[w].cols() != 3)
      throw ShapeError("prism_shell: wrap " + std::to_string(w), {nv, 3}, {wraps[w].rows(), wraps[w].cols()});
  for (Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (F(f, c) < 0 || F(f, c) >= nv)
        throw MeshError("triangle", f, "vertex index " + std::to_string(F(f, c)) + " outside [0, " + std::to_string(nv) + ")");
}

}  // namespace detail

/// Per triangle of F: 1 when some tet of its prism column is flat or inverted, six times its
/// volume at most `min_volume6` (m³; 0: only inverted or exactly flat ones), else 0.
template <exec::HostPolicy P, class S>
std::vector<char> folded_prisms(P policy, const Tris& F, const std::vector<Points<S>>& wraps, S min_volume6 = S(0)) {
  detail::require_wraps(F, wraps);
  const Index nv = wraps[0].rows();
  std::vector<char> bad(std::size_t(F.rows()), 0);
  exec::parallel_for(policy, F.rows(), [&](Index f) {
    const std::array<VIndex, 3> tri{F(f, 0), F(f, 1), F(f, 2)};
    for (Index w = 0; w + 1 < Index(wraps.size()); ++w)
      for (const auto& t : detail::prism_tets(tri, 0, nv)) {
        const auto p = [&](VIndex k) { return Vec3<S>(wraps[std::size_t(w + k / nv)].row(k % nv).transpose()); };
        if (!(detail::tet_volume6(p(t[0]), p(t[1]), p(t[2]), p(t[3])) > min_volume6)) bad[std::size_t(f)] = 1;
      }
  });
  return bad;
}

/// The shell's tet mesh (see the file comment). ArgumentError/ShapeError for fewer than 2 wraps
/// or wraps of different sizes, MeshError for a triangle index out of range or naming the first
/// folded prism (triangle and layer).
template <exec::HostPolicy P, class S>
PrismShell<S> prism_shell(P policy, const Tris& F, const std::vector<Points<S>>& wraps) {
  detail::require_wraps(F, wraps);
  const Index nv = wraps[0].rows(), layers = Index(wraps.size()) - 1;
  PrismShell<S> r;
  r.wrap_vertices = nv;
  r.mesh.V.resize(nv * Index(wraps.size()), 3);
  for (std::size_t w = 0; w < wraps.size(); ++w) r.mesh.V.middleRows(Index(w) * nv, nv) = wraps[w];
  r.mesh.T.resize(3 * F.rows() * layers, 4);
  r.tet_layer.resize(3 * F.rows() * layers);
  exec::parallel_for(policy, F.rows(), [&](Index f) {
    for (Index w = 0; w < layers; ++w) {
      const auto tets = detail::prism_tets({F(f, 0), F(f, 1), F(f, 2)}, w, nv);
      for (int k = 0; k < 3; ++k) {
        const Index row = 3 * (w * F.rows() + f) + k;
        for (int c = 0; c < 4; ++c) r.mesh.T(row, c) = tets[std::size_t(k)][std::size_t(c)];
        r.tet_layer[row] = VIndex(w);
      }
    }
  });
  for (Index t = 0; t < r.mesh.T.rows(); ++t) {
    const auto p = [&](int c) { return Vec3<S>(r.mesh.V.row(r.mesh.T(t, c)).transpose()); };
    if (!(detail::tet_volume6(p(0), p(1), p(2), p(3)) > S(0)))
      throw MeshError("triangle", (t / 3) % F.rows(),
                      "its prism between wraps " + std::to_string(r.tet_layer[t]) + " and " + std::to_string(r.tet_layer[t] + 1) +
                          " is folded (a tet of non-positive volume): the wraps cross there");
  }
  return r;
}

}  // namespace simsr
