#pragma once
/// \file
/// Per-vertex areas of a triangle mesh (lumped mass): mixed Voronoi (Meyer, Desbrun, Schröder &
/// Barr 2003, Fig. 4) and barycentric, and the diagonal mass matrix built from either.

#include <Eigen/SparseCore>

#include "../core/types.hpp"
#include "detail/elements.hpp"

namespace simsr {

/// Barycentric vertex areas: each triangle gives a third of its area to each corner.
/// V #V×3, F #F×3 → #V (sums to the total area).
template <class DV, class DF>
VecX<typename DV::Scalar> barycentric_areas(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F) {
  using S = typename DV::Scalar;
  detail::require_cols("barycentric_areas: V", V, 3);
  detail::require_cols("barycentric_areas: F", F, 3);
  VecX<S> A = VecX<S>::Zero(V.rows());
  for (Index f = 0; f < F.rows(); ++f) {
    const auto a = detail::point(V, F(f, 0));
    const S third = (detail::point(V, F(f, 1)) - a).cross(detail::point(V, F(f, 2)) - a).norm() / S(6);
    for (int c = 0; c < 3; ++c) A[F(f, c)] += third;
  }
  return A;
}

/// Mixed Voronoi vertex areas (Meyer et al. 2003): in a non-obtuse triangle each corner gets
/// its Voronoi region, ⅛(|e_ij|² cot γ_k + |e_ik|² cot γ_j); in an obtuse triangle the obtuse
/// corner gets ½ of the area and the other two ¼ each. V #V×3, F #F×3 → #V (sums to the total
/// area, every entry ≥ 0).
template <class DV, class DF>
VecX<typename DV::Scalar> voronoi_areas(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F) {
  using S = typename DV::Scalar;
  detail::require_cols("voronoi_areas: V", V, 3);
  detail::require_cols("voronoi_areas: F", F, 3);
  VecX<S> A = VecX<S>::Zero(V.rows());
  for (Index f = 0; f < F.rows(); ++f) {
    const Vec3<S> x[3] = {detail::point(V, F(f, 0)), detail::point(V, F(f, 1)), detail::point(V, F(f, 2))};
    const S area2 = (x[1] - x[0]).cross(x[2] - x[0]).norm();
    if (!(area2 > S(0))) continue;
    S dot[3];  // dot[c]: (x_{c+1} − x_c)·(x_{c+2} − x_c), negative at an obtuse corner
    for (int c = 0; c < 3; ++c) dot[c] = (x[(c + 1) % 3] - x[c]).dot(x[(c + 2) % 3] - x[c]);
    const int obtuse = dot[0] < 0 ? 0 : dot[1] < 0 ? 1 : dot[2] < 0 ? 2 : -1;
    for (int c = 0; c < 3; ++c) {
      const int j = (c + 1) % 3, k = (c + 2) % 3;
      S a;
      if (obtuse >= 0) {
        a = area2 / S(2) * (c == obtuse ? S(0.5) : S(0.25));
      } else {  // cot γ = dot / (2·area)
        a = ((x[j] - x[c]).squaredNorm() * dot[k] + (x[k] - x[c]).squaredNorm() * dot[j]) / area2 / S(8);
      }
      A[F(f, c)] += a;
    }
  }
  return A;
}

/// Which per-vertex area the lumped mass matrix uses.
enum class MassType { barycentric, voronoi };

/// Diagonal (lumped) mass matrix M (#V×#V) with M(i,i) = the vertex area of i.
template <class DV, class DF>
Eigen::SparseMatrix<typename DV::Scalar> mass_matrix(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F,
                                                     MassType type = MassType::voronoi) {
  using S = typename DV::Scalar;
  const VecX<S> a = type == MassType::voronoi ? voronoi_areas(V, F) : barycentric_areas(V, F);
  Eigen::SparseMatrix<S> M(V.rows(), V.rows());
  M.reserve(Eigen::VectorXi::Ones(V.rows()));
  for (Index i = 0; i < V.rows(); ++i) M.insert(i, i) = a[i];
  M.makeCompressed();
  return M;
}

}  // namespace simsr
