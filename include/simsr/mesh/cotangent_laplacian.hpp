#pragma once
/// \file
/// Cotangent Laplacian of a triangle mesh (Pinkall & Polthier 1993; libigl's cotmatrix).

#include <Eigen/SparseCore>
#include <vector>

#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "detail/elements.hpp"

namespace simsr {

/// Half cotangents of every triangle's angles: C(f, c) = ½ cot(angle at corner c), the weight of
/// the edge opposite corner c. 0 for a degenerate (zero-area) triangle. V #V×3, F #F×3 → #F×3.
template <exec::HostPolicy P, class DV, class DF>
Points<typename DV::Scalar> cotangent_weights(P policy, const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F) {
  using S = typename DV::Scalar;
  detail::require_cols("cotangent_weights: V", V, 3);
  detail::require_cols("cotangent_weights: F", F, 3);
  Points<S> C(F.rows(), 3);
  exec::parallel_for(policy, F.rows(), [&](Index f) {
    const Vec3<S> x[3] = {detail::point(V, F(f, 0)), detail::point(V, F(f, 1)), detail::point(V, F(f, 2))};
    const S area2 = (x[1] - x[0]).cross(x[2] - x[0]).norm();
    for (int c = 0; c < 3; ++c) {
      const Vec3<S> u = x[(c + 1) % 3] - x[c], v = x[(c + 2) % 3] - x[c];
      C(f, c) = area2 > S(0) ? u.dot(v) / area2 / S(2) : S(0);  // cot = cos/sin = u·v / |u×v|
    }
  });
  return C;
}

/// Cotangent Laplacian L (#V×#V, symmetric) of V #V×3, F #F×3, libigl's sign convention:
/// L(i,j) = ½(cot α_ij + cot β_ij) for each edge ij (α, β the angles opposite it), L(i,i) = −Σ_j L(i,j).
/// L is negative semi-definite, annihilates constants, and L·V = −∇(total area) (the mean
/// curvature normal integrated over each vertex's area, up to sign). Unlumped: divide by
/// voronoi_areas for a pointwise operator. Degenerate triangles contribute nothing.
template <exec::HostPolicy P, class DV, class DF>
Eigen::SparseMatrix<typename DV::Scalar> cotangent_laplacian(P policy, const Eigen::MatrixBase<DV>& V,
                                                             const Eigen::MatrixBase<DF>& F) {
  using S = typename DV::Scalar;
  const Points<S> C = cotangent_weights(policy, V, F);
  std::vector<Eigen::Triplet<S, Index>> trip;
  trip.reserve(static_cast<std::size_t>(12 * F.rows()));
  for (Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const Index i = F(f, (c + 1) % 3), j = F(f, (c + 2) % 3);
      const S w = C(f, c);
      trip.emplace_back(i, j, w);
      trip.emplace_back(j, i, w);
      trip.emplace_back(i, i, -w);
      trip.emplace_back(j, j, -w);
    }
  Eigen::SparseMatrix<S> L(V.rows(), V.rows());
  L.setFromTriplets(trip.begin(), trip.end());
  return L;
}

}  // namespace simsr
