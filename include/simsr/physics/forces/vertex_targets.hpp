#pragma once
/// \file
/// SoftDECA's soft Dirichlet and fitting-distance energies (softdeca supplement eqs. 4 and 5) as
/// one EnergyTerm over chosen vertices v_k, each with a target point s_k, a distance d_k ≥ 0 and a
/// weight w_k:
///
///     E(x) = Σ_k w_k (‖x_{v_k} − s_k‖ − d_k)²          (J; w_k in J/m², e.g. stiffness × area)
///
/// d ≡ 0 is E_tar = Σ w ‖x − s_x‖² (attraction to the target expression's skin); d > 0 is E_dist2
/// (each vertex kept at its predicted distance d_x from s_x). Both are projective-dynamics
/// energies: (‖x − s‖ − d)² = ‖x − p‖² with p = s + d (x − s)/‖x − s‖ the nearest point of the
/// sphere of radius d around s, so the term's constant matrix is 2w_k I per vertex.
///
///     auto tar  = physics::VertexTargets<>::attraction(num_vertices, skin, expression, weights);
///     physics::VertexTargets<> dist(num_vertices, skin, anchors, distances, weights);
///
/// Exact Hessian per vertex: 2w [r̂r̂ᵀ + (1 − d/‖r‖)(I − r̂r̂ᵀ)], r = x − s; indefinite inside the
/// sphere (‖r‖ < d), where Definiteness::project clamps the tangential part at 0. At r = 0 with
/// d > 0 (the cone point, where E has no gradient) gradient and Hessian are taken as 0.

#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../energy_term.hpp"
#include "detail/checks.hpp"

namespace simsr::physics {

/// Σ_k w_k (‖x_{v_k} − s_k‖ − d_k)² (see the file comment).
template <class S = Scalar>
class VertexTargets {
 public:
  using scalar_type = S;

  /// `vertices` (#K) into a mesh of `num_vertices`, `targets` #K×3 (m), `distances` #K (m, ≥ 0),
  /// `weights` #K (J/m², ≥ 0). ShapeError for a size mismatch, ArgumentError naming the first bad
  /// vertex index, non-finite target or negative/non-finite distance or weight.
  VertexTargets(Index num_vertices, IndexVector vertices, Points<S> targets, VecX<S> distances, VecX<S> weights)
      : n_(num_vertices), v_(std::move(vertices)) {
    detail::require_vertex_indices("VertexTargets: vertices", v_, n_);
    set_targets(std::move(targets));
    set_distances(std::move(distances));
    set_weights(std::move(weights));
  }

  /// E_tar: every distance 0.
  static VertexTargets attraction(Index num_vertices, IndexVector vertices, Points<S> targets, VecX<S> weights) {
    const Index k = vertices.size();
    return VertexTargets(num_vertices, std::move(vertices), std::move(targets), VecX<S>::Zero(k), std::move(weights));
  }

  Index num_vertices() const { return n_; }
  Index size() const { return v_.size(); }
  const IndexVector& vertices() const { return v_; }
  const Points<S>& targets() const { return s_; }
  const VecX<S>& distances() const { return d_; }
  const VecX<S>& weights() const { return w_; }

  void set_targets(Points<S> targets) {
    detail::require_finite_matrix("VertexTargets: targets", targets, v_.size(), 3);
    s_ = std::move(targets);
  }
  void set_distances(VecX<S> distances) {
    detail::require_nonnegative_each("VertexTargets: distances", distances, v_.size());
    d_ = std::move(distances);
  }
  /// Weights change the local–global solver's matrix: refactor it (LocalGlobalSolver::invalidate).
  void set_weights(VecX<S> weights) {
    detail::require_nonnegative_each("VertexTargets: weights", weights, v_.size());
    w_ = std::move(weights);
  }

  /// The nearest point of vertex k's sphere to x (projective dynamics' local step).
  Vec3<S> project(const Points<S>& x, Index k) const {
    const Vec3<S> s = s_.row(k).transpose();
    const Vec3<S> r = x.row(v_[k]).transpose() - s;
    const S len = r.norm();
    return len > S(0) ? Vec3<S>(s + (d_[k] / len) * r) : s;
  }

  template <exec::HostPolicy P>
  S energy(P policy, const Points<S>& x) const {
    physics::detail::require_positions("VertexTargets::energy: x", x, n_);
    return exec::parallel_reduce(
        policy, size(), S(0),
        [&](Index k) {
          const S e = (x.row(v_[k]) - s_.row(k)).norm() - d_[k];
          return w_[k] * e * e;
        },
        [](S a, S b) { return a + b; });
  }

  /// g += 2w (x − p) per vertex (a vertex listed twice gets both; sequential accumulation then).
  template <exec::HostPolicy P>
  void add_gradient(P, const Points<S>& x, Points<S>& g) const {
    physics::detail::require_positions("VertexTargets::add_gradient: x", x, n_);
    physics::detail::require_positions("VertexTargets::add_gradient: g", g, n_);
    for (Index k = 0; k < size(); ++k) {
      const Vec3<S> r = x.row(v_[k]).transpose() - s_.row(k).transpose();
      const S len = r.norm();
      if (len > S(0)) g.row(v_[k]) += (S(2) * w_[k] * (S(1) - d_[k] / len)) * r.transpose();
    }
  }

  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>& H, Definiteness d) const {
    physics::detail::require_positions("VertexTargets::add_hessian: x", x, n_);
    for (Index k = 0; k < size(); ++k) {
      const Vec3<S> r = x.row(v_[k]).transpose() - s_.row(k).transpose();
      const S len = r.norm();
      Mat3<S> h;
      if (d_[k] == S(0)) {
        h = S(2) * w_[k] * Mat3<S>::Identity();
      } else if (len > S(0)) {
        const Vec3<S> u = r / len;
        S tangential = S(1) - d_[k] / len;
        if (d == Definiteness::project) tangential = std::max(tangential, S(0));
        h = S(2) * w_[k] * (u * u.transpose() + tangential * (Mat3<S>::Identity() - u * u.transpose()));
      } else {
        h.setZero();
      }
      H.add(v_[k], v_[k], h);
    }
  }

  /// The local–global solver's constant matrix: 2w_k I on vertex v_k's diagonal block.
  template <exec::HostPolicy P>
  void add_global_matrix(P, BlockHessian<S>& L) const {
    for (Index k = 0; k < size(); ++k) L.add(v_[k], v_[k], S(2) * w_[k] * Mat3<S>::Identity());
  }

 private:
  Index n_ = 0;
  IndexVector v_;
  Points<S> s_;
  VecX<S> d_, w_;
};

static_assert(assert_energy_term<VertexTargets<double>, double>());

}  // namespace simsr::physics
