#pragma once
/// \file
/// Virtual-node splitting of an embedded lattice (Molino, Bao & Fedkiw 2004, "A virtual node
/// algorithm for changing mesh topology during simulation"; the embedded face of Sifakis et al.
/// 2005): a lattice tet that carries two disconnected pieces of material — the upper and the
/// lower lip in one cell, an eyelid and the cheek below it — is copied once per piece, and the
/// copies' nodes are shared only where the material they carry is connected. Without it, one
/// coarse element glues the two lips together; with it, "no LR cell spans both lips" holds
/// wherever the high-resolution material is separate, even where the gap is far below h.
///
///     auto L = discretize::bcc_lattice(hr, h, {.region = face_only});
///     auto split = discretize::split_by_material(exec::omp, L, hr);     // split.mesh: the LR mesh
///     auto emb = discretize::embed_material_vertices(exec::omp, split, hr, skin_vertices);
///
/// Definitions, for the lattice L and the material: a conforming tet mesh M.
///  * M-tet e *overlaps* L-tet t when they share interior volume (mesh/tet_overlap.hpp).
///  * The *pieces* of t: the M-tets overlapping t, grouped by shared M-vertices among those
///    tets. Each piece becomes one split tet (a copy of t); L-tets with no material vanish.
///  * A split tet's 4 corners are node *instances*. Two instances of one lattice node are the same
///    split node when their split tets' pieces touch — both hold M-tets around one M-vertex (then
///    the material is connected right there) — and transitively so. In solid material the M-tets
///    around a node reach all the L-tets around it, so the node stays one; nodes are duplicated
///    only across gaps wider than zero (two bodies that share no M-vertex).
/// Output order is deterministic and independent of the policy: split tets by (lattice tet, piece
/// by its smallest M-tet), split nodes by (lattice node, smallest instance).

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/tet_overlap.hpp"
#include "../mesh/topology.hpp"
#include "bcc_lattice.hpp"
#include "embedding.hpp"

namespace simsr::discretize {

/// A lattice split by its material (see the file comment).
template <class S = Scalar>
struct MaterialSplit {
  TetMesh<S> mesh;             ///< the split lattice: the simulation mesh
  IndexVector node_parent;     ///< split node → lattice node
  IndexVector tet_parent;      ///< split tet → lattice tet
  /// (split tet, M-tet) incidences, CSR by split tet: the M-tets of split tet s (its piece) are
  /// piece_material[piece_offsets[s] .. piece_offsets[s+1]), ascending.
  std::vector<Index> piece_offsets{0};
  std::vector<VIndex> piece_material;
  /// The transpose: the split tets holding M-tet e are material_split_tets[material_offsets[e] ..
  /// material_offsets[e+1]), ascending.
  std::vector<Index> material_offsets{0};
  std::vector<VIndex> material_split_tets;
  Index lattice_tets_without_material = 0;  ///< dropped lattice tets
  Index split_lattice_tets = 0;             ///< lattice tets copied more than once
  Index duplicated_nodes = 0;               ///< split nodes beyond the lattice nodes they copy

  Index num_tets() const { return mesh.T.rows(); }
  Index num_nodes() const { return mesh.V.rows(); }
};

namespace detail {

struct UnionFind {
  std::vector<Index> parent;
  explicit UnionFind(Index n) : parent(std::size_t(n)) { std::iota(parent.begin(), parent.end(), Index(0)); }
  Index find(Index v) {
    while (parent[std::size_t(v)] != v) v = parent[std::size_t(v)] = parent[std::size_t(parent[std::size_t(v)])];
    return v;
  }
  void join(Index a, Index b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::size_t(std::max(a, b))] = std::min(a, b);  // root: the smallest member
  }
};

template <class S, class D>
TetCorners<S> corners_of(const Eigen::MatrixBase<D>& V, const Tets& T, Index t) {
  TetCorners<S> c;
  for (int k = 0; k < 4; ++k) c[std::size_t(k)] = V.row(T(t, k)).transpose().template cast<S>();
  return c;
}

}  // namespace detail

/// Splits `lattice` by the material `material` (see the file comment). `tolerance` (a length,
/// default 1e-9·h) is the overlap a pair must exceed along every axis to count. ArgumentError
/// when no lattice tet holds material.
template <exec::HostPolicy P, class S>
MaterialSplit<S> split_by_material(P policy, const Lattice<S>& lattice, const TetMesh<S>& material, double tolerance = -1) {
  const Grid& g = lattice.cells.grid;
  if (tolerance < 0) tolerance = 1e-9 * g.h;
  const Tets& LT = lattice.mesh.T;
  const Tets& MT = material.T;
  const Index nm = MT.rows(), nl = LT.rows();
  // kept cells by linear index, for the bounding-box lookups
  std::vector<Index> linear(lattice.cells.cells.size());
  for (std::size_t c = 0; c < linear.size(); ++c) linear[c] = g.linear(lattice.cells.cells[c][0], lattice.cells.cells[c][1], lattice.cells.cells[c][2]);

  // 1. the lattice tets overlapping each M-tet
  std::vector<std::vector<VIndex>> overlaps(static_cast<std::size_t>(nm));
  exec::parallel_for(policy, nm, [&](Index e) {
    const auto me = detail::corners_of<double>(material.V, MT, e);
    Vec3<double> lo = me[0], hi = me[0];
    for (int k = 1; k < 4; ++k) {
      lo = lo.cwiseMin(me[std::size_t(k)]);
      hi = hi.cwiseMax(me[std::size_t(k)]);
    }
    std::array<Index, 3> c0{}, c1{};
    for (int a = 0; a < 3; ++a) {
      c0[std::size_t(a)] = std::max<Index>(0, Index(std::floor((lo[a] - g.origin[a]) / g.h)) - 1);
      c1[std::size_t(a)] = std::min<Index>(g.dims[std::size_t(a)] - 1, Index(std::floor((hi[a] - g.origin[a]) / g.h)) + 1);
    }
    auto& out = overlaps[std::size_t(e)];
    for (Index k = c0[2]; k <= c1[2]; ++k)
      for (Index j = c0[1]; j <= c1[1]; ++j)
        for (Index i = c0[0]; i <= c1[0]; ++i) {
          const Index l = g.linear(i, j, k);
          const auto it = std::lower_bound(linear.begin(), linear.end(), l);
          if (it == linear.end() || *it != l) continue;
          const Index c = Index(it - linear.begin());
          for (Index q = lattice.cell_offsets[std::size_t(c)]; q < lattice.cell_offsets[std::size_t(c) + 1]; ++q) {
            const VIndex t = lattice.cell_tets[std::size_t(q)];
            if (std::find(out.begin(), out.end(), t) != out.end()) continue;
            if (tets_overlap(detail::corners_of<double>(lattice.mesh.V, LT, t), me, tolerance)) out.push_back(t);
          }
        }
    std::sort(out.begin(), out.end());
  });

  // 2. transpose: M-tets per lattice tet (ascending, since e runs in order)
  std::vector<Index> off(std::size_t(nl) + 1, 0);
  for (const auto& o : overlaps)
    for (VIndex t : o) ++off[std::size_t(t) + 1];
  for (Index t = 0; t < nl; ++t) off[std::size_t(t) + 1] += off[std::size_t(t)];
  std::vector<VIndex> held(std::size_t(off.back()));
  {
    std::vector<Index> fill(off.begin(), off.end() - 1);
    for (Index e = 0; e < nm; ++e)
      for (VIndex t : overlaps[std::size_t(e)]) held[std::size_t(fill[std::size_t(t)]++)] = VIndex(e);
  }

  // 3. pieces of every lattice tet: components of its M-tets, joined where they share a vertex
  std::vector<VIndex> piece(held.size());  // piece label of each (lattice tet, M-tet) entry
  std::vector<Index> num_pieces(std::size_t(nl), 0);
  exec::parallel_for(policy, nl, [&](Index t) {
    const Index b = off[std::size_t(t)], n = off[std::size_t(t) + 1] - b;
    if (n == 0) return;
    detail::UnionFind uf(n);
    std::vector<std::pair<VIndex, Index>> corner(std::size_t(4 * n));  // (M-vertex, local M-tet)
    for (Index i = 0; i < n; ++i)
      for (int c = 0; c < 4; ++c) corner[std::size_t(4 * i + c)] = {MT(held[std::size_t(b + i)], c), i};
    std::sort(corner.begin(), corner.end());
    for (std::size_t k = 1; k < corner.size(); ++k)
      if (corner[k].first == corner[k - 1].first) uf.join(corner[k].second, corner[k - 1].second);
    std::vector<Index> label(std::size_t(n), -1);
    Index count = 0;
    for (Index i = 0; i < n; ++i) {  // numbered by each piece's smallest M-tet
      const Index r = uf.find(i);
      if (label[std::size_t(r)] < 0) label[std::size_t(r)] = count++;
      piece[std::size_t(b + i)] = VIndex(label[std::size_t(r)]);
    }
    num_pieces[std::size_t(t)] = count;
  });

  // 4. split tets
  MaterialSplit<S> out;
  std::vector<Index> first_split(std::size_t(nl) + 1, 0);
  for (Index t = 0; t < nl; ++t) {
    first_split[std::size_t(t) + 1] = first_split[std::size_t(t)] + num_pieces[std::size_t(t)];
    if (num_pieces[std::size_t(t)] == 0) ++out.lattice_tets_without_material;
    if (num_pieces[std::size_t(t)] > 1) ++out.split_lattice_tets;
  }
  const Index ns = first_split.back();
  if (ns == 0) throw ArgumentError("split_by_material: no lattice tet holds any material (do the lattice and the material mesh overlap?)");
  out.tet_parent.resize(ns);
  for (Index t = 0; t < nl; ++t)
    for (Index p = 0; p < num_pieces[std::size_t(t)]; ++p) out.tet_parent[first_split[std::size_t(t)] + p] = VIndex(t);
  // pieces as CSR by split tet, and its transpose by M-tet
  out.piece_offsets.assign(std::size_t(ns) + 1, 0);
  for (Index t = 0; t < nl; ++t)
    for (Index q = off[std::size_t(t)]; q < off[std::size_t(t) + 1]; ++q) ++out.piece_offsets[std::size_t(first_split[std::size_t(t)] + piece[std::size_t(q)]) + 1];
  for (Index s = 0; s < ns; ++s) out.piece_offsets[std::size_t(s) + 1] += out.piece_offsets[std::size_t(s)];
  out.piece_material.resize(held.size());
  {
    std::vector<Index> fill(out.piece_offsets.begin(), out.piece_offsets.end() - 1);
    for (Index t = 0; t < nl; ++t)
      for (Index q = off[std::size_t(t)]; q < off[std::size_t(t) + 1]; ++q)
        out.piece_material[std::size_t(fill[std::size_t(first_split[std::size_t(t)] + piece[std::size_t(q)])]++)] = held[std::size_t(q)];
  }
  out.material_offsets.assign(std::size_t(nm) + 1, 0);
  for (VIndex e : out.piece_material) ++out.material_offsets[std::size_t(e) + 1];
  for (Index e = 0; e < nm; ++e) out.material_offsets[std::size_t(e) + 1] += out.material_offsets[std::size_t(e)];
  out.material_split_tets.resize(out.piece_material.size());
  {
    std::vector<Index> fill(out.material_offsets.begin(), out.material_offsets.end() - 1);
    for (Index s = 0; s < ns; ++s)
      for (Index q = out.piece_offsets[std::size_t(s)]; q < out.piece_offsets[std::size_t(s) + 1]; ++q)
        out.material_split_tets[std::size_t(fill[std::size_t(out.piece_material[std::size_t(q)])]++)] = VIndex(s);
  }

  // 5. node instances (4 per split tet), joined across split tets whose pieces touch: they hold
  //    M-tets around one M-vertex (a common M-tet included). Touching, not overlap, so that a
  //    material face lying exactly in a lattice face still joins the two sides.
  std::vector<Index> voff(std::size_t(material.V.rows()) + 1, 0);
  for (Index e = 0; e < nm; ++e)
    for (int c = 0; c < 4; ++c) ++voff[std::size_t(MT(e, c)) + 1];
  for (Index v = 0; v < material.V.rows(); ++v) voff[std::size_t(v) + 1] += voff[std::size_t(v)];
  std::vector<VIndex> vtets(std::size_t(voff.back()));
  {
    std::vector<Index> fill(voff.begin(), voff.end() - 1);
    for (Index e = 0; e < nm; ++e)
      for (int c = 0; c < 4; ++c) vtets[std::size_t(fill[std::size_t(MT(e, c))]++)] = VIndex(e);
  }
  detail::UnionFind nodes(4 * ns);
  std::vector<Index> around;
  for (Index u = 0; u < material.V.rows(); ++u) {
    around.clear();
    for (Index a = voff[std::size_t(u)]; a < voff[std::size_t(u) + 1]; ++a) {
      const VIndex e = vtets[std::size_t(a)];
      for (Index q = out.material_offsets[std::size_t(e)]; q < out.material_offsets[std::size_t(e) + 1]; ++q)
        around.push_back(out.material_split_tets[std::size_t(q)]);
    }
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end()), around.end());
    for (std::size_t i = 0; i < around.size(); ++i)
      for (std::size_t j = i + 1; j < around.size(); ++j) {
        const Index si = around[i], sj = around[j];
        const Index ti = out.tet_parent[si], tj = out.tet_parent[sj];
        for (int ci = 0; ci < 4; ++ci)
          for (int cj = 0; cj < 4; ++cj)
            if (LT(ti, ci) == LT(tj, cj)) nodes.join(4 * si + ci, 4 * sj + cj);
      }
  }
  // split nodes, ordered by (lattice node, smallest instance)
  std::vector<std::pair<VIndex, Index>> roots;  // (lattice node, root instance)
  for (Index i = 0; i < 4 * ns; ++i)
    if (nodes.find(i) == i) roots.push_back({LT(out.tet_parent[i / 4], i % 4), i});
  std::sort(roots.begin(), roots.end());
  std::vector<VIndex> node_of_root(std::size_t(4 * ns), -1);
  out.node_parent.resize(Index(roots.size()));
  out.mesh.V.resize(Index(roots.size()), 3);
  std::vector<char> lattice_node_seen(std::size_t(lattice.mesh.V.rows()), 0);
  for (std::size_t k = 0; k < roots.size(); ++k) {
    node_of_root[std::size_t(roots[k].second)] = VIndex(k);
    out.node_parent[Index(k)] = roots[k].first;
    out.mesh.V.row(Index(k)) = lattice.mesh.V.row(roots[k].first);
    if (lattice_node_seen[std::size_t(roots[k].first)]++) ++out.duplicated_nodes;
  }
  out.mesh.T.resize(ns, 4);
  for (Index s = 0; s < ns; ++s)
    for (int c = 0; c < 4; ++c) out.mesh.T(s, c) = node_of_root[std::size_t(nodes.find(4 * s + c))];
  return out;
}

/// Embeds vertices of the material mesh (e.g. its skin) in the split lattice: vertex v goes into
/// the split tet, among those holding an M-tet around v, whose lattice tet contains v best (the
/// largest smallest barycentric weight; ties to the lowest split tet). `inside[q]` is false, and
/// `distance[q]` the most negative weight times the lattice tet's size, where v lies in no
/// such tet (at the edge of the lattice's region mask); where no split tet holds any M-tet
/// around v (v lies beyond the mask), tet[q] is −1 and distance[q] infinite. Throws MeshError
/// for a vertex out of range or in no M-tet.
template <exec::HostPolicy P, class S>
Embedding<S> embed_material_vertices(P policy, const MaterialSplit<S>& split, const TetMesh<S>& material, const IndexVector& vertices,
                                     double inside_tolerance = 1e-9) {
  const Index nv = material.V.rows();
  // vertex → M-tets
  std::vector<Index> voff(std::size_t(nv) + 1, 0);
  for (Index e = 0; e < material.T.rows(); ++e)
    for (int c = 0; c < 4; ++c) ++voff[std::size_t(material.T(e, c)) + 1];
  for (Index v = 0; v < nv; ++v) voff[std::size_t(v) + 1] += voff[std::size_t(v)];
  std::vector<VIndex> vtets(std::size_t(voff.back()));
  {
    std::vector<Index> fill(voff.begin(), voff.end() - 1);
    for (Index e = 0; e < material.T.rows(); ++e)
      for (int c = 0; c < 4; ++c) vtets[std::size_t(fill[std::size_t(material.T(e, c))]++)] = VIndex(e);
  }
  Embedding<S> out;
  const Index nq = vertices.size();
  out.tet.resize(nq);
  out.weights.resize(nq, 4);
  out.inside.resize(nq);
  out.distance.resize(nq);
  const auto& LV = split.mesh.V;
  const auto& ST = split.mesh.T;
  exec::parallel_for(policy, nq, [&](Index q) {
    const VIndex v = vertices[q];
    if (v < 0 || v >= nv) throw MeshError("vertex", v, "embed_material_vertices: vertex out of range [0, " + std::to_string(nv) + ")");
    const Vec3<double> p = material.V.row(v).transpose().template cast<double>();
    double best = -1e300;
    Index best_s = -1;
    Eigen::Vector4d best_w = Eigen::Vector4d::Zero();
    for (Index a = voff[std::size_t(v)]; a < voff[std::size_t(v) + 1]; ++a) {
      const VIndex e = vtets[std::size_t(a)];
      for (Index b = split.material_offsets[std::size_t(e)]; b < split.material_offsets[std::size_t(e) + 1]; ++b) {
        const Index s = split.material_split_tets[std::size_t(b)];
        Eigen::Matrix3d D;
        const Vec3<double> x0 = LV.row(ST(s, 0)).transpose().template cast<double>();
        for (int k = 0; k < 3; ++k) D.col(k) = LV.row(ST(s, k + 1)).transpose().template cast<double>() - x0;
        const Vec3<double> l = D.inverse() * (p - x0);
        const Eigen::Vector4d w(1 - l.sum(), l[0], l[1], l[2]);
        const double m = w.minCoeff();
        if (m > best || (m == best && s < best_s)) {
          best = m;
          best_s = s;
          best_w = w;
        }
      }
    }
    if (voff[std::size_t(v)] == voff[std::size_t(v) + 1])
      throw MeshError("vertex", v, "embed_material_vertices: the vertex belongs to no tet of the material mesh");
    if (best_s < 0) {  // every M-tet around v lies outside the lattice (its region mask)
      out.tet[q] = -1;
      out.weights.row(q).setZero();
      out.inside[q] = false;
      out.distance[q] = std::numeric_limits<S>::infinity();
      return;
    }
    out.tet[q] = VIndex(best_s);
    out.weights.row(q) = best_w.transpose().template cast<S>();
    out.inside[q] = best >= -inside_tolerance;
    const double size = (LV.row(ST(best_s, 1)) - LV.row(ST(best_s, 0))).template cast<double>().norm();
    out.distance[q] = out.inside[q] ? S(0) : S(-best * size);
  });
  return out;
}

}  // namespace simsr::discretize
