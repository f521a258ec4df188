#pragma once
/// \file
/// Geometry kernels of the barycentric embedding: closest point on a triangle, exact
/// point–tetrahedron distance, point–box distance.

#include <algorithm>
#include <array>

#include <Eigen/Core>

#include "../../core/types.hpp"
#include "../../mesh/closest_point.hpp"

namespace simsr::detail {

template <class S>
using Vec4 = Eigen::Matrix<S, 4, 1>;

/// Barycentric coordinates of the point of triangle abc closest to p (mesh/closest_point.hpp).
template <class S>
Vec3<S> closest_on_triangle(const Vec3<S>& p, const Vec3<S>& a, const Vec3<S>& b, const Vec3<S>& c) {
  return closest_point_on_triangle(p, a, b, c);
}

/// Squared exact distance from p to the solid tetrahedron x[0..3], given p's barycentric weights
/// `w` in it. Zero when all weights are ≥ 0; otherwise the minimum over the faces p lies outside
/// of (w_i < 0 for the face opposite vertex i: on a convex polytope the closest boundary point
/// lies on such a face). `closest` receives the tet barycentrics of the closest point (≥ 0, sum 1).
template <class S>
S point_tet_sqdist(const Vec3<S>& p, const std::array<Vec3<S>, 4>& x, const Vec4<S>& w, Vec4<S>* closest = nullptr) {
  if ((w.array() >= S(0)).all()) {
    if (closest) *closest = w;
    return S(0);
  }
  static constexpr int face[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  S best = S(-1);
  for (int i = 0; i < 4; ++i) {
    if (!(w[i] < S(0))) continue;
    const int* f = face[i];
    const Vec3<S> u = closest_on_triangle(p, x[f[0]], x[f[1]], x[f[2]]);
    const Vec3<S> q = u[0] * x[f[0]] + u[1] * x[f[1]] + u[2] * x[f[2]];
    const S d2 = (p - q).squaredNorm();
    if (best < S(0) || d2 < best) {
      best = d2;
      if (closest) {
        closest->setZero();
        for (int k = 0; k < 3; ++k) (*closest)[f[k]] = u[k];
      }
    }
  }
  return best;
}

/// Squared distance from p to the axis-aligned box [lo, hi] (0 inside).
template <class S>
S point_box_sqdist(const Vec3<S>& p, const Vec3<S>& lo, const Vec3<S>& hi) {
  S d2 = S(0);
  for (int k = 0; k < 3; ++k) {
    const S e = std::max({lo[k] - p[k], S(0), p[k] - hi[k]});
    d2 += e * e;
  }
  return d2;
}

}  // namespace simsr::detail
