#pragma once
/// \file
/// Penalty contact of embedded material points against an analytic rigid obstacle: the skin of an
/// LR lattice simulation, whose surface points live inside lattice tets (§5.3 of Park et al.
/// 2023: a sphere pushed into the cheek of the LR face). Point q is p_q = Σ_i w_qi x_{a_qi} (a
/// tet's 4 vertices with barycentric weights); with d the obstacle's signed distance:
///
///     E(x) = Σ_q k_q/2 min(d(p_q), 0)²                                  (J)
///     ∂E/∂x_{a_qi} = w_qi k_q d ∇d                                     (d < 0)
///     ∂²E/∂x_{a_qi}∂x_{a_qj} = w_qi w_qj k_q (∇d ∇dᵀ + d ∇²d)
///
/// The 3×3 block is PSD-projected as in ObstacleContact (obstacle_contact.hpp), so each point's
/// 12×12 block w wᵀ ⊗ B stays PSD. Contact on the lattice's own vertices would touch the obstacle
/// up to a cell away from the skin (lattice nodes lie outside it); embedded points touch where the
/// skin is.

#include <string>
#include <utility>
#include <vector>

#include "../../core/types.hpp"
#include "../../discretize/embedding.hpp"
#include "../energy_term.hpp"
#include "detail/checks.hpp"
#include "detail/embedded_points.hpp"
#include "obstacle_contact.hpp"

namespace simsr::physics {

/// Penalty contact of embedded points (anchors #Q×4, weights #Q×4, stiffness #Q in N/m) against
/// one obstacle O: ObstacleContact's per-point penalty (detail::obstacle_penalty_*) on
/// detail::EmbeddedPoints. Energy, gradient and Hessian run over the points in order (seq).
template <class O, class S = typename O::scalar_type>
  requires Obstacle<O, S>
class EmbeddedObstacleContact {
 public:
  using scalar_type = S;
  using Anchors = typename detail::EmbeddedPoints<S>::Anchors;
  using Weights = typename detail::EmbeddedPoints<S>::Weights;

  /// ArgumentError for an anchor outside [0, num_vertices), a non-finite weight, or a negative or
  /// non-finite stiffness; ShapeError for mismatched sizes.
  EmbeddedObstacleContact(O obstacle, Anchors anchors, Weights weights, Index num_vertices, VecX<S> stiffness)
      : EmbeddedObstacleContact(std::move(obstacle), detail::EmbeddedPoints<S>(who, std::move(anchors), std::move(weights), num_vertices), std::move(stiffness)) {}

  /// Every point of embedding e (in the tets T of a mesh with num_vertices vertices), stiffness k
  /// per point.
  EmbeddedObstacleContact(O obstacle, const Embedding<S>& e, const Tets& T, Index num_vertices, VecX<S> stiffness)
      : EmbeddedObstacleContact(std::move(obstacle), detail::EmbeddedPoints<S>::of(who, e, T, num_vertices), std::move(stiffness)) {}

  /// The points `rows` of embedding e only. ArgumentError for a row outside e.
  EmbeddedObstacleContact(O obstacle, const Embedding<S>& e, const Tets& T, Index num_vertices, const std::vector<Index>& rows, VecX<S> stiffness)
      : EmbeddedObstacleContact(std::move(obstacle), detail::EmbeddedPoints<S>::of(who, e, T, num_vertices, rows), std::move(stiffness)) {}

  O& obstacle() { return o_; }  ///< to move the obstacle between frames
  const O& obstacle() const { return o_; }
  /// The penalty's onset depth δ (m), as ObstacleContact::set_onset: 0 (the default) is C¹,
  /// δ > 0 ramps the stiffness over the first δ of depth (C²).
  void set_onset(S onset) {
    detail::require_nonnegative("EmbeddedObstacleContact: onset", onset);
    onset_ = onset;
  }
  S onset() const { return onset_; }
  Index num_points() const { return pts_.size(); }
  Index num_vertices() const { return pts_.num_vertices; }

  /// The points' current positions, #Q×3.
  Points<S> points(const Points<S>& x) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, num_vertices());
    return pts_.points(x);
  }
  /// How many points are inside the obstacle (d < 0) at x.
  Index num_active(const Points<S>& x) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, num_vertices());
    Index c = 0;
    for (Index q = 0; q < num_points(); ++q) c += o_.distance(pts_.point(x, q)) < S(0);
    return c;
  }

  template <exec::HostPolicy P>
  S energy(P, const Points<S>& x) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, num_vertices());
    S e = S(0);
    for (Index q = 0; q < num_points(); ++q) e += detail::obstacle_penalty_energy(o_, pts_.point(x, q), k_[q], onset_);
    return e;
  }

  template <exec::HostPolicy P>
  void add_gradient(P, const Points<S>& x, Points<S>& g) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, num_vertices());
    detail::require_positions("EmbeddedObstacleContact: gradient", g, num_vertices());
    Vec3<S> f;
    for (Index q = 0; q < num_points(); ++q)
      if (detail::obstacle_penalty_force(o_, pts_.point(x, q), k_[q], f, onset_)) pts_.add_force(g, q, f);
  }

  /// w_qi w_qj B_q with B_q the PSD-projected block of obstacle_contact.hpp (both Definiteness values).
  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>& H, Definiteness) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, num_vertices());
    Mat3<S> B;
    for (Index q = 0; q < num_points(); ++q)
      if (detail::obstacle_penalty_block(o_, pts_.point(x, q), k_[q], B, onset_)) pts_.add_block(H, q, B);
  }

 private:
  static constexpr const char* who = "EmbeddedObstacleContact";
  EmbeddedObstacleContact(O obstacle, detail::EmbeddedPoints<S> points, VecX<S> stiffness)
      : o_(std::move(obstacle)), pts_(std::move(points)), k_(std::move(stiffness)) {
    detail::require_nonnegative_each("EmbeddedObstacleContact: stiffness", k_, pts_.size());
  }

  O o_;
  detail::EmbeddedPoints<S> pts_;
  VecX<S> k_;
  S onset_ = S(0);
};

static_assert(assert_energy_term<EmbeddedObstacleContact<Sphere<double>>, double>());

}  // namespace simsr::physics
