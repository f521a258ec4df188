#pragma once
/// \file
/// SoftDECA's layered head template from the ICT face kit (softdeca supplement §3), in metres:
///
///  1. Outer wrap: the kit's closed head surface (skin + mouth and eye sockets, head_surface.hpp)
///     without the neck cap, at the kit's neutral: open only at the neck cut. Either the kit's own
///     triangles (ict_outer_wrap) or those remeshed to one edge length (remeshed_wrap.hpp), the
///     template's surface resolution.
///  2. Inward direction: the angle-weighted vertex normal, smoothed over the surface (a few
///     umbrella rounds), so neighbouring offsets stay nearly parallel; then turned, where needed,
///     until it points into the flesh across every triangle at the vertex (creases: the lips'
///     and eyelids' inner edges), without which no thickness gives that triangle a valid prism.
///  3. Flesh thickness: the vertex marches inward along its direction until it meets the skull of
///     the face scenario (skull.hpp: where the distance to the head surface exceeds the regional
///     soft-tissue depth t(x)): there the inner wrap is bone. Where the ray passes the middle of a
///     thin part first (the distance to the head surface drops below 0.8 × depth: lips, nose,
///     eyelids, ears) the thickness is 0.45 × that depth and the inner wrap is free, so the two
///     sides' prisms do not meet; beyond `max_depth` (the neck) it is max_depth, free.
///  4. Bones: bone vertices with a jaw weight ≥ jaw_weight_min are the mandible, ≤
///     cranium_weight_max the cranium, in between free (the face model's rule, face_model.hpp).
///  5. The layered head (layered_head.hpp) with `layers` prisms per shell. Where a triangle's
///     prism still folds (a needle triangle of the kit's triangulated quads, whose plane says
///     nothing about the surface, or a crease no direction fits), its corners thin and, below
///     0.5 mm, pinch to the surface (51 of the 14,062 wrap vertices at 1 layer).
///
/// The skin (the kit's face and head_and_neck vertices of the outer wrap) carries the kit's 57
/// expressions as displacements, the targets of SoftDECA's E_tar.
///
///     auto tpl = scenario::softdeca_template(exec::omp, kit, {.head = {.layers = 1}});

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../mesh/normals.hpp"
#include "../../mesh/topology.hpp"
#include "../../neighbors/surface_distance.hpp"
#include "../face/head_surface.hpp"
#include "../face/ict_kit.hpp"
#include "../face/jaw.hpp"
#include "../face/jaw_weights.hpp"
#include "../face/skull.hpp"
#include "layered_head.hpp"
#include "template.hpp"

namespace simsr::scenario {

/// How the template is built (lengths in cm, the kit's unit).
struct SoftDecaTemplateOptions {
  LayeredHeadOptions head{.layers = 1, .muscle_fraction = 0.35, .max_repairs = 60, .collapse_below = 0.05};
  double max_depth = 3.0;             ///< cm: the deepest the flesh goes (the neck)
  double march_step = 0.05;           ///< cm: the inward march's step
  Index normal_smoothing = 5;         ///< umbrella rounds over the vertex normals
  double direction_margin = 0.2;      ///< each direction's least cosine with its triangles' inward normals
  Index direction_rounds = 100;       ///< rounds of projecting a direction into those half-spaces
  double jaw_weight_min = 0.6;
  double cranium_weight_max = 0.15;
};

/// The template from the kit, and how its construction went.
struct IctTemplate : SoftDecaTemplate {
  Index bone_vertices = 0, thin_vertices = 0, deep_vertices = 0;  ///< how step 3's march ended, per wrap vertex
};

/// The outer wrap (step 1) before the inward march, in cm: the kit's closed head surface without
/// the neck cap, or any surface laid over it (remeshed_wrap.hpp), with each triangle's part and
/// each vertex's place on the kit as a barycentric point of three kit vertices (a kit vertex
/// itself: corners (k, k, k), weights (1, 0, 0)), through which the expressions reach it.
struct IctOuterWrap {
  HeadSurface closed;          ///< the kit's closed head surface it lies on (at the neutral): the inward march's distances
  TriMesh<> mesh;
  std::vector<HeadPart> part;  ///< per triangle: skin, mouth_socket or eye_socket
  Tris kit_corners;            ///< per vertex: three kit vertices
  Points<> kit_weights;        ///< per vertex: their barycentric weights (sum 1)
};

/// The kit's own outer wrap: the closed surface (head_surface.hpp) without the neck cap and the
/// cap's centre, every vertex a kit vertex.
template <exec::HostPolicy P>
IctOuterWrap ict_outer_wrap(P policy, const IctKit& kit) {
  IctOuterWrap wrap;
  wrap.closed = head_surface(policy, kit, kit.neutral.V);
  const HeadSurface& closed = wrap.closed;
  std::vector<VIndex> map(static_cast<std::size_t>(closed.mesh.num_vertices()), -1);
  std::vector<std::array<VIndex, 3>> tris;
  std::vector<VIndex> used;
  for (Index f = 0; f < closed.mesh.F.rows(); ++f) {
    if (closed.part[std::size_t(f)] == HeadPart::neck_cap) continue;
    std::array<VIndex, 3> t{};
    for (int c = 0; c < 3; ++c) {
      VIndex& m = map[std::size_t(closed.mesh.F(f, c))];
      if (m < 0) {
        m = VIndex(used.size());
        used.push_back(closed.mesh.F(f, c));
      }
      t[std::size_t(c)] = m;
    }
    tris.push_back(t);
    wrap.part.push_back(closed.part[std::size_t(f)]);
  }
  const Index nv = Index(used.size());
  wrap.mesh.V.resize(nv, 3);
  wrap.kit_corners.resize(nv, 3);
  wrap.kit_weights.setZero(nv, 3);
  for (Index i = 0; i < nv; ++i) {
    wrap.mesh.V.row(i) = closed.mesh.V.row(used[std::size_t(i)]);
    const VIndex k = closed.kit_vertex[used[std::size_t(i)]];
    if (k < 0) throw ArgumentError("ict_outer_wrap: outer wrap vertex " + std::to_string(i) + " is no kit vertex");
    wrap.kit_corners.row(i).setConstant(k);
    wrap.kit_weights(i, 0) = 1;
  }
  wrap.mesh.F.resize(Index(tris.size()), 3);
  for (std::size_t f = 0; f < tris.size(); ++f)
    for (int c = 0; c < 3; ++c) wrap.mesh.F(Index(f), c) = tris[f][std::size_t(c)];
  return wrap;
}

/// Builds the template on an outer wrap (steps 2–5 of the file comment). Throws what
/// head_surface, skull_surface and layered_head throw; ArgumentError for bad options;
/// ShapeError and ArgumentError for a wrap whose arrays disagree or whose kit places are not
/// barycentric points of kit vertices. (The options have no default here, so that
/// softdeca_template(policy, kit, {}) names the other overload.)
template <exec::HostPolicy P>
IctTemplate softdeca_template(P policy, const IctKit& kit, const IctOuterWrap& wrap, const SoftDecaTemplateOptions& opt) {
  if (!(opt.max_depth > 0) || !(opt.march_step > 0) || opt.march_step > opt.max_depth)
    throw ArgumentError("softdeca_template: need 0 < march_step <= max_depth");
  if (!(opt.cranium_weight_max >= 0 && opt.cranium_weight_max < opt.jaw_weight_min && opt.jaw_weight_min <= 1))
    throw ArgumentError("softdeca_template: need 0 <= cranium_weight_max < jaw_weight_min <= 1");
  const Index nv = wrap.mesh.num_vertices(), nf = wrap.mesh.F.rows(), nk = kit.neutral.num_vertices();
  if (Index(wrap.part.size()) != nf) throw ShapeError("softdeca_template: wrap parts", {nf}, {Index(wrap.part.size())});
  if (wrap.kit_corners.rows() != nv) throw ShapeError("softdeca_template: wrap kit corners", {nv, 3}, {wrap.kit_corners.rows(), 3});
  if (wrap.kit_weights.rows() != nv) throw ShapeError("softdeca_template: wrap kit weights", {nv, 3}, {wrap.kit_weights.rows(), 3});
  for (Index i = 0; i < nv; ++i) {
    if (!(wrap.kit_corners.row(i).minCoeff() >= 0 && wrap.kit_corners.row(i).maxCoeff() < nk))
      throw ArgumentError("softdeca_template: wrap vertex " + std::to_string(i) + " names a kit vertex outside [0, " + std::to_string(nk) + ")");
    if (!(wrap.kit_weights.row(i).minCoeff() >= -1e-12 && std::abs(wrap.kit_weights.row(i).sum() - 1) < 1e-9))
      throw ArgumentError("softdeca_template: wrap vertex " + std::to_string(i) + "'s kit weights are not barycentric");
  }
  constexpr double m_per_cm = 0.01;
  const Points<>& rest = kit.neutral.V;
  if (wrap.closed.mesh.num_vertices() == 0) throw ArgumentError("softdeca_template: the wrap carries no closed head surface (ict_outer_wrap makes one)");
  const HeadSurface& closed = wrap.closed;  // computed once, by ict_outer_wrap
  const FleshThickness depth_of = default_flesh_thickness(kit, rest, closed);

  IctTemplate tpl;
  const TriMesh<>& outer = wrap.mesh;
  for (Index i = 0; i < nv; ++i) tpl.kit_vertex.push_back(wrap.kit_weights(i, 0) == 1 ? wrap.kit_corners(i, 0) : VIndex(-1));
  {
    Index skin_rows = 0;
    for (HeadPart part : wrap.part) skin_rows += part == HeadPart::skin;
    tpl.skin_triangles.resize(skin_rows, 3);
    for (Index f = 0, r = 0; f < nf; ++f)
      if (wrap.part[std::size_t(f)] == HeadPart::skin) tpl.skin_triangles.row(r++) = outer.F.row(f);
  }

  // 2. inward directions: smoothed normals
  Points<> n = vertex_normals(outer.V, outer.F, NormalWeighting::angle);
  const Adjacency adj = vertex_adjacency(outer.F, nv);
  for (Index round = 0; round < opt.normal_smoothing; ++round) {
    Points<> next(nv, 3);
    exec::parallel_for(policy, nv, [&](Index i) {
      Vec3<> s = n.row(i).transpose();
      for (Index k = adj.offsets[i]; k < adj.offsets[i + 1]; ++k) s += n.row(adj.neighbors[k]).transpose();
      next.row(i) = s.normalized().transpose();
    });
    n.swap(next);
  }
  // A prism is valid for small thicknesses exactly when every corner's direction points into the
  // flesh across the triangle (−n_f·d > 0); at creases (the lips' and eyelids' inner edges, where
  // the skin turns into a socket) the averaged normal does not. Cyclic projections onto those
  // half-spaces (−n_f·d ≥ margin for each triangle at the vertex) find a direction that does
  // wherever the crease leaves a wedge open.
  Points<> inward = -n;
  {
    const Points<> fn = face_normals(policy, outer.V, outer.F);
    std::vector<std::vector<Index>> faces_at(static_cast<std::size_t>(nv));
    for (Index f = 0; f < outer.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) faces_at[std::size_t(outer.F(f, c))].push_back(f);
    exec::parallel_for(policy, nv, [&](Index i) {
      Vec3<> d = inward.row(i).transpose();
      for (Index round = 0; round < opt.direction_rounds; ++round) {
        bool ok = true;
        for (Index f : faces_at[std::size_t(i)]) {
          const Vec3<> m = -fn.row(f).transpose();
          const double a = m.dot(d);
          if (a < opt.direction_margin) {
            d += (opt.direction_margin - a) * m;
            d.normalize();
            ok = false;
          }
        }
        if (ok) break;
      }
      inward.row(i) = d.transpose();
    });
  }

  // 3. thickness by marching inward
  const neighbors::SurfaceDistance<> dist(closed.mesh);
  VecX<> thickness(nv);
  std::vector<int> outcome(std::size_t(nv), 0);  // 1 bone, 2 thin, 3 deep
  exec::parallel_for(policy, nv, [&](Index i) {
    const Vec3<> x = outer.V.row(i).transpose(), d = inward.row(i).transpose();
    for (double s = opt.march_step; s <= opt.max_depth + 1e-12; s += opt.march_step) {
      const Vec3<> p = x + s * d;
      const double ds = dist.closest(p).distance;
      if (ds >= depth_of(p)) {
        thickness[i] = s;
        outcome[std::size_t(i)] = 1;
        return;
      }
      if (ds < 0.8 * s) {
        thickness[i] = 0.45 * s;
        outcome[std::size_t(i)] = 2;
        return;
      }
    }
    thickness[i] = opt.max_depth;
    outcome[std::size_t(i)] = 3;
  });
  tpl.bone_vertices = Index(std::count(outcome.begin(), outcome.end(), 1));
  tpl.thin_vertices = Index(std::count(outcome.begin(), outcome.end(), 2));
  tpl.deep_vertices = Index(std::count(outcome.begin(), outcome.end(), 3));

  // 4. bones by jaw weight at the inner ends
  const JawFromData jaw = jaw_from_kit(policy, kit);
  const JawWeights jw(kit, rest, jaw.hinge);
  Points<> inner(nv, 3);
  for (Index i = 0; i < nv; ++i) inner.row(i) = outer.V.row(i) + thickness[i] * inward.row(i);
  const VecX<> w = jw.at(policy, inner);
  std::vector<Bone> bones(std::size_t(nv), Bone::none);
  for (Index i = 0; i < nv; ++i)
    if (outcome[std::size_t(i)] == 1) bones[std::size_t(i)] = w[i] >= opt.jaw_weight_min ? Bone::jaw : w[i] <= opt.cranium_weight_max ? Bone::cranium : Bone::none;

  // 5. the layered head, in metres
  TriMesh<> outer_m{outer.V * m_per_cm, outer.F};
  LayeredHeadOptions ho = opt.head;
  ho.collapse_below *= m_per_cm;
  tpl.head = layered_head(policy, outer_m, inward, thickness * m_per_cm, bones, ho, jaw.hinge.point * m_per_cm);

  // the skin (every vertex of a skin triangle) and its expressions, through the kit places
  std::vector<char> on_skin(static_cast<std::size_t>(nv), 0);
  for (Index f = 0; f < tpl.skin_triangles.rows(); ++f)
    for (int c = 0; c < 3; ++c) on_skin[std::size_t(tpl.skin_triangles(f, c))] = 1;
  std::vector<VIndex> skin;
  for (Index i = 0; i < nv; ++i)
    if (on_skin[std::size_t(i)]) skin.push_back(VIndex(i));
  tpl.skin = Eigen::Map<const IndexVector>(skin.data(), Index(skin.size()));
  tpl.expression_names = kit.expression_names;
  const Index E = Index(kit.expression_names.size());
  tpl.expression_deltas.resize(E, 3 * tpl.skin.size());
  for (Index e = 0; e < E; ++e) {
    const Points<> d = kit.expression(kit.expression_names[std::size_t(e)]);
    for (Index k = 0; k < tpl.skin.size(); ++k) {
      const Index i = tpl.skin[k];
      Vec3<> delta = Vec3<>::Zero();
      for (int c = 0; c < 3; ++c) delta += wrap.kit_weights(i, c) * d.row(wrap.kit_corners(i, c)).transpose();
      tpl.expression_deltas.block<1, 3>(e, 3 * k) = m_per_cm * delta.transpose();
    }
  }
  return tpl;
}

/// The template on the kit's own triangles (see the file comment).
template <exec::HostPolicy P>
IctTemplate softdeca_template(P policy, const IctKit& kit, const SoftDecaTemplateOptions& opt = {}) {
  return softdeca_template(policy, kit, ict_outer_wrap(policy, kit), opt);
}

}  // namespace simsr::scenario
