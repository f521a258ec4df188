#pragma once
/// \file
/// Points embedded in a tet mesh, p_q = Σ_i w_qi x_{a_qi} (4 anchors and weights each; a mesh
/// vertex is anchors (v, v, v, v) with weights (1, 0, 0, 0)): the part that EmbeddedSprings and
/// EmbeddedObstacleContact share. The checks, the positions, and scattering one point's force
/// (∂E/∂x_{a_qi} = w_qi f) and its 3×3 block (w_qi w_qj B for the non-zero weights) onto its anchors.

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../../../core/error.hpp"
#include "../../../core/types.hpp"
#include "../../../discretize/embedding.hpp"
#include "../../hessian.hpp"
#include "checks.hpp"

namespace simsr::physics::detail {

template <class S>
struct EmbeddedPoints {
  using Anchors = Eigen::Matrix<VIndex, Eigen::Dynamic, 4, Eigen::RowMajor>;
  using Weights = Eigen::Matrix<S, Eigen::Dynamic, 4, Eigen::RowMajor>;

  Anchors anchors;
  Weights weights;
  Index num_vertices = 0;

  /// `who` names the owner in errors: ArgumentError for an anchor outside [0, num_vertices) or a
  /// non-finite weight, ShapeError for weights of another size.
  EmbeddedPoints(const std::string& who, Anchors a, Weights w, Index n) : anchors(std::move(a)), weights(std::move(w)), num_vertices(n) {
    require_vertex_indices(who + ": anchors", anchors, num_vertices);
    require_finite_matrix(who + ": weights", weights, anchors.rows(), 4);
  }

  /// Every point of embedding e (in the tets T of a mesh with n vertices), or only `rows` of it.
  /// ArgumentError for a tet id outside T or a row outside e, MeshError for a tet's vertex out of range.
  static EmbeddedPoints of(const std::string& who, const Embedding<S>& e, const Tets& T, Index n) {
    simsr::detail::embedding_check_tets(who.c_str(), e, T, n);
    Anchors a(e.size(), 4);
    for (Index q = 0; q < e.size(); ++q) a.row(q) = T.row(e.tet[q]);
    return EmbeddedPoints(who, std::move(a), e.weights, n);
  }
  static EmbeddedPoints of(const std::string& who, const Embedding<S>& e, const Tets& T, Index n, const std::vector<Index>& rows) {
    simsr::detail::embedding_check_tets(who.c_str(), e, T, n);
    Anchors a(Index(rows.size()), 4);
    Weights w(Index(rows.size()), 4);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      if (rows[r] < 0 || rows[r] >= e.size())
        throw ArgumentError(who + ": point " + std::to_string(rows[r]) + " outside the embedding's " + std::to_string(e.size()));
      a.row(Index(r)) = T.row(e.tet[rows[r]]);
      w.row(Index(r)) = e.weights.row(rows[r]);
    }
    return EmbeddedPoints(who, std::move(a), std::move(w), n);
  }

  Index size() const { return anchors.rows(); }

  Vec3<S> point(const Points<S>& x, Index q) const {
    Vec3<S> p = Vec3<S>::Zero();
    for (int i = 0; i < 4; ++i) p += weights(q, i) * x.row(anchors(q, i)).transpose();
    return p;
  }
  Points<S> points(const Points<S>& x) const {
    Points<S> p(size(), 3);
    for (Index q = 0; q < size(); ++q) p.row(q) = point(x, q).transpose();
    return p;
  }

  /// g.row(a_qi) += w_qi f: the gradient of a term whose derivative at point q is f.
  void add_force(Points<S>& g, Index q, const Vec3<S>& f) const {
    for (int i = 0; i < 4; ++i) g.row(anchors(q, i)) += weights(q, i) * f.transpose();
  }
  /// H(a_qi, a_qj) += w_qi w_qj B over the non-zero weights: the Hessian of a term whose second
  /// derivative at point q is B (PSD when B is).
  void add_block(BlockHessian<S>& H, Index q, const Mat3<S>& B) const {
    for (int i = 0; i < 4; ++i) {
      if (weights(q, i) == S(0)) continue;
      for (int j = 0; j < 4; ++j)
        if (weights(q, j) != S(0)) H.add(anchors(q, i), anchors(q, j), (weights(q, i) * weights(q, j)) * B);
    }
  }
};

}  // namespace simsr::physics::detail
