#pragma once
/// \file
/// Zero-length springs from embedded material points to kinematic targets (SPEC §3 track springs,
/// Cong et al. 2016 "Art-directed muscle simulation for high-end facial animation", §4 of Park
/// et al. 2023): spring s ties the point Σ_i w_si x_{a_si} (a tet's 4 vertices with barycentric
/// weights, or one vertex with weight 1) to the target y_s with stiffness k_s (N/m):
///
///     E(x) = Σ_s k_s/2 ‖Σ_i w_si x_{a_si} − y_s‖²           (J)
///
///     auto emb = simsr::embed(exec::omp, lr_rest, hr_surface.V);                    // HR skin in the LR mesh
///     auto springs = physics::track_springs(exec::omp, emb, lr_rest, hr_surface, 1e4);  // κ = 1e4 N/m³
///     springs.set_targets(blendshape_positions);                         // each frame, #Q×3
///
/// The Hessian, (w_s w_sᵀ ⊗ I₃) k_s per spring, is exact and positive semi-definite.

#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/types.hpp"
#include "../../discretize/embedding.hpp"
#include "../../mesh/tet_mesh.hpp"
#include "../../mesh/tri_mesh.hpp"
#include "../../mesh/vertex_areas.hpp"
#include "../energy_term.hpp"
#include "detail/checks.hpp"
#include "detail/embedded_points.hpp"

namespace simsr::physics {

/// Zero-length springs from points embedded in a mesh (4 vertices and weights each) to targets.
/// Anchors #Q×4 vertex indices, weights #Q×4 (unitless, usually barycentric: sum 1), stiffness #Q
/// (N/m), targets #Q×3 (m). Energy, gradient and Hessian run over the springs in order (seq).
template <class S = Scalar>
class EmbeddedSprings {
 public:
  using scalar_type = S;
  using Anchors = typename detail::EmbeddedPoints<S>::Anchors;
  using Weights = typename detail::EmbeddedPoints<S>::Weights;

  /// The general form: spring s pulls Σ_i weights(s,i) x[anchors(s,i)] towards targets.row(s).
  /// Throws ShapeError for mismatched sizes, ArgumentError for an anchor outside
  /// [0, num_vertices), a non-finite weight or target, or a negative or non-finite stiffness.
  EmbeddedSprings(Anchors anchors, Weights weights, Index num_vertices, VecX<S> stiffness, Points<S> targets)
      : EmbeddedSprings(detail::EmbeddedPoints<S>("EmbeddedSprings", std::move(anchors), std::move(weights), num_vertices), std::move(stiffness),
                        std::move(targets)) {}

  /// Springs from the points of an embedding in the tets T of a mesh with `num_vertices` vertices
  /// (anchors = T's vertices of each point's tet, weights = its barycentric weights).
  /// Throws ArgumentError for a tet id outside T, MeshError for a tet whose vertex is out of range.
  EmbeddedSprings(const Embedding<S>& e, const Tets& T, Index num_vertices, VecX<S> stiffness, Points<S> targets)
      : EmbeddedSprings(detail::EmbeddedPoints<S>::of("EmbeddedSprings", e, T, num_vertices), std::move(stiffness), std::move(targets)) {}

  /// Springs on the points `rows` of embedding e only (ArgumentError for a row outside e).
  EmbeddedSprings(const Embedding<S>& e, const Tets& T, Index num_vertices, const std::vector<Index>& rows, VecX<S> stiffness, Points<S> targets)
      : EmbeddedSprings(detail::EmbeddedPoints<S>::of("EmbeddedSprings", e, T, num_vertices, rows), std::move(stiffness), std::move(targets)) {}

  Index num_springs() const { return pts_.size(); }
  Index num_vertices() const { return pts_.num_vertices; }
  const Anchors& anchors() const { return pts_.anchors; }
  const Weights& weights() const { return pts_.weights; }
  const VecX<S>& stiffness() const { return k_; }  ///< #Q, N/m
  const Points<S>& targets() const { return y_; }   ///< #Q×3, m

  /// Replaces the targets (once per frame). ShapeError unless #Q×3; ArgumentError for a non-finite row.
  template <class D>
  void set_targets(const Eigen::MatrixBase<D>& targets) {
    detail::require_finite_matrix("EmbeddedSprings: targets", targets, num_springs(), 3);
    y_ = targets.template cast<S>();
  }
  /// Replaces the stiffnesses (#Q, N/m, each finite and ≥ 0).
  void set_stiffness(VecX<S> k) {
    detail::require_nonnegative_each("EmbeddedSprings: stiffness", k, num_springs());
    k_ = std::move(k);
  }

  /// Current positions of the anchored points, Σ_i w_si x_{a_si}: #Q×3.
  Points<S> points(const Points<S>& x) const {
    detail::require_positions("EmbeddedSprings: x", x, num_vertices());
    return pts_.points(x);
  }

  /// Σ_s k_s/2 ‖residual‖² (J), over the springs in order (the policy is taken for the EnergyTerm form).
  template <exec::HostPolicy P>
  S energy(P, const Points<S>& x) const {
    detail::require_positions("EmbeddedSprings: x", x, num_vertices());
    S e = S(0);
    for (Index s = 0; s < num_springs(); ++s) e += k_[s] / S(2) * residual(x, s).squaredNorm();
    return e;
  }

  template <exec::HostPolicy P>
  void add_gradient(P, const Points<S>& x, Points<S>& g) const {
    detail::require_positions("EmbeddedSprings: x", x, num_vertices());
    detail::require_positions("EmbeddedSprings: gradient", g, num_vertices());
    for (Index s = 0; s < num_springs(); ++s) pts_.add_force(g, s, k_[s] * residual(x, s));
  }

  /// Adds k_s w_si w_sj I₃ for every pair of non-zero weights (exact and PSD: the same for both
  /// Definiteness values).
  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>& H, Definiteness) const {
    detail::require_positions("EmbeddedSprings: x", x, num_vertices());
    for (Index s = 0; s < num_springs(); ++s) pts_.add_block(H, s, k_[s] * Mat3<S>::Identity());
  }

 private:
  EmbeddedSprings(detail::EmbeddedPoints<S> points, VecX<S> stiffness, Points<S> targets) : pts_(std::move(points)) {
    set_stiffness(std::move(stiffness));
    set_targets(targets);
  }
  Vec3<S> residual(const Points<S>& x, Index s) const { return pts_.point(x, s) - y_.row(s).transpose(); }

  detail::EmbeddedPoints<S> pts_;
  VecX<S> k_;
  Points<S> y_;
};

static_assert(assert_energy_term<EmbeddedSprings<double>, double>());

/// Track springs (Cong 2016 directability): one spring per embedded surface point, k_s =
/// stiffness_per_area (N/m³) × areas[s] (m², the surface area point s stands for), so meshes of
/// any resolution pull alike in bulk (total stiffness = κ × surface area). Targets start at the
/// points' rest positions (zero energy at rest, computed under `policy`); `mesh` is the rest mesh
/// the points are embedded in.
template <exec::HostPolicy P, class S>
EmbeddedSprings<S> track_springs(P policy, const Embedding<S>& e, const TetMesh<S>& mesh, const VecX<std::type_identity_t<S>>& areas,
                                 std::type_identity_t<S> stiffness_per_area) {
  detail::require_nonnegative("track_springs: stiffness per area", stiffness_per_area);
  detail::require_nonnegative_each("track_springs: areas", areas, e.size());
  return EmbeddedSprings<S>(e, mesh.T, mesh.num_vertices(), VecX<S>(stiffness_per_area * areas), deform(policy, e, mesh.T, mesh.V));
}

/// Track springs on the vertices of `surface` (embedded as `e`, one point per surface vertex), with
/// areas = mixed Voronoi (default) or barycentric vertex areas of the surface (simsr::vertex_areas).
template <exec::HostPolicy P, class S>
EmbeddedSprings<S> track_springs(P policy, const Embedding<S>& e, const TetMesh<S>& mesh, const TriMesh<S>& surface,
                                 std::type_identity_t<S> stiffness_per_area, MassType areas = MassType::voronoi) {
  if (surface.num_vertices() != e.size())
    throw ShapeError("track_springs: surface vertices (one per embedded point)", {e.size(), 3}, {surface.V.rows(), surface.V.cols()});
  detail::require_vertex_indices("track_springs: surface triangles", surface.F, surface.num_vertices());
  const VecX<S> a = areas == MassType::voronoi ? voronoi_areas(surface.V, surface.F) : barycentric_areas(surface.V, surface.F);
  return track_springs(policy, e, mesh, a, stiffness_per_area);
}

/// Springs of stiffness k (N/m) on a few arbitrary rest points (#P×3, e.g. a lip corner), embedded
/// in `mesh` under `policy` (points outside it get extrapolated weights of the nearest tet). Targets
/// start at the points themselves; move them with set_targets.
template <exec::HostPolicy P, class S, class DP>
EmbeddedSprings<S> point_springs(P policy, const TetMesh<S>& mesh, const Eigen::MatrixBase<DP>& points, std::type_identity_t<S> k) {
  detail::require_nonnegative("point_springs: stiffness", k);
  const Points<S> p = points.template cast<S>();
  const Embedding<S> e = embed(policy, mesh, p);
  return EmbeddedSprings<S>(e, mesh.T, mesh.num_vertices(), VecX<S>::Constant(e.size(), k), p);
}

/// Springs of stiffness k (N/m) on mesh vertices directly (weight 1 on one vertex each); targets
/// start at the vertices' rest positions rest.row(v). `rest` is #V×3.
template <class S>
EmbeddedSprings<S> vertex_springs(const Points<S>& rest, const IndexVector& vertices, std::type_identity_t<S> k) {
  detail::require_nonnegative("vertex_springs: stiffness", k);
  detail::require_vertex_indices("vertex_springs: vertices", vertices, rest.rows());
  const Index q = vertices.size();
  typename EmbeddedSprings<S>::Anchors a(q, 4);
  typename EmbeddedSprings<S>::Weights w = EmbeddedSprings<S>::Weights::Zero(q, 4);
  Points<S> y(q, 3);
  for (Index s = 0; s < q; ++s) {
    a.row(s).setConstant(vertices[s]);
    w(s, 0) = S(1);
    y.row(s) = rest.row(vertices[s]);
  }
  return EmbeddedSprings<S>(std::move(a), std::move(w), rest.rows(), VecX<S>::Constant(q, k), std::move(y));
}

}  // namespace simsr::physics
