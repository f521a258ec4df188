#pragma once
/// \file
/// Single-threaded GEMM on raw row-major buffers: the block products of the feature kNN
/// (neighbors::BruteForceKnn's blocked-GEMM kernel) and of the network layers' backward (nn::Linear;
/// their forward products go through PackedGemm, packed_gemm.hpp).

#include <Eigen/Core>
#include <memory>

#include "eigen_threads.hpp"
#include "types.hpp"

namespace simsr {

/// C (+)= op(A)·op(B) on the calling thread. C is m×n row-major (leading dimension ldc); op(A) is
/// m×k: A row-major m×k (lda), or with `a_t` A row-major k×m read transposed; op(B) is k×n: B
/// row-major k×n (ldb), or with `b_t` B row-major n×k read transposed. `accumulate` adds to C.
///
/// Why not Eigen's product: called outside a parallel region (exec::seq) it starts its own OpenMP
/// threads, which oversubscribes the cores and makes rounding depend on where it runs (it made the
/// feature kNN 5× slower on a loaded machine). This calls Eigen 3.4's packed kernel directly with
/// one thread and packing buffers sized once in reserve(); other Eigen versions fall back to the
/// public product with Eigen's threads off (EigenSingleThreaded).
/// Rounding depends on (m, n, k) and the reserved sizes only, never on the thread.
template <class S>
class SerialGemm {
  using Matrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

 public:
  /// Sizes the packing buffers for products up to rows×cols with depth `depth`.
  void reserve(Index rows, Index cols, Index depth) {
#if EIGEN_VERSION_AT_LEAST(3, 4, 0) && !EIGEN_VERSION_AT_LEAST(3, 5, 0)
    if (blocking_ && rows == rows_ && cols == cols_ && depth == depth_) return;
    blocking_ = std::make_unique<Blocking>(rows, cols, depth, 1, true);
    blocking_->allocateAll();
    rows_ = rows, cols_ = cols, depth_ = depth;
#else
    (void)rows, (void)cols, (void)depth;
#endif
  }

  void run(Index m, Index n, Index k, const S* A, Index lda, bool a_t, const S* B, Index ldb, bool b_t, S* C, Index ldc,
           bool accumulate) {
    Eigen::Map<Matrix, 0, Eigen::OuterStride<>> Cm(C, m, n, Eigen::OuterStride<>(ldc));
    if (!accumulate) Cm.setZero();
    if (m == 0 || n == 0 || k == 0) return;
#if EIGEN_VERSION_AT_LEAST(3, 4, 0) && !EIGEN_VERSION_AT_LEAST(3, 5, 0)
    if (!a_t && !b_t)
      kernel<Eigen::RowMajor, Eigen::RowMajor>(m, n, k, A, lda, B, ldb, C, ldc);
    else if (!a_t && b_t)
      kernel<Eigen::RowMajor, Eigen::ColMajor>(m, n, k, A, lda, B, ldb, C, ldc);
    else if (a_t && !b_t)
      kernel<Eigen::ColMajor, Eigen::RowMajor>(m, n, k, A, lda, B, ldb, C, ldc);
    else
      kernel<Eigen::ColMajor, Eigen::ColMajor>(m, n, k, A, lda, B, ldb, C, ldc);
#else
    using Stride = Eigen::OuterStride<>;
    using CM = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor>;
    auto opA = [&]() -> Matrix {
      if (a_t) return Eigen::Map<const CM, 0, Stride>(A, m, k, Stride(lda));
      return Eigen::Map<const Matrix, 0, Stride>(A, m, k, Stride(lda));
    };
    auto opB = [&]() -> Matrix {
      if (b_t) return Eigen::Map<const CM, 0, Stride>(B, k, n, Stride(ldb));
      return Eigen::Map<const Matrix, 0, Stride>(B, k, n, Stride(ldb));
    };
    const EigenSingleThreaded eigen_serial;
    Cm.noalias() += opA() * opB();
#endif
  }

 private:
#if EIGEN_VERSION_AT_LEAST(3, 4, 0) && !EIGEN_VERSION_AT_LEAST(3, 5, 0)
  using Blocking = Eigen::internal::gemm_blocking_space<Eigen::RowMajor, S, S, Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic>;

  // A row-major k×m read as op(A) is a column-major m×k with the same leading dimension.
  template <int LhsOrder, int RhsOrder>
  void kernel(Index m, Index n, Index k, const S* A, Index lda, const S* B, Index ldb, S* C, Index ldc) {
    if (!blocking_ || m > rows_ || n > cols_ || k > depth_) reserve(m, n, k);
    Eigen::internal::general_matrix_matrix_product<Index, S, LhsOrder, false, S, RhsOrder, false, Eigen::RowMajor, 1>::run(
        m, n, k, A, lda, B, ldb, C, 1, ldc, S(1), *blocking_, nullptr);
  }

  std::unique_ptr<Blocking> blocking_;
  Index rows_ = 0, cols_ = 0, depth_ = 0;
#endif
};

}  // namespace simsr
