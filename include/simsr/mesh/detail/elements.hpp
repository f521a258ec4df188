#pragma once
/// \file
/// Shared helpers of the mesh area: shape checks, element names and per-element geometry kernels.

#include <cmath>
#include <cstdint>
#include <string>

#include <Eigen/Geometry>

#include "../../core/error.hpp"
#include "../../core/types.hpp"

namespace simsr::detail {

/// Name of an element with `corners` vertices, as MeshError's `kind`.
inline const char* element_kind(Index corners) {
  switch (corners) {
    case 2: return "edge";
    case 3: return "triangle";
    case 4: return "tet";
    default: return "element";
  }
}

/// Throws ShapeError unless `M` has exactly `cols` columns.
template <class D>
void require_cols(const std::string& what, const Eigen::MatrixBase<D>& M, Index cols) {
  if (M.cols() != cols) throw ShapeError(what, {-1, cols}, {M.rows(), M.cols()});
}

/// Throws ShapeError unless `E` has between `lo` and `hi` columns.
template <class D>
void require_cols_between(const std::string& what, const Eigen::MatrixBase<D>& E, Index lo, Index hi) {
  if (E.cols() < lo || E.cols() > hi) throw ShapeError(what, {-1, E.cols() < lo ? lo : hi}, {E.rows(), E.cols()});
}

/// Row `i` of a #V×3 matrix as a 3-vector.
template <class D>
Vec3<typename D::Scalar> point(const Eigen::MatrixBase<D>& V, Index i) {
  return Vec3<typename D::Scalar>(V(i, 0), V(i, 1), V(i, 2));
}

/// Six times the signed volume of (a, b, c, d): (b−a)·((c−a)×(d−a)).
template <class S>
S tet_volume6(const Vec3<S>& a, const Vec3<S>& b, const Vec3<S>& c, const Vec3<S>& d) {
  return (b - a).dot((c - a).cross(d - a));
}

/// Packs an ordered pair of non-negative indices into one sortable key.
inline std::uint64_t pair_key(VIndex a, VIndex b) {
  return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint64_t(std::uint32_t(b));
}

}  // namespace simsr::detail
