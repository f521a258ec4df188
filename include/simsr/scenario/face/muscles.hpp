#pragma once
/// \file
/// The face's muscles as fibre bundles (SPEC §4; the muscle layout of Sifakis et al. 2005), laid
/// out from the kit's own blendshapes so no landmark is hand-placed: a muscle's insertion is the
/// skin vertex its expression moves most (mouthSmile_L moves the left mouth corner), its line of
/// action the direction that vertex moves (a muscle pulls its insertion towards its origin), its
/// origin the skull point nearest to the insertion moved `length` along that line. The bundle is
/// the capsule of `radius` about origin–insertion, fibres along it. The orbicularis oris is a
/// ring: the flesh within `radius` of the lips' inner edge, fibres along the edge.
///
/// One definition serves both meshes: membership and fibre direction are functions of position
/// (muscle_fibre_at), evaluated at each tet's rest centroid, HR or LR.
///
///     auto muscles = scenario::face_muscles(kit, rest, skull, mouth_loop);   // 17 muscles
///     auto fibre = scenario::muscle_fibre_at(muscles, centroid);            // which, and direction

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "../../mesh/tri_mesh.hpp"
#include "../../neighbors/surface_distance.hpp"
#include "ict_kit.hpp"

namespace simsr::scenario {

/// A muscle's shape: a straight bundle or a ring along a closed polyline.
enum class MuscleShape { bundle, ring };

/// What drives a muscle: activation = clamp(Σ gain · blendshape weight, 0, 1).
struct MuscleDriver {
  std::string expression;
  double gain = 1;
};

/// How a muscle is laid out (lengths in the kit's unit).
struct MuscleSpec {
  std::string name;
  MuscleShape shape = MuscleShape::bundle;
  std::vector<MuscleDriver> drivers;  ///< the first one also places the insertion (bundles)
  double length = 4;                  ///< insertion → origin before projection onto the skull
  double radius = 0.6;                ///< bundle or ring thickness
};

/// A laid-out muscle.
struct Muscle {
  MuscleSpec spec;
  Vec3<> insertion = Vec3<>::Zero(), origin = Vec3<>::Zero();  ///< bundles
  Points<> ring;                                              ///< ring: closed polyline
  Index insertion_vertex = -1;                                ///< kit vertex (bundles)
};

/// The issue's named muscles, each driven by the ARKit expression that contracts it.
inline std::vector<MuscleSpec> default_muscle_specs() {
  std::vector<MuscleSpec> m;
  for (const char* s : {"L", "R"}) {
    const std::string side = s;
    m.push_back({"zygomaticus_major_" + side, MuscleShape::bundle, {{"mouthSmile_" + side, 1}}, 5.0, 0.6});
    m.push_back({"frontalis_" + side, MuscleShape::bundle, {{"browOuterUp_" + side, 1}, {"browInnerUp_" + side, 0.5}}, 5.0, 1.2});
    m.push_back({"depressor_anguli_oris_" + side, MuscleShape::bundle, {{"mouthFrown_" + side, 1}}, 3.0, 0.6});
    m.push_back({"levator_labii_superioris_" + side, MuscleShape::bundle, {{"mouthUpperUp_" + side, 1}, {"noseSneer_" + side, 0.5}}, 3.5, 0.5});
    m.push_back({"risorius_" + side, MuscleShape::bundle, {{"mouthStretch_" + side, 1}}, 4.0, 0.5});
    m.push_back({"corrugator_" + side, MuscleShape::bundle, {{"browDown_" + side, 1}}, 2.5, 0.5});
    m.push_back({"buccinator_" + side, MuscleShape::bundle, {{"mouthDimple_" + side, 1}, {"cheekPuff_" + side, 0.5}}, 4.0, 0.8});
  }
  m.push_back({"orbicularis_oris", MuscleShape::ring, {{"mouthPucker", 1}, {"mouthFunnel", 0.7}, {"mouthPress_L", 0.3}, {"mouthPress_R", 0.3}}, 0, 0.9});
  m.push_back({"mentalis", MuscleShape::bundle, {{"mouthShrugLower", 1}}, 2.0, 0.6});
  return m;
}

/// Lays out `specs` on the kit at `positions` (its rest pose), with insertions among the skin
/// vertices `skin` and origins on `skull`; `mouth` is the lips' inner edge (kit vertices, a loop).
/// ArgumentError for an unknown expression or one that moves no skin vertex.
inline std::vector<Muscle> face_muscles(const IctKit& kit, const Points<>& positions, const std::vector<VIndex>& skin, const TriMesh<>& skull,
                                        const std::vector<VIndex>& mouth, const std::vector<MuscleSpec>& specs = default_muscle_specs()) {
  const neighbors::SurfaceDistance<> to_skull(skull);
  std::vector<Muscle> out;
  for (const auto& spec : specs) {
    if (spec.drivers.empty()) throw ArgumentError("face_muscles: muscle '" + spec.name + "' has no driving expression");
    for (const auto& d : spec.drivers) (void)kit.expression_index(d.expression);  // ArgumentError when unknown
    if (!(spec.radius > 0)) throw ArgumentError("face_muscles: muscle '" + spec.name + "' needs a radius > 0");
    Muscle m;
    m.spec = spec;
    if (spec.shape == MuscleShape::ring) {
      m.ring.resize(Index(mouth.size()), 3);
      for (std::size_t i = 0; i < mouth.size(); ++i) m.ring.row(Index(i)) = positions.row(mouth[i]);
      out.push_back(std::move(m));
      continue;
    }
    const Index e = kit.expression_index(spec.drivers.front().expression);
    double best = 0;
    for (VIndex v : skin) {
      const double d2 = Vec3<>(kit.deltas(e, 3 * v), kit.deltas(e, 3 * v + 1), kit.deltas(e, 3 * v + 2)).squaredNorm();
      if (d2 > best) {
        best = d2;
        m.insertion_vertex = v;
      }
    }
    if (m.insertion_vertex < 0) throw ArgumentError("face_muscles: '" + spec.drivers.front().expression + "' moves no skin vertex (muscle '" + spec.name + "')");
    const VIndex v = VIndex(m.insertion_vertex);
    const Vec3<> dir = Vec3<>(kit.deltas(e, 3 * v), kit.deltas(e, 3 * v + 1), kit.deltas(e, 3 * v + 2)).normalized();
    m.insertion = positions.row(v).transpose();
    const auto hit = to_skull.closest(m.insertion + spec.length * dir);
    m.origin = Vec3<>::Zero();
    for (int c = 0; c < 3; ++c) m.origin += hit.barycentric[c] * skull.V.row(skull.F(hit.triangle, c)).transpose();
    out.push_back(std::move(m));
  }
  return out;
}

/// A point's muscle: which (index into the muscles) and the fibre direction there.
struct MuscleFibreAt {
  Index muscle = -1;
  Vec3<> direction = Vec3<>::UnitX();
};

/// The first muscle whose bundle or ring holds `x`, and its fibre direction; nullopt outside all.
inline std::optional<MuscleFibreAt> muscle_fibre_at(const std::vector<Muscle>& muscles, const Vec3<>& x) {
  for (std::size_t k = 0; k < muscles.size(); ++k) {
    const Muscle& m = muscles[k];
    if (m.spec.shape == MuscleShape::bundle) {
      const Vec3<> a = m.insertion, b = m.origin, ab = b - a;
      const double L2 = ab.squaredNorm();
      if (!(L2 > 0)) continue;
      const double s = std::clamp((x - a).dot(ab) / L2, 0.0, 1.0);
      if ((a + s * ab - x).norm() <= m.spec.radius) return MuscleFibreAt{Index(k), ab.normalized()};
    } else {
      double best = 1e300;
      Vec3<> tangent = Vec3<>::UnitX();
      const Index n = m.ring.rows();
      for (Index i = 0; i < n; ++i) {
        const Vec3<> a = m.ring.row(i).transpose(), b = m.ring.row((i + 1) % n).transpose(), ab = b - a;
        const double L2 = ab.squaredNorm();
        if (!(L2 > 0)) continue;
        const double s = std::clamp((x - a).dot(ab) / L2, 0.0, 1.0);
        const double d = (a + s * ab - x).norm();
        if (d < best) {
          best = d;
          tangent = ab.normalized();
        }
      }
      if (best <= m.spec.radius) return MuscleFibreAt{Index(k), tangent};
    }
  }
  return std::nullopt;
}

/// Activations from blendshape weights (one per expression of `names`): each muscle's drivers.
inline VecX<> muscle_activations(const std::vector<Muscle>& muscles, const std::vector<std::string>& names, const VecX<>& weights) {
  if (Index(names.size()) != weights.size()) throw ShapeError("muscle_activations: weights", {Index(names.size()), 1}, {weights.size(), 1});
  VecX<> a(Index(muscles.size()));
  for (std::size_t k = 0; k < muscles.size(); ++k) {
    double s = 0;
    for (const auto& d : muscles[k].spec.drivers) {
      const auto it = std::find(names.begin(), names.end(), d.expression);
      if (it == names.end()) throw ArgumentError("muscle_activations: no expression '" + d.expression + "' (muscle '" + muscles[k].spec.name + "')");
      s += d.gain * weights[Index(it - names.begin())];
    }
    a[Index(k)] = std::clamp(s, 0.0, 1.0);
  }
  return a;
}

}  // namespace simsr::scenario
