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
///
/// A column may be collapsed (the shell pinched to the outer surface there, e.g. at a crease no
/// offset direction fits): its vertex is one vertex in every wrap, and the tets that would join
/// it to itself are left out. The rest of each prism (a pyramid or a single tet) still conforms.

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
  Index wrap_vertices = 0;  ///< #nv
  Index num_wraps = 0;
  IndexVector vertex_of;    ///< w·#nv + i → the mesh vertex of vertex i of wrap w (wrap 0's are 0..#nv−1; −1: an
                            ///< inner copy no tet uses, dropped)
  IndexVector column_of;    ///< mesh vertex → i, its column
  VIndex vertex(Index w, Index i) const { return vertex_of[w * wrap_vertices + i]; }
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

namespace detail {
/// Whether tet t (virtual indices w·nv + i) joins a collapsed column to itself.
inline bool collapsed_tet(const std::array<VIndex, 4>& t, Index nv, const std::vector<char>& collapsed) {
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b)
      if (t[std::size_t(a)] % nv == t[std::size_t(b)] % nv && !collapsed.empty() && collapsed[std::size_t(t[std::size_t(a)] % nv)]) return true;
  return false;
}
}  // namespace detail

/// Per triangle of F: 1 when some tet of its prism column is flat or inverted, six times its
/// volume at most `min_volume6` (m³; 0: only inverted or exactly flat ones), else 0. Tets that a
/// collapsed column (`collapsed`: per wrap vertex, or empty for none) leaves out are not checked.
template <exec::HostPolicy P, class S>
std::vector<char> folded_prisms(P policy, const Tris& F, const std::vector<Points<S>>& wraps, const std::vector<char>& collapsed = {},
                                S min_volume6 = S(0)) {
  detail::require_wraps(F, wraps);
  const Index nv = wraps[0].rows();
  std::vector<char> bad(static_cast<std::size_t>(F.rows()), 0);
  exec::parallel_for(policy, F.rows(), [&](Index f) {
    const std::array<VIndex, 3> tri{F(f, 0), F(f, 1), F(f, 2)};
    for (Index w = 0; w + 1 < Index(wraps.size()); ++w)
      for (const auto& t : detail::prism_tets(tri, 0, nv)) {
        if (detail::collapsed_tet(t, nv, collapsed)) continue;
        const auto p = [&](VIndex k) { return Vec3<S>(wraps[std::size_t(w + k / nv)].row(k % nv).transpose()); };
        if (!(detail::tet_volume6(p(t[0]), p(t[1]), p(t[2]), p(t[3])) > min_volume6)) bad[std::size_t(f)] = 1;
      }
  });
  return bad;
}

/// The shell's tet mesh (see the file comment). `collapsed`: per wrap vertex, 1 where the column
/// is pinched (empty: none). ArgumentError/ShapeError for fewer than 2 wraps, wraps of different
/// sizes or a collapsed list of another length, MeshError for a triangle index out of range or
/// naming the first folded prism (triangle and layer).
template <exec::HostPolicy P, class S>
PrismShell<S> prism_shell(P policy, const Tris& F, const std::vector<Points<S>>& wraps, const std::vector<char>& collapsed = {}) {
  detail::require_wraps(F, wraps);
  const Index nv = wraps[0].rows(), W = Index(wraps.size()), layers = W - 1;
  if (!collapsed.empty() && Index(collapsed.size()) != nv) throw ShapeError("prism_shell: collapsed columns", {nv}, {Index(collapsed.size())});
  PrismShell<S> r;
  r.wrap_vertices = nv;
  r.num_wraps = W;
  r.vertex_of.resize(W * nv);
  std::vector<VIndex> column;
  for (Index w = 0; w < W; ++w)
    for (Index i = 0; i < nv; ++i) {
      if (w > 0 && !collapsed.empty() && collapsed[std::size_t(i)]) {
        r.vertex_of[w * nv + i] = r.vertex_of[i];
        continue;
      }
      r.vertex_of[w * nv + i] = VIndex(column.size());
      column.push_back(VIndex(i));
    }
  r.column_of = Eigen::Map<const IndexVector>(column.data(), Index(column.size()));
  r.mesh.V.resize(Index(column.size()), 3);
  for (Index w = 0; w < W; ++w)
    for (Index i = 0; i < nv; ++i)
      if (w == 0 || collapsed.empty() || !collapsed[std::size_t(i)]) r.mesh.V.row(r.vertex_of[w * nv + i]) = wraps[std::size_t(w)].row(i);
  // tets, prism by prism (sequential: a prism gives 1 to 3 tets), then their volumes checked
  std::vector<std::array<VIndex, 4>> tets;
  std::vector<VIndex> layer, triangle;
  tets.reserve(std::size_t(3 * F.rows() * layers));
  for (Index w = 0; w < layers; ++w)
    for (Index f = 0; f < F.rows(); ++f)
      for (const auto& t : detail::prism_tets({F(f, 0), F(f, 1), F(f, 2)}, w, nv)) {
        if (detail::collapsed_tet(t, nv, collapsed)) continue;
        std::array<VIndex, 4> m{};
        for (int c = 0; c < 4; ++c) m[std::size_t(c)] = r.vertex_of[t[std::size_t(c)]];
        tets.push_back(m);
        layer.push_back(VIndex(w));
        triangle.push_back(VIndex(f));
      }
  exec::parallel_for(policy, Index(tets.size()), [&](Index k) {
    const auto p = [&](int c) { return Vec3<S>(r.mesh.V.row(tets[std::size_t(k)][std::size_t(c)]).transpose()); };
    if (!(detail::tet_volume6(p(0), p(1), p(2), p(3)) > S(0)))
      throw MeshError("triangle", triangle[std::size_t(k)],
                      "its prism between wraps " + std::to_string(layer[std::size_t(k)]) + " and " + std::to_string(layer[std::size_t(k)] + 1) +
                          " is folded (a tet of non-positive volume): the wraps cross there");
  });
  // inner copies that no tet uses (where pinched columns surround a vertex) are dropped: a vertex
  // without a tet would be a zero row of every solver's matrix. The outer wrap's stay (0..nv−1).
  std::vector<char> used(static_cast<std::size_t>(r.mesh.V.rows()), 0);
  for (const auto& t : tets)
    for (VIndex v : t) used[std::size_t(v)] = 1;
  std::vector<VIndex> renumber(used.size(), -1);
  VIndex next = 0;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v] || Index(v) < nv) renumber[v] = next++;
  if (next < r.mesh.V.rows()) {
    Points<S> V(next, 3);
    IndexVector column(next);
    for (std::size_t v = 0; v < used.size(); ++v)
      if (renumber[v] >= 0) {
        V.row(renumber[v]) = r.mesh.V.row(Index(v));
        column[renumber[v]] = r.column_of[Index(v)];
      }
    r.mesh.V.swap(V);
    r.column_of.swap(column);
    for (Index k = 0; k < r.vertex_of.size(); ++k) r.vertex_of[k] = renumber[std::size_t(r.vertex_of[k])];
    for (auto& t : tets)
      for (VIndex& v : t) v = renumber[std::size_t(v)];
  }
  r.mesh.T.resize(Index(tets.size()), 4);
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int c = 0; c < 4; ++c) r.mesh.T(Index(t), c) = tets[t][std::size_t(c)];
  r.tet_layer = Eigen::Map<const IndexVector>(layer.data(), Index(layer.size()));
  return r;
}

}  // namespace simsr
