#pragma once
/// \file
/// Triangle areas, unit face normals and vertex normals (area- or angle-weighted).

#include <cmath>

#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "detail/elements.hpp"

namespace simsr {

namespace detail {
/// (b−a)×(c−a) of triangle f: twice its area times its unit normal.
template <class DV, class DF>
Vec3<typename DV::Scalar> area_vector2(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F, Index f) {
  const auto a = point(V, F(f, 0));
  return (point(V, F(f, 1)) - a).cross(point(V, F(f, 2)) - a);
}
}  // namespace detail

/// Area of every triangle. V #V×3, F #F×3 → #F.
template <exec::HostPolicy P, class DV, class DF>
VecX<typename DV::Scalar> face_areas(P policy, const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F) {
  using S = typename DV::Scalar;
  detail::require_cols("face_areas: V", V, 3);
  detail::require_cols("face_areas: F", F, 3);
  VecX<S> A(F.rows());
  exec::parallel_for(policy, F.rows(), [&](Index f) { A[f] = detail::area_vector2(V, F, f).norm() / S(2); });
  return A;
}

/// Unit normal of every triangle, (v1−v0)×(v2−v0) normalized (right-hand rule: outward for
/// counter-clockwise faces); zero for a degenerate (zero-area) triangle. V #V×3, F #F×3 → #F×3.
template <exec::HostPolicy P, class DV, class DF>
Points<typename DV::Scalar> face_normals(P policy, const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F) {
  using S = typename DV::Scalar;
  detail::require_cols("face_normals: V", V, 3);
  detail::require_cols("face_normals: F", F, 3);
  Points<S> N(F.rows(), 3);
  exec::parallel_for(policy, F.rows(), [&](Index f) {
    const Vec3<S> n = detail::area_vector2(V, F, f);
    const S len = n.norm();
    N.row(f) = (len > S(0) ? Vec3<S>(n / len) : Vec3<S>::Zero()).transpose();
  });
  return N;
}

/// How the normals of the triangles around a vertex are averaged.
enum class NormalWeighting {
  uniform,  ///< every incident triangle counts once
  area,     ///< by triangle area (the sum of unnormalized cross products)
  angle,    ///< by the triangle's interior angle at the vertex (Thürmer & Wüthrich 1998)
};

/// Unit vertex normals: the weighted sum of the unit normals of the incident triangles,
/// normalized; zero for a vertex in no (non-degenerate) triangle. V #V×3, F #F×3 → #V×3.
template <class DV, class DF>
Points<typename DV::Scalar> vertex_normals(const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DF>& F,
                                           NormalWeighting weighting = NormalWeighting::angle) {
  using S = typename DV::Scalar;
  detail::require_cols("vertex_normals: V", V, 3);
  detail::require_cols("vertex_normals: F", F, 3);
  Points<S> N = Points<S>::Zero(V.rows(), 3);
  for (Index f = 0; f < F.rows(); ++f) {
    const Vec3<S> n2 = detail::area_vector2(V, F, f);
    const S len = n2.norm();
    if (!(len > S(0))) continue;
    const Vec3<S> n = n2 / len;
    for (int c = 0; c < 3; ++c) {
      S w = S(1);
      if (weighting == NormalWeighting::area) {
        w = len / S(2);
      } else if (weighting == NormalWeighting::angle) {
        const Vec3<S> p = detail::point(V, F(f, c));
        const Vec3<S> u = detail::point(V, F(f, (c + 1) % 3)) - p, v = detail::point(V, F(f, (c + 2) % 3)) - p;
        w = std::atan2(u.cross(v).norm(), u.dot(v));
      }
      N.row(F(f, c)) += w * n.transpose();
    }
  }
  for (Index v = 0; v < N.rows(); ++v) {
    const S len = N.row(v).norm();
    if (len > S(0)) N.row(v) /= len;
  }
  return N;
}

}  // namespace simsr
