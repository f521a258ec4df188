#pragma once
/// \file
/// Do two tetrahedra share interior volume? The separating-axis theorem for convex polyhedra
/// (Gottschalk et al. 1996, "OBBTree"; Eberly's "Intersection of convex objects"): two tets are
/// disjoint iff some axis among the 4 + 4 face normals and the 6 × 6 edge–edge cross products
/// separates their projections. An axis "separates" here when the projections overlap by no more
/// than `tolerance` (a length), so tets that only touch along a face, an edge or a vertex count
/// as disjoint: the test answers "positive-volume overlap", the question an embedded lattice asks
/// of the material it carries (discretize/material_split.hpp).
///
///     bool meet = simsr::tets_overlap(a, b, 1e-12 * h);   // a, b: 4 corners each

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>

#include "../core/types.hpp"

namespace simsr {

/// The 4 corners of a tetrahedron.
template <class S = Scalar>
using TetCorners = std::array<Vec3<S>, 4>;

namespace detail {

/// min and max of the corners' projections onto `axis`.
template <class S>
inline void project_tet(const TetCorners<S>& t, const Vec3<S>& axis, S& lo, S& hi) {
  lo = hi = t[0].dot(axis);
  for (int k = 1; k < 4; ++k) {
    const S p = t[k].dot(axis);
    lo = std::min(lo, p);
    hi = std::max(hi, p);
  }
}

/// True when `axis` (any length > 0) separates a and b up to `tolerance` (a length).
template <class S>
inline bool separates(const TetCorners<S>& a, const TetCorners<S>& b, const Vec3<S>& axis, S tolerance) {
  const S n = axis.norm();
  if (!(n > S(0))) return false;
  S alo, ahi, blo, bhi;
  project_tet(a, axis, alo, ahi);
  project_tet(b, axis, blo, bhi);
  const S tol = tolerance * n;
  return ahi <= blo + tol || bhi <= alo + tol;
}

}  // namespace detail

/// True when tets a and b overlap in a set of positive volume (see the file comment): the
/// separating axes are tried in the order face normals, then edge pairs. Degenerate tets (zero
/// volume) never overlap anything. Exact up to `tolerance` and floating-point rounding.
template <class S>
bool tets_overlap(const TetCorners<S>& a, const TetCorners<S>& b, S tolerance = S(0)) {
  static constexpr int edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  static constexpr int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  // bounding boxes first: the cheapest separating axes
  for (int d = 0; d < 3; ++d) {
    Vec3<S> axis = Vec3<S>::Zero();
    axis[d] = S(1);
    if (detail::separates(a, b, axis, tolerance)) return false;
  }
  for (const TetCorners<S>* t : {&a, &b}) {
    const Vec3<S> e1 = (*t)[1] - (*t)[0], e2 = (*t)[2] - (*t)[0], e3 = (*t)[3] - (*t)[0];
    if (!(std::abs(e1.dot(e2.cross(e3))) > S(0))) return false;  // no volume, no overlap
    for (const auto& f : face) {
      const Vec3<S> n = ((*t)[f[1]] - (*t)[f[0]]).cross((*t)[f[2]] - (*t)[f[0]]);
      if (detail::separates(a, b, n, tolerance)) return false;
    }
  }
  for (const auto& ea : edge) {
    const Vec3<S> da = a[ea[1]] - a[ea[0]];
    for (const auto& eb : edge) {
      const Vec3<S> axis = da.cross(b[eb[1]] - b[eb[0]]);
      // nearly parallel edges give no new axis (their cross product is round-off)
      if (axis.squaredNorm() <= S(1e-24) * da.squaredNorm() * (b[eb[1]] - b[eb[0]]).squaredNorm()) continue;
      if (detail::separates(a, b, axis, tolerance)) return false;
    }
  }
  return true;
}

}  // namespace simsr
