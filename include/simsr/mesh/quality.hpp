#pragma once
/// \file
/// Shape quality of tets and triangles: the normalized mean ratio (Liu & Joe 1994), 1 for a
/// regular element, → 0 as it flattens, scale- and rotation-invariant.

#include <cmath>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "detail/elements.hpp"

namespace simsr {

namespace detail {
/// Signed mean ratio of a tet: 12·(3|vol|)^⅔ / Σ edge², carrying the sign of the volume.
template <class S>
S tet_mean_ratio(const Vec3<S>& a, const Vec3<S>& b, const Vec3<S>& c, const Vec3<S>& d) {
  const S vol = tet_volume6(a, b, c, d) / S(6);
  const S l2 = (b - a).squaredNorm() + (c - a).squaredNorm() + (d - a).squaredNorm() + (c - b).squaredNorm() +
               (d - b).squaredNorm() + (d - c).squaredNorm();
  if (!(l2 > S(0))) return S(0);
  const S q = S(12) * std::cbrt(S(9) * vol * vol) / l2;
  return vol < S(0) ? -q : q;
}

/// Mean ratio of a triangle: 4√3·area / Σ edge² ∈ [0, 1].
template <class S>
S triangle_mean_ratio(const Vec3<S>& a, const Vec3<S>& b, const Vec3<S>& c) {
  const S l2 = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  if (!(l2 > S(0))) return S(0);
  return S(2) * std::sqrt(S(3)) * (b - a).cross(c - a).norm() / l2;
}
}  // namespace detail

/// Quality of every element of E: for tets (#T×4) the signed mean ratio ∈ [−1, 1] — 1 regular,
/// → 0 flat, < 0 inverted (negative volume); for triangles (#F×3) the mean ratio ∈ [0, 1].
/// V #V×3 → #E. Throws ShapeError when E has neither 3 nor 4 columns.
template <exec::HostPolicy P, class DV, class DE>
VecX<typename DV::Scalar> element_quality(P policy, const Eigen::MatrixBase<DV>& V, const Eigen::MatrixBase<DE>& E) {
  using S = typename DV::Scalar;
  detail::require_cols("element_quality: V", V, 3);
  detail::require_cols_between("element_quality: elements", E, 3, 4);
  VecX<S> q(E.rows());
  if (E.cols() == 4) {
    exec::parallel_for(policy, E.rows(), [&](Index t) {
      q[t] = detail::tet_mean_ratio(detail::point(V, E(t, 0)), detail::point(V, E(t, 1)), detail::point(V, E(t, 2)),
                                    detail::point(V, E(t, 3)));
    });
  } else {
    exec::parallel_for(policy, E.rows(), [&](Index f) {
      q[f] = detail::triangle_mean_ratio(detail::point(V, E(f, 0)), detail::point(V, E(f, 1)), detail::point(V, E(f, 2)));
    });
  }
  return q;
}

}  // namespace simsr
