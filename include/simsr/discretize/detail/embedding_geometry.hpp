#pragma once
/// \file
/// Geometry kernels of the barycentric embedding: closest point on a triangle (Ericson,
/// Real-Time Collision Detection §5.1.5), exact point–tetrahedron distance, point–box distance.

#include <algorithm>
#include <array>

#include <Eigen/Core>

#include "../../core/types.hpp"

namespace simsr::detail {

template <class S>
using Vec4 = Eigen::Matrix<S, 4, 1>;

/// Barycentric coordinates (of a, b, c) of the point of triangle abc closest to p; all ≥ 0, sum 1.
/// Works for degenerate triangles too (falls back to vertices/edges).
template <class S>
Vec3<S> closest_on_triangle(const Vec3<S>& p, const Vec3<S>& a, const Vec3<S>& b, const Vec3<S>& c) {
  const Vec3<S> ab = b - a, ac = c - a, ap = p - a;
  const S d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= S(0) && d2 <= S(0)) return {S(1), S(0), S(0)};
  const Vec3<S> bp = p - b;
  const S d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= S(0) && d4 <= d3) return {S(0), S(1), S(0)};
  const S vc = d1 * d4 - d3 * d2;
  if (vc <= S(0) && d1 >= S(0) && d3 <= S(0)) {
    const S v = d1 / (d1 - d3);
    return {S(1) - v, v, S(0)};
  }
  const Vec3<S> cp = p - c;
  const S d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= S(0) && d5 <= d6) return {S(0), S(0), S(1)};
  const S vb = d5 * d2 - d1 * d6;
  if (vb <= S(0) && d2 >= S(0) && d6 <= S(0)) {
    const S w = d2 / (d2 - d6);
    return {S(1) - w, S(0), w};
  }
  const S va = d3 * d6 - d5 * d4;
  if (va <= S(0) && (d4 - d3) >= S(0) && (d5 - d6) >= S(0)) {
    const S w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {S(0), S(1) - w, w};
  }
  const S denom = S(1) / (va + vb + vc);
  const S v = vb * denom, w = vc * denom;
  return {S(1) - v - w, v, w};
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
