#pragma once
/// \file
/// A 3×3 block copy of a row-major CSR matrix (BSR: one column index per 3×3 block, the nine
/// values of a block contiguous), for the products y = A·x that dominate PCG with a multigrid
/// preconditioner. Why: a Newton Hessian of a tet mesh is made of 3×3 vertex blocks, so a scalar
/// CSR spends 4 bytes of column index on every 8-byte value; the block copy spends 4 on nine. The
/// product is memory-bound (on the 73k-tet face lattice the matrix is ~27 MB and every V-cycle
/// streams it twice), so fewer bytes are the speed-up. With `Value = float` the values take
/// 4 bytes too (the multigrid's smoothing and residual products, MultigridOptions::storage): the
/// products still sum in S.
///
/// The numbers: every row is summed over its stored columns in ascending order, the CSR row's
/// order, and the entries a block adds that the CSR did not store are exact zeros; whether the
/// compiler fuses a term's multiply and add (FMA) is its own choice per loop, so the product
/// agrees with sparse_multiply's to rounding (tested), not bitwise. Rows are summed by one worker
/// each: seq and omp agree bitwise.
///
///     physics::BlockCsr<double> B;
///     B.assign(exec::omp, A);          // pattern analysed once, values copied at every call
///     B.multiply(exec::omp, x, y);     // y = A x

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "../../core/error.hpp"
#include "../../core/host_device.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "sparse_ops.hpp"

namespace simsr::physics {

namespace detail {
/// The three sums of one block row.
template <class S>
struct BlockRowSum {
  S s0, s1, s2;
};

/// (block row b of A)·x, summed from zero one term at a time in column order (the file comment's
/// rounding): BlockCsrProduct's row, and the row product of the multigrid's Gauss–Seidel sweep.
/// The sums are locals returned by value: accumulators passed by reference may alias x (both S),
/// which forced a store after every term wherever the compiler kept the function out of line.
template <class S, class Value>
SIMSR_HOST_DEVICE inline BlockRowSum<S> block_row_sum(const int* outer, const int* inner, const Value* values, const S* x, Index b) {
  S s0 = 0, s1 = 0, s2 = 0;
  for (int k = outer[b]; k < outer[b + 1]; ++k) {
    const Value* a = values + 9 * std::size_t(k);
    const S* xb = x + 3 * std::size_t(inner[k]);
    const S x0 = xb[0], x1 = xb[1], x2 = xb[2];
    s0 += S(a[0]) * x0;
    s0 += S(a[1]) * x1;
    s0 += S(a[2]) * x2;
    s1 += S(a[3]) * x0;
    s1 += S(a[4]) * x1;
    s1 += S(a[5]) * x2;
    s2 += S(a[6]) * x0;
    s2 += S(a[7]) * x1;
    s2 += S(a[8]) * x2;
  }
  return {s0, s1, s2};
}

/// y(3b..3b+2) = Σ over block row b's blocks of A_bk · x(3k..3k+2): BlockCsr's product, one
/// functor for exec::seq, exec::omp (host arrays) and exec::cuda (DeviceBlockCsr's device arrays).
template <class S, class Value>
struct BlockCsrProduct {
  const int* outer;
  const int* inner;
  const Value* values;
  const S* x;
  S* y;
  SIMSR_HOST_DEVICE void operator()(Index b) const {
    const BlockRowSum<S> s = block_row_sum(outer, inner, values, x, b);
    y[3 * b] = s.s0;
    y[3 * b + 1] = s.s1;
    y[3 * b + 2] = s.s2;
  }
};
}  // namespace detail

/// The 3×3 block copy of a square-blocked CSR matrix (see the file comment). S: the scalar of
/// the source matrix and of the vectors; Value: how the block values are stored (S or float).
template <class S = Scalar, class Value = S>
class BlockCsr {
 public:
  using scalar_type = S;
  using value_type = Value;
  using Source = Eigen::SparseMatrix<S, Eigen::RowMajor, int>;

  /// Copies A's values into the blocks; the block pattern (and where each CSR entry lands) is
  /// rebuilt only when A's pattern differs from the last call's. ShapeError unless A's rows and
  /// columns are multiples of 3; ArgumentError for an uncompressed A.
  template <exec::HostPolicy P>
  void assign(P policy, const Source& A) {
    if (A.rows() % 3 || A.cols() % 3)
      throw ShapeError("BlockCsr: matrix (rows and columns multiples of 3)", {A.rows() / 3 * 3, A.cols() / 3 * 3}, {A.rows(), A.cols()});
    if (!A.isCompressed()) throw ArgumentError("BlockCsr: the matrix must be compressed");
    if (!source_.matches(A)) analyse(A);
    const S* src = A.valuePtr();
    const int* outer = A.outerIndexPtr();
    Value* dst = values_.data();
    const std::uint32_t* slot = slot_.data();
    // block row b owns CSR rows 3b..3b+2 and their slots: rows are written by one worker each
    exec::parallel_for(policy, block_rows_, [&](Index b) {
      for (int k = outer[3 * b]; k < outer[3 * b + 3]; ++k) dst[slot[k]] = Value(src[k]);
    });
  }

  /// y = A·x (the matrix of the last assign); x and y are S vectors, the sums in S.
  template <exec::HostPolicy P>
  void multiply(P policy, const VecX<S>& x, VecX<S>& y) const {
    if (x.size() != 3 * block_cols_) throw ShapeError("BlockCsr::multiply: x", {3 * block_cols_}, {x.size()});
    if (y.size() != 3 * block_rows_) y.resize(3 * block_rows_);
    exec::parallel_for(policy, block_rows_, detail::BlockCsrProduct<S, Value>{outer_.data(), inner_.data(), values_.data(), x.data(), y.data()});
  }

  /// The blocks: block row b holds blocks block_outer()[b] .. block_outer()[b+1] − 1, block k in
  /// block column block_inner()[k] with its nine values (row-major) at block_values() + 9k.
  const int* block_outer() const { return outer_.data(); }
  const int* block_inner() const { return inner_.data(); }
  const Value* block_values() const { return values_.data(); }
  Index rows() const { return 3 * block_rows_; }
  Index cols() const { return 3 * block_cols_; }
  Index num_blocks() const { return Index(inner_.size()); }
  /// Changes whenever assign() analysed a new block pattern (unique over all BlockCsr objects:
  /// what a colouring or ordering computed from the pattern is checked against).
  std::uint64_t pattern_version() const { return version_; }
  /// Bytes the product streams for the matrix (values and block indices).
  std::size_t matrix_bytes() const { return values_.size() * sizeof(Value) + (inner_.size() + outer_.size()) * sizeof(int); }
  /// Block (i, j) as a dense 3×3 (zero where none is stored), for checks.
  Mat3<S> block(Index i, Index j) const {
    Mat3<S> out = Mat3<S>::Zero();
    for (int k = outer_.at(std::size_t(i)); k < outer_.at(std::size_t(i) + 1); ++k)
      if (inner_[std::size_t(k)] == j)
        for (int e = 0; e < 9; ++e) out(e / 3, e % 3) = S(values_[9 * std::size_t(k) + std::size_t(e)]);
    return out;
  }

 private:
  /// The block pattern of A (every block holding at least one stored entry) and each CSR
  /// entry's slot in the block values. The slots no entry maps to stay zero.
  void analyse(const Source& A) {
    block_rows_ = A.rows() / 3;
    block_cols_ = A.cols() / 3;
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    outer_.assign(std::size_t(block_rows_) + 1, 0);
    inner_.clear();
    slot_.assign(std::size_t(A.nonZeros()), 0);
    std::vector<int> position(std::size_t(block_cols_), -1);  // block column → its block number in the current block row
    for (Index b = 0; b < block_rows_; ++b) {
      const std::size_t first = inner_.size();
      for (Index r = 3 * b; r < 3 * b + 3; ++r)
        for (int k = outer[r]; k < outer[r + 1]; ++k) {
          const int bc = inner[k] / 3;
          if (position[std::size_t(bc)] < 0) position[std::size_t(bc)] = 0, inner_.push_back(bc);
        }
      std::sort(inner_.begin() + std::ptrdiff_t(first), inner_.end());
      for (std::size_t q = first; q < inner_.size(); ++q) position[std::size_t(inner_[q])] = int(q);
      for (Index r = 3 * b; r < 3 * b + 3; ++r)
        for (int k = outer[r]; k < outer[r + 1]; ++k) {
          const std::size_t block = std::size_t(position[std::size_t(inner[k] / 3)]);
          slot_[std::size_t(k)] = std::uint32_t(9 * block + 3 * std::size_t(r - 3 * b) + std::size_t(inner[k] % 3));
        }
      for (std::size_t q = first; q < inner_.size(); ++q) position[std::size_t(inner_[q])] = -1;
      outer_[std::size_t(b) + 1] = int(inner_.size());
    }
    if (9 * inner_.size() > std::size_t(UINT32_MAX))
      throw ArgumentError("BlockCsr: " + std::to_string(inner_.size()) + " blocks are more than 32-bit slots can address");
    values_.assign(9 * inner_.size(), Value(0));
    source_.remember(A);
    static std::atomic<std::uint64_t> versions{0};
    version_ = ++versions;
  }

  Index block_rows_ = 0, block_cols_ = 0;
  std::vector<int> outer_, inner_;      ///< block rows' starts, block columns
  std::vector<Value> values_;           ///< 9 per block, row-major
  std::vector<std::uint32_t> slot_;     ///< CSR entry k → its index in values_
  detail::CsrPattern<int> source_;      ///< the pattern analysed (compared at every assign)
  std::uint64_t version_ = 0;           ///< pattern_version()
};

}  // namespace simsr::physics
