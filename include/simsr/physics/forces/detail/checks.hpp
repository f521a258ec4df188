#pragma once
/// \file
/// Construction-time input checks shared by the force terms: each throws the typed error of
/// core/error.hpp, naming the array, the entry and the offending value.

#include <cmath>
#include <string>

#include <Eigen/Core>

#include "../../../core/error.hpp"
#include "../../../core/types.hpp"

namespace simsr::physics::detail {

/// ArgumentError unless `value` is finite and ≥ 0.
template <class S>
void require_nonnegative(const std::string& what, S value) {
  if (!(std::isfinite(double(value)) && value >= S(0)))
    throw ArgumentError(what + " must be finite and non-negative, got " + std::to_string(double(value)));
}

/// ArgumentError unless `value` is finite and > 0.
template <class S>
void require_positive(const std::string& what, S value) {
  if (!(std::isfinite(double(value)) && value > S(0)))
    throw ArgumentError(what + " must be finite and positive, got " + std::to_string(double(value)));
}

/// ShapeError unless `v` has `n` entries; ArgumentError naming the first entry that is negative or not finite.
template <class D>
void require_nonnegative_each(const std::string& what, const Eigen::MatrixBase<D>& v, Index n) {
  if (v.size() != n) throw ShapeError(what, {n}, {v.size()});
  for (Index i = 0; i < n; ++i)
    if (!(std::isfinite(double(v(i))) && v(i) >= 0))
      throw ArgumentError(what + "[" + std::to_string(i) + "] must be finite and non-negative, got " + std::to_string(double(v(i))));
}

/// ShapeError unless `M` is rows×cols (rows < 0: any); ArgumentError naming the first row with a non-finite entry.
template <class D>
void require_finite_matrix(const std::string& what, const Eigen::MatrixBase<D>& M, Index rows, Index cols) {
  if ((rows >= 0 && M.rows() != rows) || M.cols() != cols) throw ShapeError(what, {rows, cols}, {M.rows(), M.cols()});
  for (Index i = 0; i < M.rows(); ++i)
    if (!M.row(i).allFinite()) throw ArgumentError(what + ": row " + std::to_string(i) + " has a non-finite entry");
}

/// ArgumentError unless `v` is finite.
template <class S>
void require_finite_vector(const std::string& what, const Vec3<S>& v) {
  if (!v.allFinite()) throw ArgumentError(what + " has a non-finite entry");
}

/// ArgumentError naming the first entry of the vertex list `idx` outside [0, num_vertices).
template <class D>
void require_vertex_indices(const std::string& what, const Eigen::MatrixBase<D>& idx, Index num_vertices) {
  for (Index r = 0; r < idx.rows(); ++r)
    for (Index c = 0; c < idx.cols(); ++c)
      if (idx(r, c) < 0 || idx(r, c) >= num_vertices)
        throw ArgumentError(what + ": entry (" + std::to_string(r) + ", " + std::to_string(c) + ") = " + std::to_string(idx(r, c)) +
                            " is not a vertex of a mesh with " + std::to_string(num_vertices));
}

/// MeshError naming the first tet of T (#T×4) with a vertex index outside [0, num_vertices).
inline void require_tets(const Tets& T, Index num_vertices) {
  for (Index t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      if (T(t, k) < 0 || T(t, k) >= num_vertices)
        throw MeshError("tet", t, "vertex index " + std::to_string(T(t, k)) + " outside [0, " + std::to_string(num_vertices) + ")");
}

}  // namespace simsr::physics::detail
