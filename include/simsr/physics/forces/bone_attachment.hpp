#pragma once
/// \file
/// Bone attachments (SPEC §3, Park et al. 2023 §4): flesh vertices glued to a static cranium and a
/// jaw rotating about its hinge. They are Dirichlet constraints, not energies: the solver takes
/// the DirichletBoundary (dirichlet_boundary.hpp: sorted vertices and their prescribed positions) and
/// eliminates them.
///
///     physics::BoneAttachments<> bones(hr_rest.V);
///     bones.add_bone("cranium", cranium_vertices);
///     bones.add_bone("jaw", jaw_vertices);
///     bones.set_transform("jaw", physics::hinge_rotation(hinge_point, hinge_axis, jaw_angle));
///     physics::DirichletBoundary<> bc = bones.boundary();   // per frame

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "../dirichlet_boundary.hpp"
#include "detail/checks.hpp"

namespace simsr::physics {

/// x ↦ R x + t (R a rotation, t in m). Default: the identity.
template <class S = Scalar>
struct RigidTransform {
  Mat3<S> R = Mat3<S>::Identity();
  Vec3<S> t = Vec3<S>::Zero();

  static RigidTransform identity() { return {}; }
  Vec3<S> apply(const Vec3<S>& x) const { return R * x + t; }
  /// Transforms every row of P (#P×3).
  Points<S> apply(const Points<S>& P) const {
    Points<S> out = P * R.transpose();
    out.rowwise() += t.transpose();
    return out;
  }
  /// Composition: (a * b).apply(x) == a.apply(b.apply(x)).
  friend RigidTransform operator*(const RigidTransform& a, const RigidTransform& b) { return {a.R * b.R, a.R * b.t + a.t}; }
  RigidTransform inverse() const { return {R.transpose(), -(R.transpose() * t)}; }
};

/// Rotation by `angle` (radians, right-handed about the direction) about the axis through
/// `axis_point` along `axis_direction` (normalized here), e.g. the jaw hinge: points on the axis
/// stay fixed. The scalar type follows `angle`. Throws ArgumentError for a zero or non-finite direction, a non-finite point or angle.
template <class S>
RigidTransform<S> hinge_rotation(const Vec3<std::type_identity_t<S>>& axis_point, const Vec3<std::type_identity_t<S>>& axis_direction, S angle) {
  detail::require_finite_vector("hinge_rotation: axis point", axis_point);
  detail::require_finite_vector("hinge_rotation: axis direction", axis_direction);
  if (!std::isfinite(double(angle))) throw ArgumentError("hinge_rotation: angle is not finite");
  const S len = axis_direction.norm();
  if (!(len > S(0))) throw ArgumentError("hinge_rotation: axis direction is zero");
  RigidTransform<S> r;
  r.R = Eigen::AngleAxis<S>(angle, axis_direction / len).toRotationMatrix();
  r.t = axis_point - r.R * axis_point;
  return r;
}

/// Named rigid bones, each a set of attached vertices with their rest positions and a current
/// RigidTransform (identity until set: a static cranium never needs one). A vertex belongs to at
/// most one bone.
template <class S = Scalar>
class BoneAttachments {
 public:
  using scalar_type = S;

  /// `rest` (#V×3): the rest positions of the whole mesh. ArgumentError for a non-finite row.
  explicit BoneAttachments(Points<S> rest) : rest_(std::move(rest)), owner_(rest_.rows(), -1) {
    detail::require_finite_matrix("BoneAttachments: rest positions", rest_, -1, 3);
  }

  /// Adds a bone holding `vertices` (any order; duplicates merged) and returns its id. Throws
  /// ArgumentError for an empty or repeated name or a vertex out of range, MeshError("vertex", v)
  /// naming both bones for a vertex already attached to another bone.
  Index add_bone(const std::string& name, const IndexVector& vertices) {
    if (name.empty()) throw ArgumentError("BoneAttachments: bone name is empty");
    if (find(name) >= 0) throw ArgumentError("BoneAttachments: bone '" + name + "' exists already");
    detail::require_vertex_indices("BoneAttachments: vertices of bone '" + name + "'", vertices, num_vertices());
    std::vector<VIndex> v(vertices.data(), vertices.data() + vertices.size());
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    const Index id = num_bones();
    for (VIndex i : v)
      if (owner_[std::size_t(i)] >= 0)
        throw MeshError("vertex", i, "attached to both bone '" + bones_[std::size_t(owner_[std::size_t(i)])].name + "' and bone '" + name + "'");
    for (VIndex i : v) owner_[std::size_t(i)] = id;
    Bone b{name, IndexVector::Map(v.data(), Index(v.size())), {}};
    bones_.push_back(std::move(b));
    return id;
  }

  Index num_vertices() const { return rest_.rows(); }
  Index num_bones() const { return Index(bones_.size()); }
  /// Id of the bone called `name`, −1 if none.
  Index find(const std::string& name) const {
    for (std::size_t b = 0; b < bones_.size(); ++b)
      if (bones_[b].name == name) return Index(b);
    return -1;
  }
  const std::string& name(Index bone) const { return at(bone).name; }
  /// The bone's vertices, sorted and unique.
  const IndexVector& vertices(Index bone) const { return at(bone).vertices; }
  const IndexVector& vertices(const std::string& bone) const { return at(bone).vertices; }
  const RigidTransform<S>& transform(Index bone) const { return at(bone).transform; }
  const RigidTransform<S>& transform(const std::string& bone) const { return at(bone).transform; }
  /// Bone owning vertex v, −1 if free. ArgumentError for v outside [0, num_vertices).
  Index owner(Index v) const {
    if (v < 0 || v >= num_vertices()) throw ArgumentError("BoneAttachments: no vertex " + std::to_string(v) + " (have " + std::to_string(num_vertices()) + ")");
    return owner_[std::size_t(v)];
  }

  void set_transform(Index bone, const RigidTransform<S>& T) { at(bone).transform = checked(T); }
  void set_transform(const std::string& bone, const RigidTransform<S>& T) { at(bone).transform = checked(T); }

  /// The Dirichlet boundary under the current transforms: every attached vertex (sorted) and its
  /// transformed rest position.
  DirichletBoundary<S> boundary() const {
    DirichletBoundary<S> bc;
    Index n = 0;
    for (const Bone& b : bones_) n += b.vertices.size();
    bc.vertices.resize(n);
    bc.targets.resize(n, 3);
    Index k = 0;
    for (Index v = 0; v < num_vertices(); ++v) {
      const Index b = owner_[std::size_t(v)];
      if (b < 0) continue;
      bc.vertices[k] = VIndex(v);
      bc.targets.row(k++) = bones_[std::size_t(b)].transform.apply(Vec3<S>(rest_.row(v).transpose())).transpose();
    }
    return bc;
  }

 private:
  struct Bone {
    std::string name;
    IndexVector vertices;
    RigidTransform<S> transform;
  };
  const Bone& at(Index b) const {
    if (b < 0 || b >= num_bones()) throw ArgumentError("BoneAttachments: no bone " + std::to_string(b) + " (have " + std::to_string(num_bones()) + ")");
    return bones_[std::size_t(b)];
  }
  Bone& at(Index b) { return const_cast<Bone&>(std::as_const(*this).at(b)); }
  const Bone& at(const std::string& name) const {
    const Index b = find(name);
    if (b < 0) throw ArgumentError("BoneAttachments: no bone named '" + name + "'");
    return bones_[std::size_t(b)];
  }
  Bone& at(const std::string& name) { return const_cast<Bone&>(std::as_const(*this).at(name)); }
  static const RigidTransform<S>& checked(const RigidTransform<S>& T) {
    if (!T.R.allFinite() || !T.t.allFinite()) throw ArgumentError("BoneAttachments: transform has a non-finite entry");
    return T;
  }

  Points<S> rest_;
  std::vector<Index> owner_;
  std::vector<Bone> bones_;
};

/// Rows of `rest` (#V×3) whose position satisfies `pred(Vec3<S>)`, ascending: e.g. the clamped
/// end of a cantilever, `select_vertices(V, [](const Vec3<>& p) { return p.x() < 1e-9; })`.
template <class S, class Pred>
IndexVector select_vertices(const Points<S>& rest, Pred&& pred) {
  std::vector<VIndex> v;
  for (Index i = 0; i < rest.rows(); ++i)
    if (pred(Vec3<S>(rest.row(i).transpose()))) v.push_back(VIndex(i));
  return IndexVector::Map(v.data(), Index(v.size()));
}

}  // namespace simsr::physics
