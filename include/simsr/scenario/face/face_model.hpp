#pragma once
/// \file
/// The face of the core paper (§4) at two resolutions, from the ICT kit: one anatomy, two meshes.
///
///  1. Rest pose: the kit's neutral plus a fraction of its own `jawOpen` (default 0.1: 2.5° of
///     jaw), so the lips are apart (§4 pre-deforms the HR mesh by a small jaw rotation).
///  2. Flesh: the closed head surface (head_surface.hpp) minus the skull (skull.hpp), both at the
///     rest pose.
///  3. HR: Debian's tetgen on that PLC (skull as a hole), boundary kept (-Y), quality -q.
///  4. LR: the BCC lattice at cell size h over the HR mesh, masked to the face (cells whose centre
///     lies nearest to the kit's face, mouth or eye region, and above the chin: no neck, no back
///     of the head), then split by material (discretize/material_split.hpp) so no LR element
///     spans both lips.
///  5. Bones: HR vertices on the skull surface; LR nodes inside the skull. Two rigid bones: a
///     point whose jaw weight (jaw_weights.hpp) is at least `jaw_weight_min` is mandible and turns
///     with the hinge, one at most `cranium_weight_max` is cranium and stays; the band between
///     (the floor of the mouth, the cheeks between the jaw and the cheekbone) is soft tissue and
///     held by nothing. Blending the two motions there instead (linear blend skinning) shears the
///     skull surface itself: with the weight rising over ~2 cm under the chin and the chin moving
///     ~3 cm at a wide-open jaw, the blended map has det ≈ 1 + ∇w·r ≈ 0.1 and crushed the flesh
///     under the chin to inverted tets in the first full run.
///  6. The output surface: the kit's face skin where it lies inside the LR mesh, its vertices
///     HR vertices (the skin is kept by -Y) and embedded in LR tets.
///  7. Lips: the HR surface vertices and triangles within `lip_radius` of the lips' inner edge,
///     upper (jaw weight < ½) and lower, for the HR-only self-contact.
/// Everything is returned in metres (the kit is in cm), the physics' unit.
///
///     scenario::FaceModel face = scenario::build_face_model(exec::omp, kit, {.lr_cell = 1.2}, "out/mesh");

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../../discretize/bcc_lattice.hpp"
#include "../../discretize/material_split.hpp"
#include "../../discretize/voxelize.hpp"
#include "../../mesh/tet_mesh.hpp"
#include "../../mesh/topology.hpp"
#include "../../mesh/tri_mesh.hpp"
#include "../../mesh/triangulate.hpp"
#include "../../mesh/vertex_areas.hpp"
#include "../../neighbors/kd_tree.hpp"
#include "../tetgen_mesher.hpp"
#include "head_surface.hpp"
#include "ict_kit.hpp"
#include "jaw.hpp"
#include "jaw_weights.hpp"
#include "muscles.hpp"
#include "skull.hpp"

namespace simsr::scenario {

/// How the face model is built (lengths in cm, the kit's unit; the model comes out in metres).
struct FaceModelOptions {
  double rest_jaw_open = 0.1;     ///< jawOpen weight of the rest pose
  /// h of the LR BCC lattice. 1.2 cm: 10.8k tets, against the HR default's 135k (12.5×, the
  /// issue's ≥ 10×; the paper has 26×); see face_model_preset for the paper's ratio and size.
  double lr_cell = 1.2;
  /// Spacing of the lattice the skull level set is taken on: the skull's triangle size, which
  /// with the skin's fixes most of the HR mesh (the boundary is kept as it is).
  double skull_lattice = 1.0;
  /// HR tet quality and size: tetgen -q radius_edge/min_dihedral -a max_volume (cm³), -Y.
  TetgenOptions hr{.max_volume = 0.1, .radius_edge = 1.5, .min_dihedral = 12, .preserve_boundary = true};
  double chin_margin = 3.5;       ///< the LR mask drops cells lower than the lower teeth's bottom minus this
  double lip_radius = 1.5;        ///< surface within this distance of the lips' inner edge takes part in lip contact
  double jaw_weight_min = 0.6;     ///< skull points with at least this jaw weight are mandible (rigid, weight 1)
  double cranium_weight_max = 0.15; ///< skull points with at most this jaw weight are cranium (fixed)
  std::vector<MuscleSpec> muscles = default_muscle_specs();
};

/// The options of a named mesh-size preset (the HR mesh is the same in all three):
///   default       LR h = 1.2 cm:   10,782 LR tets, 12.5× fewer than HR's 134,563 (fits the
///                 ≤ 20 min budget of 4 × 120 frames on 2 cores with room to spare)
///   paper-ratio   LR h = 1.6 cm:    5,144 LR tets, 26.2× (the paper's 1.9M / 73k)
///   paper-lr      LR h = 0.565 cm: 73,066 LR tets (the paper's LR size, §4)
/// (counts measured on the ICT kit; `simsr datagen --preset`). ArgumentError for another name.
inline FaceModelOptions face_model_preset(const std::string& name) {
  FaceModelOptions o;
  if (name == "paper-ratio") {
    o.lr_cell = 1.6;
  } else if (name == "paper-lr") {
    o.lr_cell = 0.565;
  } else if (name != "default") {
    throw ArgumentError("face model preset must be default, paper-ratio or paper-lr (got '" + name + "')");
  }
  return o;
}

/// The preset `name` with each size override that is > 0 put in (`simsr datagen --preset
/// --lr-cell --skull-lattice --hr-max-volume`, Python's keywords of the same names): the LR cell
/// and the skull lattice in cm, the largest HR tet in cm³. ArgumentError for an unknown preset or a
/// negative or non-finite override.
inline FaceModelOptions face_model_preset(const std::string& name, double lr_cell, double skull_lattice, double hr_max_volume) {
  FaceModelOptions o = face_model_preset(name);
  for (const auto& [what, v] : {std::pair{"lr_cell", lr_cell}, std::pair{"skull_lattice", skull_lattice}, std::pair{"hr_max_volume", hr_max_volume}})
    if (!(v >= 0) || !std::isfinite(v)) throw ArgumentError(std::string("face model: ") + what + " = " + std::to_string(v) + " (need > 0, or 0 for the preset's)");
  if (lr_cell > 0) o.lr_cell = lr_cell;
  if (skull_lattice > 0) o.skull_lattice = skull_lattice;
  if (hr_max_volume > 0) o.hr.max_volume = hr_max_volume;
  return o;
}

/// One anatomy at two resolutions (metres; see the file comment).
struct FaceModel {
  // rest pose and rig data
  Hinge<> hinge;                       ///< the jaw hinge (point in m; angle: the full jawOpen rotation, rad)
  double rest_jaw_angle = 0;           ///< rad, the rest pose's jaw rotation from the neutral
  std::vector<std::string> expression_names;
  // HR
  TetMesh<> hr;
  IndexVector hr_bone;                 ///< HR vertices held by bones
  VecX<> hr_bone_jaw;                  ///< their jaw weights
  // LR
  TetMesh<> lr;
  IndexVector lr_bone;
  VecX<> lr_bone_jaw;
  discretize::MaterialSplit<> lr_split;  ///< how the lattice was split (node/tet parents, pieces)
  // the output surface (M vertices)
  TriMesh<> surface;                   ///< rest positions and triangles
  IndexVector surface_hr_vertex;       ///< surface vertex → HR vertex
  IndexVector surface_kit_vertex;      ///< surface vertex → kit vertex
  Embedding<> surface_in_lr;    ///< surface vertices in the LR tets
  VecX<> surface_area;                 ///< Voronoi area per surface vertex at rest (m²)
  Points<> neutral;                    ///< the surface at the kit's neutral (M×3): the blendshapes' base
  Eigen::MatrixXd deltas;              ///< E × 3M blendshape displacements of the surface vertices (m)
  std::vector<Muscle> muscles;         ///< fibre bundles (m), one definition for both meshes
  // lips (HR vertex indices)
  IndexVector lip_upper_vertices, lip_lower_vertices;
  Tris lip_upper_triangles, lip_lower_triangles;
  // what it took
  Index skull_vertices = 0, head_vertices = 0;
  double skull_volume = 0, min_flesh = 0;  ///< m³, m

  Index num_expressions() const { return Index(expression_names.size()); }
};

namespace detail {

/// The lips' inner edge: the boundary loop of the kit's skin with the most vertices among those
/// around the mouth (the loop whose centroid is closest to the mouth socket's).
inline std::vector<VIndex> mouth_loop(const IctKit& kit) {
  const TriMesh<> skin = triangulate(kit.faces_within({"face", "head_and_neck"}));
  const auto loops = boundary_loops(skin.F);
  const VertexRange ms = kit.region("mouth_socket");
  const Vec3<> socket = kit.neutral.V.middleRows(ms.first, ms.size()).colwise().mean().transpose();
  const std::vector<VIndex>* best = nullptr;
  double best_d = 1e300;
  for (const auto& l : loops) {
    Vec3<> c = Vec3<>::Zero();
    for (VIndex v : l) c += kit.neutral.V.row(v).transpose();
    c /= double(l.size());
    const double d = (c - socket).norm();
    if (d < best_d) {
      best_d = d;
      best = &l;
    }
  }
  if (!best) throw ArgumentError("face model: the kit's skin has no boundary loop at the mouth");
  return *best;
}

inline Tris select_triangles(const Tris& F, const std::vector<char>& keep) {
  std::vector<Index> rows;
  for (Index f = 0; f < F.rows(); ++f)
    if (keep[std::size_t(F(f, 0))] && keep[std::size_t(F(f, 1))] && keep[std::size_t(F(f, 2))]) rows.push_back(f);
  Tris out(Index(rows.size()), 3);
  for (std::size_t r = 0; r < rows.size(); ++r) out.row(Index(r)) = F.row(rows[r]);
  return out;
}

inline IndexVector flagged(const std::vector<char>& f) {
  std::vector<VIndex> v;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f[i]) v.push_back(VIndex(i));
  return Eigen::Map<const IndexVector>(v.data(), Index(v.size()));
}

/// The bone points of `candidates` (jaw weights `w`) as two rigid bones: weight ≥ jaw_weight_min
/// → 1, ≤ cranium_weight_max → 0, the band between dropped (file comment, step 5).
inline std::pair<IndexVector, VecX<>> rigid_bones(const IndexVector& candidates, const VecX<>& w, const FaceModelOptions& opt) {
  std::vector<VIndex> ids;
  std::vector<double> jaw;
  for (Index i = 0; i < candidates.size(); ++i)
    if (w[i] >= opt.jaw_weight_min || w[i] <= opt.cranium_weight_max) {
      ids.push_back(candidates[i]);
      jaw.push_back(w[i] >= opt.jaw_weight_min ? 1.0 : 0.0);
    }
  return {Eigen::Map<const IndexVector>(ids.data(), Index(ids.size())), Eigen::Map<const VecX<>>(jaw.data(), Index(jaw.size()))};
}

}  // namespace detail

/// Builds the face model from `kit` (see the file comment); tetgen's files go to `work_dir`.
/// Throws what the steps throw (ArgumentError for options that leave no skull or no LR cell,
/// Error from tetgen) and ArgumentError when a surface vertex cannot be embedded.
template <exec::HostPolicy P>
FaceModel build_face_model(P policy, const IctKit& kit, const FaceModelOptions& opt, const std::filesystem::path& work_dir) {
  if (!(opt.lr_cell > 0) || !(opt.skull_lattice > 0) || !(opt.lip_radius > 0) || !(opt.rest_jaw_open >= 0 && opt.rest_jaw_open < 1))
    throw ArgumentError("build_face_model: lr_cell, skull_lattice and lip_radius must be > 0 and rest_jaw_open in [0, 1)");
  if (!(opt.cranium_weight_max >= 0 && opt.cranium_weight_max < opt.jaw_weight_min && opt.jaw_weight_min <= 1))
    throw ArgumentError("build_face_model: need 0 <= cranium_weight_max < jaw_weight_min <= 1, got " + std::to_string(opt.cranium_weight_max) +
                        " and " + std::to_string(opt.jaw_weight_min));
  constexpr double m_per_cm = 0.01;
  FaceModel face;
  face.expression_names = kit.expression_names;

  // 1. rest pose
  const JawFromData jaw = jaw_from_kit(policy, kit);
  const Points<> rest = kit.neutral.V + opt.rest_jaw_open * kit.expression("jawOpen");
  face.hinge = jaw.hinge;
  face.rest_jaw_angle = opt.rest_jaw_open * jaw.hinge.angle;

  // 2. flesh boundary
  const HeadSurface head = head_surface(policy, kit, rest);
  const FleshThickness thickness = default_flesh_thickness(kit, rest, head);
  const Skull skull = skull_surface(policy, head, thickness, {.lattice_h = opt.skull_lattice});
  face.head_vertices = head.mesh.num_vertices();
  face.skull_vertices = skull.surface.num_vertices();
  for (double v : skull.component_volume) face.skull_volume += v * 1e-6;
  face.min_flesh = skull.min_flesh * m_per_cm;

  // 3. HR: head + skull (inward: the PLC's facets need no orientation) with the skull as holes
  TriMesh<> plc;
  plc.V.resize(head.mesh.V.rows() + skull.surface.V.rows(), 3);
  plc.V << head.mesh.V, skull.surface.V;
  plc.F.resize(head.mesh.F.rows() + skull.surface.F.rows(), 3);
  plc.F << head.mesh.F, (skull.surface.F.array() + VIndex(head.mesh.V.rows())).matrix();
  TetMesh<> hr_cm = tetgen_mesh(plc, skull.inside_point, opt.hr, work_dir);

  // 4. LR: masked lattice, split by material
  const VertexRange lower_teeth = kit.region("teeth_lower");
  const double min_y = rest.middleRows(lower_teeth.first, lower_teeth.size()).col(1).minCoeff() - opt.chin_margin;
  std::vector<char> face_part(std::size_t(head.mesh.V.rows()), 0);
  {
    const VertexRange f = kit.region("face"), ms = kit.region("mouth_socket"), el = kit.region("eye_socket_left"),
                      er = kit.region("eye_socket_right");
    for (Index v = 0; v < head.mesh.V.rows(); ++v) {
      const VIndex k = head.kit_vertex[std::size_t(v)];
      face_part[std::size_t(v)] = k >= 0 && (f.contains(k) || ms.contains(k) || el.contains(k) || er.contains(k));
    }
  }
  const neighbors::KdTree<double> head_tree(head.mesh.V);
  discretize::VoxelizeOptions vox;
  neighbors::KnnResult<double> one;
  Points<> query(1, 3);
  vox.region = [&](const Vec3<double>& c) {  // voxelize calls it sequentially
    if (c.y() < min_y) return false;
    query.row(0) = c.transpose();
    head_tree.query_into(exec::seq, query, 1, one);
    return face_part[std::size_t(one.indices(0, 0))] != 0;
  };
  const auto lattice = discretize::bcc_lattice(hr_cm, opt.lr_cell, vox);
  face.lr_split = discretize::split_by_material(policy, lattice, hr_cm);

  // 5. bones
  const JawWeights jw(kit, rest, jaw.hinge);
  {
    IndexVector hb(skull.surface.V.rows());
    for (Index i = 0; i < hb.size(); ++i) hb[i] = VIndex(head.mesh.V.rows() + i);
    std::tie(face.hr_bone, face.hr_bone_jaw) = detail::rigid_bones(hb, jw.at(policy, skull.surface.V), opt);
    const IndexVector lb = detail::flagged(discretize::inside_surface(skull.surface, face.lr_split.mesh.V));
    Points<> at(lb.size(), 3);
    for (Index i = 0; i < at.rows(); ++i) at.row(i) = face.lr_split.mesh.V.row(lb[i]);
    std::tie(face.lr_bone, face.lr_bone_jaw) = detail::rigid_bones(lb, jw.at(policy, at), opt);
  }

  // 6. output surface: face skin inside the LR mesh
  std::vector<char> candidate(std::size_t(head.mesh.V.rows()), 0);
  {
    const VertexRange f = kit.region("face");
    for (Index t = 0; t < head.mesh.F.rows(); ++t)
      if (head.part[std::size_t(t)] == HeadPart::skin)
        for (int c = 0; c < 3; ++c) {
          const VIndex k = head.kit_vertex[std::size_t(head.mesh.F(t, c))];
          if (k >= 0 && f.contains(k)) candidate[std::size_t(head.mesh.F(t, c))] = 1;
        }
  }
  const IndexVector cand = detail::flagged(candidate);
  const auto emb = discretize::embed_material_vertices(policy, face.lr_split, hr_cm, cand);
  std::vector<char> keep(std::size_t(head.mesh.V.rows()), 0);
  for (Index q = 0; q < cand.size(); ++q) keep[std::size_t(cand[q])] = emb.inside[q];
  // skin triangles with every corner kept
  Tris skinF;
  {
    const Tris& all = head.mesh.F;
    std::vector<Index> rows;
    for (Index t = 0; t < all.rows(); ++t)
      if (head.part[std::size_t(t)] == HeadPart::skin && keep[std::size_t(all(t, 0))] && keep[std::size_t(all(t, 1))] && keep[std::size_t(all(t, 2))])
        rows.push_back(t);
    skinF.resize(Index(rows.size()), 3);
    for (std::size_t r = 0; r < rows.size(); ++r) skinF.row(Index(r)) = all.row(rows[r]);
  }
  // compact: surface vertex order = HR vertex order of the vertices the kept triangles use
  std::vector<VIndex> to_surface(std::size_t(head.mesh.V.rows()), -1);
  for (Index t = 0; t < skinF.rows(); ++t)
    for (int c = 0; c < 3; ++c) to_surface[std::size_t(skinF(t, c))] = 0;
  std::vector<VIndex> hr_of;
  for (std::size_t v = 0; v < to_surface.size(); ++v)
    if (to_surface[v] == 0) {
      to_surface[v] = VIndex(hr_of.size());
      hr_of.push_back(VIndex(v));
    }
  const Index M = Index(hr_of.size());
  if (M == 0) throw ArgumentError("build_face_model: no face skin lies inside the LR mesh (lr_cell or the mask too tight?)");
  face.surface_hr_vertex = Eigen::Map<const IndexVector>(hr_of.data(), M);
  face.surface_kit_vertex.resize(M);
  for (Index i = 0; i < M; ++i) face.surface_kit_vertex[i] = head.kit_vertex[std::size_t(hr_of[std::size_t(i)])];
  face.surface.F.resize(skinF.rows(), 3);
  for (Index t = 0; t < skinF.rows(); ++t)
    for (int c = 0; c < 3; ++c) face.surface.F(t, c) = to_surface[std::size_t(skinF(t, c))];
  face.surface_in_lr = discretize::embed_material_vertices(policy, face.lr_split, hr_cm, face.surface_hr_vertex);

  // 7. lips: surface of the head near the lips' inner edge, split by jaw weight
  {
    const auto loop = detail::mouth_loop(kit);
    Points<> edge(Index(loop.size()), 3);
    for (std::size_t i = 0; i < loop.size(); ++i) edge.row(Index(i)) = rest.row(loop[i]);
    const neighbors::KdTree<double> edge_tree(edge);
    const VecX<> w = jw.at(policy, head.mesh.V);
    neighbors::KnnResult<double> near_edge;
    edge_tree.query_into(policy, head.mesh.V, 1, near_edge);
    std::vector<char> up(std::size_t(head.mesh.V.rows()), 0), lo(up.size(), 0);
    for (Index v = 0; v < head.mesh.V.rows(); ++v) {
      if (near_edge.distances(v, 0) > opt.lip_radius) continue;
      (w[v] < 0.5 ? up : lo)[std::size_t(v)] = 1;
    }
    face.lip_upper_vertices = detail::flagged(up);
    face.lip_lower_vertices = detail::flagged(lo);
    face.lip_upper_triangles = detail::select_triangles(head.mesh.F, up);
    face.lip_lower_triangles = detail::select_triangles(head.mesh.F, lo);
  }

  // 8. muscles, laid out on the rest pose
  {
    std::vector<VIndex> skin;
    const VertexRange f = kit.region("face");
    for (Index v = f.first; v <= f.last; ++v) skin.push_back(VIndex(v));
    face.muscles = face_muscles(kit, rest, skin, skull.surface, detail::mouth_loop(kit), opt.muscles);
    for (auto& m : face.muscles) {
      m.insertion *= m_per_cm;
      m.origin *= m_per_cm;
      m.ring *= m_per_cm;
      m.spec.length *= m_per_cm;
      m.spec.radius *= m_per_cm;
    }
  }

  // to metres
  face.hinge.point *= m_per_cm;
  face.hr = TetMesh<>{hr_cm.V * m_per_cm, hr_cm.T};
  face.lr = TetMesh<>{face.lr_split.mesh.V * m_per_cm, face.lr_split.mesh.T};
  face.lr_split.mesh.V *= m_per_cm;
  face.surface.V.resize(M, 3);
  face.neutral.resize(M, 3);
  for (Index i = 0; i < M; ++i) {
    face.surface.V.row(i) = face.hr.V.row(face.surface_hr_vertex[i]);
    face.neutral.row(i) = kit.neutral.V.row(face.surface_kit_vertex[i]) * m_per_cm;
  }
  face.deltas.resize(kit.deltas.rows(), 3 * M);
  for (Index e = 0; e < kit.deltas.rows(); ++e)
    for (Index i = 0; i < M; ++i)
      for (int c = 0; c < 3; ++c) face.deltas(e, 3 * i + c) = double(kit.deltas(e, 3 * face.surface_kit_vertex[i] + c)) * m_per_cm;
  face.surface_area = voronoi_areas(face.surface.V, face.surface.F);
  return face;
}

}  // namespace simsr::scenario
