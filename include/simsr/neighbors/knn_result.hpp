#pragma once
/// \file
/// The result of every k-nearest-neighbour search in simsr::neighbors, and the argument checks
/// the searches share.

#include <cmath>
#include <string>

#include "../core/error.hpp"
#include "../core/types.hpp"

namespace simsr::neighbors {

/// k nearest neighbours of Q queries: `indices` Q×k (into the searched point set) and
/// `distances` Q×k (Euclidean or geodesic as the search says, not squared), both row-major;
/// each row is sorted by ascending distance, ties by ascending index.
template <class S = Scalar>
struct KnnResult {
  using scalar_type = S;
  using IndexMatrix = Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  using DistanceMatrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  IndexMatrix indices;       ///< Q×k neighbour indices
  DistanceMatrix distances;  ///< Q×k distances, ascending along each row

  Index queries() const { return indices.rows(); }
  Index k() const { return indices.cols(); }

  /// Sizes both matrices to q×k; allocates only when the shape changes.
  void resize(Index q, Index k) {
    if (indices.rows() != q || indices.cols() != k) indices.resize(q, k);
    if (distances.rows() != q || distances.cols() != k) distances.resize(q, k);
  }
};

namespace detail {

/// ArgumentError unless 1 ≤ k ≤ available (`available` = candidate neighbours per query).
inline void check_k(const char* where, Index k, Index available, const char* of_what = "points") {
  if (k < 1) throw ArgumentError(std::string(where) + ": k = " + std::to_string(k) + " must be at least 1");
  if (k > available)
    throw ArgumentError(std::string(where) + ": k = " + std::to_string(k) + " exceeds the " + std::to_string(available) +
                        " " + of_what + " available");
}

/// ShapeError unless M has `cols` columns.
template <class D>
void check_cols(const char* where, const char* what, const Eigen::MatrixBase<D>& M, Index cols) {
  if (M.cols() != cols) throw ShapeError(std::string(where) + ": " + what, {-1, cols}, {M.rows(), M.cols()});
}

/// ArgumentError naming the first row of M holding NaN or ±inf.
template <class D>
void check_finite_rows(const char* where, const char* what, const Eigen::MatrixBase<D>& M) {
  for (Index i = 0; i < M.rows(); ++i)
    for (Index j = 0; j < M.cols(); ++j)
      if (!std::isfinite(static_cast<double>(M(i, j))))
        throw ArgumentError(std::string(where) + ": " + what + " row " + std::to_string(i) + " holds a non-finite coordinate (column " +
                            std::to_string(j) + ")");
}

/// Lexicographic (distance, index) order: the tie rule of every search here.
template <class D>
constexpr bool closer(D da, VIndex ia, D db, VIndex ib) {
  return da < db || (da == db && ia < ib);
}

}  // namespace detail

}  // namespace simsr::neighbors
