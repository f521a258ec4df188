#pragma once
/// \file
/// SoftDECA's layered head (softdeca supplement §3, Table 1): skin, soft tissue, muscle and bone
/// as nested wraps of one topology, the space between them filled with prisms (mesh/prism_shell.hpp):
///
///     wrap 0            the outer surface (skin, and the mouth and eye sockets that close it)
///     wraps 1..L        soft tissue:  the skin moved inward by (1 − m)·k/L of the flesh thickness
///     wraps L+1..2L     muscle:       down to the full thickness (m: muscle_fraction)
///     wrap 2L           the inner surface: bone where it lies on the skull, free elsewhere
///
/// L (`layers`) is the resolution parameter: each shell is L prisms deep, 3 tets per prism. A
/// vertex moves inward along its given direction by its thickness; where the prisms of a
/// triangle fold (a concave spot where the offset crosses itself) the thickness at its corners
/// is reduced until no prism folds, and a column thinned below `collapse_below` pinches to the
/// surface (prism_shell.hpp: one vertex in every wrap, its degenerate tets left out; it is then
/// held by no bone), so the shell is always a valid, conforming tet mesh.
///
/// The inner wrap's bone vertices are Dirichlet vertices: cranium or jaw, each scaled per axis for
/// an individual skull (supplement §1 "Skull", 0.5–1.5 per axis): the cranium about its bone
/// vertices' centroid, the jaw about the hinge point (carried along by the cranium's scaling), so
/// the two bones stay joined at the hinge. Vertices on the outer surface's open boundary (the
/// neck) are held too, in every wrap, and move with the cranium.
///
///     auto head = scenario::layered_head(exec::omp, outer, inward, thickness, bones, {.layers = 2}, hinge);
///     physics::DirichletBoundary<> bc = head.bone_targets({1.1, 0.9, 1.0}, {1.0, 1.2, 1.0});

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/prism_shell.hpp"
#include "../../mesh/tet_mesh.hpp"
#include "../../mesh/topology.hpp"
#include "../../mesh/tri_mesh.hpp"
#include "../../physics/dirichlet_boundary.hpp"

namespace simsr::scenario {

/// What holds a vertex of the layered head.
enum class Bone : std::int8_t {
  none = 0,     ///< free
  cranium = 1,  ///< inner wrap on the cranium
  jaw = 2,      ///< inner wrap on the mandible
  neck = 3,     ///< on the open boundary (the neck cut), every wrap
};

/// Which layer a tet belongs to.
enum class TissueLayer : std::int8_t { soft_tissue = 0, muscle = 1 };

/// How the layered head is built.
struct LayeredHeadOptions {
  Index layers = 1;               ///< prism layers per shell: the resolution parameter (≥ 1)
  double muscle_fraction = 0.35;  ///< the share of the flesh thickness, next to the bone, that is muscle (0, 1)
  Index max_repairs = 60;         ///< rounds of thinning folded prisms (each: × 0.8 at their corners)
  double collapse_below = 0;      ///< a column thinned below this pinches to the surface (model units; 0: never)
};

/// The layered head (see the file comment).
struct LayeredHead {
  TetMesh<> mesh;                    ///< every wrap's vertices (vertex(w, i); the outer wrap's are 0..nv−1) and both shells' tets
  std::vector<TissueLayer> tissue;   ///< per tet
  std::vector<Bone> bone;            ///< per mesh vertex
  Tris outer_triangles;              ///< the outer wrap's triangles (mesh vertices 0..nv−1)
  VecX<> thickness;                  ///< per wrap vertex: the flesh thickness it got (after repairs)
  Index wrap_vertices = 0;           ///< nv
  Index layers = 0;                  ///< L
  Index repaired_vertices = 0;       ///< wrap vertices whose thickness was reduced to unfold prisms
  Index collapsed_vertices = 0;      ///< of those, the ones pinched to the surface (thickness 0)
  IndexVector vertex_of;             ///< w·nv + i → the mesh vertex of wrap w's vertex i (prism_shell.hpp)
  IndexVector column_of;             ///< mesh vertex → its column i
  Vec3<> hinge = Vec3<>::Zero();     ///< the jaw's scaling centre
  Vec3<> cranium_centre = Vec3<>::Zero();

  Index num_wraps() const { return 2 * layers + 1; }
  VIndex vertex(Index w, Index i) const { return vertex_of[w * wrap_vertices + i]; }
  Index count(TissueLayer l) const { return Index(std::count(tissue.begin(), tissue.end(), l)); }
  Index count(Bone b) const { return Index(std::count(bone.begin(), bone.end(), b)); }

  /// The tets of one layer as their own mesh (compacted vertices), for reports and files.
  TetMesh<> layer_mesh(TissueLayer l) const {
    std::vector<VIndex> map(std::size_t(mesh.num_vertices()), -1);
    std::vector<Index> rows;
    for (Index t = 0; t < mesh.num_tets(); ++t)
      if (tissue[std::size_t(t)] == l) rows.push_back(t);
    TetMesh<> r;
    r.T.resize(Index(rows.size()), 4);
    std::vector<VIndex> used;
    for (std::size_t k = 0; k < rows.size(); ++k)
      for (int c = 0; c < 4; ++c) {
        VIndex& m = map[std::size_t(mesh.T(rows[k], c))];
        if (m < 0) {
          m = VIndex(used.size());
          used.push_back(mesh.T(rows[k], c));
        }
        r.T(Index(k), c) = m;
      }
    r.V.resize(Index(used.size()), 3);
    for (std::size_t i = 0; i < used.size(); ++i) r.V.row(Index(i)) = mesh.V.row(used[i]);
    return r;
  }

  /// Where point x goes when the skull is scaled: with the jaw, or with the cranium.
  Vec3<> scaled(const Vec3<>& x, bool with_jaw, const Vec3<>& cranium_scale, const Vec3<>& jaw_scale) const {
    if (!with_jaw) return cranium_centre + cranium_scale.cwiseProduct(x - cranium_centre);
    return cranium_centre + cranium_scale.cwiseProduct(hinge - cranium_centre) + jaw_scale.cwiseProduct(x - hinge);
  }

  /// The held vertices at their places for a skull scaled per axis (1 = the template's).
  physics::DirichletBoundary<> bone_targets(const Vec3<>& cranium_scale, const Vec3<>& jaw_scale) const {
    std::vector<VIndex> held;
    for (Index v = 0; v < mesh.num_vertices(); ++v)
      if (bone[std::size_t(v)] != Bone::none) held.push_back(VIndex(v));
    physics::DirichletBoundary<> b;
    b.vertices = Eigen::Map<const IndexVector>(held.data(), Index(held.size()));
    b.targets.resize(b.vertices.size(), 3);
    for (Index k = 0; k < b.vertices.size(); ++k)
      b.targets.row(k) = scaled(mesh.V.row(b.vertices[k]).transpose(), bone[std::size_t(b.vertices[k])] == Bone::jaw, cranium_scale, jaw_scale).transpose();
    return b;
  }

  /// Every vertex moved with the bone at the inner end of its prism column (the jaw, or else the
  /// cranium): the held vertices at bone_targets() and the flesh carried along, a start for the
  /// solve of the scaled individual that inverts no tet of a positive scaling.
  Points<> scaled_rest(const Vec3<>& cranium_scale, const Vec3<>& jaw_scale) const {
    Points<> x(mesh.num_vertices(), 3);
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      const VIndex inner = vertex(2 * layers, column_of[v]);
      const bool jaw = inner >= 0 && bone[std::size_t(inner)] == Bone::jaw;
      x.row(v) = scaled(mesh.V.row(v).transpose(), jaw, cranium_scale, jaw_scale).transpose();
    }
    return x;
  }
};

/// The layered head from its outer surface, a unit inward direction and a flesh thickness per
/// vertex, and the bone under each vertex's inner end (Bone::none, cranium or jaw). `hinge`: the
/// jaw's scaling centre. ShapeError for arrays of the wrong size; ArgumentError for bad options,
/// a non-finite or negative thickness, a zero direction; MeshError when folded prisms remain
/// after max_repairs rounds (naming one).
template <exec::HostPolicy P>
LayeredHead layered_head(P policy, const TriMesh<>& outer, const Points<>& inward, VecX<> thickness, const std::vector<Bone>& inner_bone,
                         const LayeredHeadOptions& opt = {}, const Vec3<>& hinge = Vec3<>::Zero()) {
  const Index nv = outer.num_vertices();
  if (opt.layers < 1) throw ArgumentError("layered_head: layers must be >= 1, got " + std::to_string(opt.layers));
  if (!(opt.muscle_fraction > 0 && opt.muscle_fraction < 1))
    throw ArgumentError("layered_head: muscle_fraction must lie in (0, 1), got " + std::to_string(opt.muscle_fraction));
  if (inward.rows() != nv || inward.cols() != 3) throw ShapeError("layered_head: inward directions", {nv, 3}, {inward.rows(), inward.cols()});
  if (thickness.size() != nv) throw ShapeError("layered_head: thickness", {nv}, {thickness.size()});
  if (Index(inner_bone.size()) != nv) throw ShapeError("layered_head: inner bones", {nv}, {Index(inner_bone.size())});
  for (Index i = 0; i < nv; ++i) {
    if (!(std::isfinite(thickness[i]) && thickness[i] >= 0))
      throw ArgumentError("layered_head: thickness[" + std::to_string(i) + "] must be finite and >= 0, got " + std::to_string(thickness[i]));
    if (!(std::abs(inward.row(i).norm() - 1) < 1e-6)) throw ArgumentError("layered_head: inward direction " + std::to_string(i) + " is not a unit vector");
    if (inner_bone[std::size_t(i)] == Bone::neck) throw ArgumentError("layered_head: the neck is found from the boundary, not given as an inner bone");
  }

  const Index L = opt.layers, W = 2 * L + 1;
  std::vector<double> fraction(static_cast<std::size_t>(W));
  for (Index k = 0; k <= L; ++k) fraction[std::size_t(k)] = (1 - opt.muscle_fraction) * double(k) / double(L);
  for (Index k = 1; k <= L; ++k) fraction[std::size_t(L + k)] = (1 - opt.muscle_fraction) + opt.muscle_fraction * double(k) / double(L);
  const auto make_wraps = [&]() {
    std::vector<Points<>> wraps(static_cast<std::size_t>(W));
    for (Index w = 0; w < W; ++w) wraps[std::size_t(w)] = outer.V + fraction[std::size_t(w)] * (thickness.asDiagonal() * inward);
    return wraps;
  };

  LayeredHead head;
  std::vector<char> thinned(static_cast<std::size_t>(nv), 0), collapsed(static_cast<std::size_t>(nv), 0);
  std::vector<Points<>> wraps = make_wraps();
  for (Index round = 0;; ++round) {
    const std::vector<char> bad = folded_prisms(policy, outer.F, wraps, collapsed);
    if (std::find(bad.begin(), bad.end(), 1) == bad.end()) break;
    if (round >= opt.max_repairs) {
      const Index f = Index(std::find(bad.begin(), bad.end(), 1) - bad.begin());
      throw MeshError("triangle", f, "its prisms still fold after " + std::to_string(opt.max_repairs) + " rounds of thinning the layered head");
    }
    std::vector<char> shrink(static_cast<std::size_t>(nv), 0);
    for (Index f = 0; f < outer.F.rows(); ++f)
      if (bad[std::size_t(f)])
        for (int c = 0; c < 3; ++c) shrink[std::size_t(outer.F(f, c))] = 1;
    for (Index i = 0; i < nv; ++i)
      if (shrink[std::size_t(i)]) {
        thickness[i] *= 0.8;
        thinned[std::size_t(i)] = 1;
        if (thickness[i] < opt.collapse_below) {  // no thickness fits: the shell pinches to the surface here
          thickness[i] = 0;
          collapsed[std::size_t(i)] = 1;
        }
      }
    wraps = make_wraps();
  }
  head.repaired_vertices = Index(std::count(thinned.begin(), thinned.end(), 1));
  head.collapsed_vertices = Index(std::count(collapsed.begin(), collapsed.end(), 1));

  const PrismShell<> shell = prism_shell(policy, outer.F, wraps, collapsed);
  head.mesh = shell.mesh;
  head.vertex_of = shell.vertex_of;
  head.column_of = shell.column_of;
  head.wrap_vertices = nv;
  head.layers = L;
  head.thickness = thickness;
  head.outer_triangles = outer.F;
  head.tissue.resize(std::size_t(head.mesh.num_tets()));
  for (Index t = 0; t < head.mesh.num_tets(); ++t) head.tissue[std::size_t(t)] = shell.tet_layer[t] < L ? TissueLayer::soft_tissue : TissueLayer::muscle;
  head.bone.assign(std::size_t(head.mesh.num_vertices()), Bone::none);
  for (Index i = 0; i < nv; ++i)  // a pinched column is skin, held by nothing; a dropped inner copy holds nothing either
    if (!collapsed[std::size_t(i)] && head.vertex(2 * L, i) >= 0) head.bone[std::size_t(head.vertex(2 * L, i))] = inner_bone[std::size_t(i)];
  // the open boundary (the neck cut) is held in every wrap
  const Edges open = boundary_edges(outer.F);
  for (Index e = 0; e < open.rows(); ++e)
    for (int c = 0; c < 2; ++c)
      for (Index w = 0; w < W; ++w)
        if (head.vertex(w, open(e, c)) >= 0) head.bone[std::size_t(head.vertex(w, open(e, c)))] = Bone::neck;
  // scaling centres
  Vec3<> sum = Vec3<>::Zero();
  Index n = 0;
  for (Index v = 0; v < head.mesh.num_vertices(); ++v)
    if (head.bone[std::size_t(v)] == Bone::cranium) {
      sum += head.mesh.V.row(v).transpose();
      ++n;
    }
  head.cranium_centre = n > 0 ? Vec3<>(sum / double(n)) : Vec3<>::Zero();
  head.hinge = hinge;
  return head;
}

}  // namespace simsr::scenario
