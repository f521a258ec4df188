#pragma once
/// \file
/// The EnergyTerm concept: one potential of a quasistatic problem (elasticity, springs, gravity,
/// contact). The solver minimizes the sum of the terms it is given, over the positions x (#V×3).
///
///     double e = term.energy(x);
///     term.add_gradient(x, g);        // g += ∂E/∂x, #V×3
///     term.add_hessian(x, H);         // H += a positive semi-definite approximation of ∂²E/∂x²
///
/// Terms are stateless between calls (they may own scratch buffers) and never throw on a
/// configuration the solver can reach (inverted elements included).

#include <concepts>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/types.hpp"

namespace simsr::physics {

/// 3×3 blocks (row vertex, column vertex, block) of a Hessian; duplicates are summed on assembly.
/// Terms that touch few vertices (springs, contact) add their blocks here.
template <class S = Scalar>
class BlockTriplets {
 public:
  void add(VIndex row, VIndex col, const Mat3<S>& block) {
    rows_.push_back(row);
    cols_.push_back(col);
    blocks_.push_back(block);
  }
  /// Adds the blocks of a dense (3n×3n) matrix over `vertices` (n of them), e.g. a 12×12 element Hessian.
  template <class D, class I>
  void add_dense(const I& vertices, const Eigen::MatrixBase<D>& H) {
    const Index n = Index(std::size(vertices));
    for (Index a = 0; a < n; ++a)
      for (Index b = 0; b < n; ++b) add(VIndex(vertices[std::size_t(a)]), VIndex(vertices[std::size_t(b)]), H.template block<3, 3>(3 * a, 3 * b));
  }
  void clear() {
    rows_.clear();
    cols_.clear();
    blocks_.clear();
  }
  Index size() const { return Index(rows_.size()); }
  VIndex row(Index k) const { return rows_[std::size_t(k)]; }
  VIndex col(Index k) const { return cols_[std::size_t(k)]; }
  const Mat3<S>& block(Index k) const { return blocks_[std::size_t(k)]; }

 private:
  std::vector<VIndex> rows_, cols_;
  std::vector<Mat3<S>, Eigen::aligned_allocator<Mat3<S>>> blocks_;
};

/// A potential the quasistatic solver can minimize (see the file comment).
template <class T, class S = Scalar>
concept EnergyTerm = requires(const T& t, const Points<S>& x, Points<S>& g, BlockTriplets<S>& h) {
  { t.energy(x) } -> std::convertible_to<S>;
  t.add_gradient(x, g);
  t.add_hessian(x, h);
};

namespace detail {
/// Throws ShapeError unless x is #V×3 with the expected vertex count.
template <class D>
void require_positions(const char* what, const Eigen::MatrixBase<D>& x, Index num_vertices) {
  if (x.rows() != num_vertices || x.cols() != 3) throw ShapeError(what, {num_vertices, 3}, {x.rows(), x.cols()});
}
}  // namespace detail

}  // namespace simsr::physics
