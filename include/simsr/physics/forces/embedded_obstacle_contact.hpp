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
#include "obstacle_contact.hpp"

namespace simsr::physics {

/// Penalty contact of embedded points (anchors #Q×4, weights #Q×4, stiffness #Q in N/m) against
/// one obstacle O. Energy, gradient and Hessian run over the points in order (seq).
template <class O, class S = typename O::scalar_type>
  requires Obstacle<O, S>
class EmbeddedObstacleContact {
 public:
  using scalar_type = S;
  using Anchors = Eigen::Matrix<VIndex, Eigen::Dynamic, 4, Eigen::RowMajor>;
  using Weights = Eigen::Matrix<S, Eigen::Dynamic, 4, Eigen::RowMajor>;

  /// ArgumentError for an anchor outside [0, num_vertices), a non-finite weight, or a negative or
  /// non-finite stiffness; ShapeError for mismatched sizes.
  EmbeddedObstacleContact(O obstacle, Anchors anchors, Weights weights, Index num_vertices, VecX<S> stiffness)
      : o_(std::move(obstacle)), a_(std::move(anchors)), w_(std::move(weights)), n_(num_vertices), k_(std::move(stiffness)) {
    detail::require_vertex_indices("EmbeddedObstacleContact: anchors", a_, n_);
    detail::require_finite_matrix("EmbeddedObstacleContact: weights", w_, a_.rows(), 4);
    detail::require_nonnegative_each("EmbeddedObstacleContact: stiffness", k_, a_.rows());
  }

  /// The points `rows` of embedding e (in the tets T of a mesh with num_vertices vertices), with
  /// stiffness k per point. ArgumentError for a row outside e.
  EmbeddedObstacleContact(O obstacle, const Embedding<S>& e, const Tets& T, Index num_vertices, const std::vector<Index>& rows, VecX<S> stiffness)
      : EmbeddedObstacleContact(std::move(obstacle), anchors_of(e, T, num_vertices, rows), weights_of(e, rows), num_vertices, std::move(stiffness)) {}

  O& obstacle() { return o_; }  ///< to move the obstacle between frames
  const O& obstacle() const { return o_; }
  Index num_points() const { return a_.rows(); }
  Index num_vertices() const { return n_; }

  /// The points' current positions, #Q×3.
  Points<S> points(const Points<S>& x) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, n_);
    Points<S> p(num_points(), 3);
    for (Index q = 0; q < num_points(); ++q) p.row(q) = point(x, q).transpose();
    return p;
  }
  /// How many points are inside the obstacle (d < 0) at x.
  Index num_active(const Points<S>& x) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, n_);
    Index c = 0;
    for (Index q = 0; q < num_points(); ++q) c += o_.distance(point(x, q)) < S(0);
    return c;
  }

  template <exec::HostPolicy P>
  S energy(P, const Points<S>& x) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, n_);
    S e = S(0);
    for (Index q = 0; q < num_points(); ++q) {
      const S d = o_.distance(point(x, q));
      if (d < S(0)) e += k_[q] / S(2) * d * d;
    }
    return e;
  }

  template <exec::HostPolicy P>
  void add_gradient(P, const Points<S>& x, Points<S>& g) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, n_);
    detail::require_positions("EmbeddedObstacleContact: gradient", g, n_);
    for (Index q = 0; q < num_points(); ++q) {
      const Vec3<S> p = point(x, q);
      const S d = o_.distance(p);
      if (!(d < S(0))) continue;
      const Vec3<S> f = (k_[q] * d) * o_.distance_gradient(p);
      for (int i = 0; i < 4; ++i) g.row(a_(q, i)) += w_(q, i) * f.transpose();
    }
  }

  /// w_qi w_qj k_q B_q with B_q the PSD-projected block of obstacle_contact.hpp (both
  /// Definiteness values).
  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>& H, Definiteness) const {
    detail::require_positions("EmbeddedObstacleContact: x", x, n_);
    for (Index q = 0; q < num_points(); ++q) {
      const Vec3<S> p = point(x, q);
      const S d = o_.distance(p);
      if (!(d < S(0))) continue;
      const Vec3<S> nrm = o_.distance_gradient(p);
      const Mat3<S> B = k_[q] * detail::project_psd3(Mat3<S>(nrm * nrm.transpose() + d * o_.distance_hessian(p)));
      for (int i = 0; i < 4; ++i) {
        if (w_(q, i) == S(0)) continue;
        for (int j = 0; j < 4; ++j)
          if (w_(q, j) != S(0)) H.add(a_(q, i), a_(q, j), (w_(q, i) * w_(q, j)) * B);
      }
    }
  }

 private:
  static void check_rows(const Embedding<S>& e, const std::vector<Index>& rows) {
    for (const Index r : rows)
      if (r < 0 || r >= e.size()) throw ArgumentError("EmbeddedObstacleContact: point " + std::to_string(r) + " outside the embedding's " + std::to_string(e.size()));
  }
  static Anchors anchors_of(const Embedding<S>& e, const Tets& T, Index num_vertices, const std::vector<Index>& rows) {
    simsr::detail::embedding_check_tets("EmbeddedObstacleContact", e, T, num_vertices);
    check_rows(e, rows);
    Anchors a(Index(rows.size()), 4);
    for (std::size_t r = 0; r < rows.size(); ++r) a.row(Index(r)) = T.row(e.tet[rows[r]]);
    return a;
  }
  static Weights weights_of(const Embedding<S>& e, const std::vector<Index>& rows) {
    check_rows(e, rows);  // (the arguments of the delegating constructor run in any order)
    Weights w(Index(rows.size()), 4);
    for (std::size_t r = 0; r < rows.size(); ++r) w.row(Index(r)) = e.weights.row(rows[r]);
    return w;
  }
  Vec3<S> point(const Points<S>& x, Index q) const {
    Vec3<S> p = Vec3<S>::Zero();
    for (int i = 0; i < 4; ++i) p += w_(q, i) * x.row(a_(q, i)).transpose();
    return p;
  }

  O o_;
  Anchors a_;
  Weights w_;
  Index n_;
  VecX<S> k_;
};

static_assert(assert_energy_term<EmbeddedObstacleContact<Sphere<double>>, double>());

}  // namespace simsr::physics
