#pragma once
/// \file
/// The point of a triangle closest to a query point (Ericson, Real-Time Collision Detection
/// §5.1.5: the Voronoi regions of the vertices, edges and face), as barycentric weights.

#include <Eigen/Geometry>
#include <algorithm>

#include "../core/types.hpp"

namespace simsr {

namespace detail {

/// Parameter s ∈ [0, 1] of the point a + s(b − a) of segment ab closest to p (0 for a = b).
template <class S>
S closest_on_segment(const Vec3<S>& p, const Vec3<S>& a, const Vec3<S>& b) {
  const Vec3<S> ab = b - a;
  const S len2 = ab.squaredNorm();
  if (!(len2 > S(0))) return S(0);
  return std::clamp((p - a).dot(ab) / len2, S(0), S(1));
}

}  // namespace detail

/// Barycentric coordinates (of a, b, c) of the point of triangle abc closest to p; all ≥ 0, sum 1.
/// A degenerate triangle (collinear or coincident corners: its area below 1e-12 of its longest
/// edge squared) is the union of its edges, and the closest of their closest points is returned.
template <class S>
Vec3<S> closest_point_on_triangle(const Vec3<S>& p, const Vec3<S>& a, const Vec3<S>& b, const Vec3<S>& c) {
  const S longest2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  if (!((b - a).cross(c - a).norm() > S(1e-12) * longest2)) {
    const S s_ab = detail::closest_on_segment(p, a, b), s_bc = detail::closest_on_segment(p, b, c), s_ca = detail::closest_on_segment(p, c, a);
    const Vec3<S> w_ab(S(1) - s_ab, s_ab, S(0)), w_bc(S(0), S(1) - s_bc, s_bc), w_ca(s_ca, S(0), S(1) - s_ca);
    auto dist2 = [&](const Vec3<S>& w) { return (w[0] * a + w[1] * b + w[2] * c - p).squaredNorm(); };
    const S d_ab = dist2(w_ab), d_bc = dist2(w_bc), d_ca = dist2(w_ca);
    if (d_ab <= d_bc && d_ab <= d_ca) return w_ab;
    return d_bc <= d_ca ? w_bc : w_ca;
  }
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

}  // namespace simsr
