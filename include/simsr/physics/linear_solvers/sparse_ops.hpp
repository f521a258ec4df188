#pragma once
/// \file
/// The sparse kernels the iterative solvers here run under their execution policy: y = A·v for a
/// row-major CSR A, the dot product with the fixed chunking of exec::parallel_reduce (so seq and
/// omp give bitwise identical results), and a sparse·sparse product that reuses its structure.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "linear_solver.hpp"

namespace simsr::physics {

/// out = A·v (row-major CSR; each row summed in storage order by one worker).
template <exec::HostPolicy P, class S, class StorageIndex>
void sparse_multiply(P policy, const Eigen::SparseMatrix<S, Eigen::RowMajor, StorageIndex>& A, const VecX<S>& v, VecX<S>& out) {
  const StorageIndex* outer = A.outerIndexPtr();
  const StorageIndex* inner = A.innerIndexPtr();
  const S* val = A.valuePtr();
  if (out.size() != A.rows()) out.resize(A.rows());
  exec::parallel_for(policy, A.rows(), [&](Index r) {
    S s = 0;
    for (StorageIndex k = outer[r]; k < outer[r + 1]; ++k) s += val[k] * v[inner[k]];
    out[r] = s;
  });
}

/// a·b with exec::parallel_reduce's fixed chunks.
template <exec::HostPolicy P, class S>
S dot(P policy, const VecX<S>& a, const VecX<S>& b) {
  return exec::parallel_reduce(policy, a.size(), S(0), [&](Index i) { return a[i] * b[i]; }, [](S u, S v) { return u + v; });
}

namespace detail {
/// A CSR pattern (sizes, row starts, column indices) kept to tell whether the next matrix has the
/// same one: SparseProduct's operands, BlockCsr's source, BlockGalerkin's operands.
template <class StorageIndex = int>
struct CsrPattern {
  Index rows = -1, cols = -1;
  std::vector<StorageIndex> outer, inner;
  bool matches(Index r, Index c, const StorageIndex* o, const StorageIndex* i, Index nonzeros) const {
    return r == rows && c == cols && Index(inner.size()) == nonzeros && std::equal(outer.begin(), outer.end(), o) && std::equal(inner.begin(), inner.end(), i);
  }
  void remember(Index r, Index c, const StorageIndex* o, const StorageIndex* i, Index nonzeros) {
    rows = r, cols = c;
    outer.assign(o, o + r + 1);
    inner.assign(i, i + nonzeros);
  }
  template <class M>
  bool matches(const M& m) const {
    return matches(m.rows(), m.cols(), m.outerIndexPtr(), m.innerIndexPtr(), m.nonZeros());
  }
  template <class M>
  void remember(const M& m) {
    remember(m.rows(), m.cols(), m.outerIndexPtr(), m.innerIndexPtr(), m.nonZeros());
  }
};
}  // namespace detail

/// C = A·B for row-major CSR matrices whose patterns repeat (the Galerkin products of a multigrid
/// hierarchy at every Newton iteration): C's structure is built when A's or B's pattern differs
/// from the last call's, otherwise only its values are recomputed, row by row under the policy
/// with one dense accumulator per chunk (rows are independent: seq and omp agree bitwise).
/// Every structurally possible entry is kept, zeros included, so the structure never depends
/// on values.
template <class S, class StorageIndex = int>
class SparseProduct {
 public:
  using Matrix = Eigen::SparseMatrix<S, Eigen::RowMajor, StorageIndex>;

  template <exec::HostPolicy P>
  const Matrix& compute(P policy, const Matrix& A, const Matrix& B) {
    if (A.cols() != B.rows()) throw ShapeError("SparseProduct: B's rows (A's columns)", {A.cols(), -1}, {B.rows(), B.cols()});
    if (!A.isCompressed() || !B.isCompressed()) throw ArgumentError("SparseProduct: A and B must be compressed");
    if (!a_pattern_.matches(A) || !b_pattern_.matches(B)) symbolic(A, B);
    const StorageIndex* ao = A.outerIndexPtr();
    const StorageIndex* ai = A.innerIndexPtr();
    const S* av = A.valuePtr();
    const StorageIndex* bo = B.outerIndexPtr();
    const StorageIndex* bi = B.innerIndexPtr();
    const S* bv = B.valuePtr();
    const StorageIndex* co = C_.outerIndexPtr();
    const StorageIndex* ci = C_.innerIndexPtr();
    S* cv = C_.valuePtr();
    const Index rows = A.rows();
    exec::parallel_for(policy, kChunks, [&](Index chunk) {
      VecX<S>& acc = scratch_[std::size_t(chunk)];
      for (Index i = chunk * rows / kChunks; i < (chunk + 1) * rows / kChunks; ++i) {
        for (StorageIndex k = ao[i]; k < ao[i + 1]; ++k) {
          const S a = av[k];
          const Index row_b = ai[k];
          for (StorageIndex m = bo[row_b]; m < bo[row_b + 1]; ++m) acc[bi[m]] += a * bv[m];
        }
        for (StorageIndex p = co[i]; p < co[i + 1]; ++p) {
          cv[p] = acc[ci[p]];
          acc[ci[p]] = S(0);
        }
      }
    });
    return C_;
  }
  const Matrix& result() const { return C_; }
  /// C, for adjusting values in place (the structure is the product's).
  Matrix& result() { return C_; }
  /// Changes whenever the structure of C is rebuilt.
  std::uint64_t structure_version() const { return version_; }

 private:
  static constexpr Index kChunks = 16;
  void symbolic(const Matrix& A, const Matrix& B) {
    std::vector<StorageIndex> outer(std::size_t(A.rows()) + 1, 0), inner, row;
    std::vector<char> mark(std::size_t(B.cols()), 0);
    for (Index i = 0; i < A.rows(); ++i) {
      row.clear();
      for (StorageIndex k = A.outerIndexPtr()[i]; k < A.outerIndexPtr()[i + 1]; ++k) {
        const Index rb = A.innerIndexPtr()[k];
        for (StorageIndex m = B.outerIndexPtr()[rb]; m < B.outerIndexPtr()[rb + 1]; ++m) {
          const StorageIndex c = B.innerIndexPtr()[m];
          if (!mark[std::size_t(c)]) mark[std::size_t(c)] = 1, row.push_back(c);
        }
      }
      std::sort(row.begin(), row.end());
      for (const StorageIndex c : row) mark[std::size_t(c)] = 0;
      inner.insert(inner.end(), row.begin(), row.end());
      outer[std::size_t(i) + 1] = StorageIndex(inner.size());
    }
    C_ = Matrix(A.rows(), B.cols());
    C_.resizeNonZeros(Index(inner.size()));
    std::copy(outer.begin(), outer.end(), C_.outerIndexPtr());
    std::copy(inner.begin(), inner.end(), C_.innerIndexPtr());
    std::fill(C_.valuePtr(), C_.valuePtr() + inner.size(), S(0));
    scratch_.assign(std::size_t(kChunks), VecX<S>::Zero(B.cols()));
    a_pattern_.remember(A);
    b_pattern_.remember(B);
    ++version_;
  }

  Matrix C_;
  detail::CsrPattern<StorageIndex> a_pattern_, b_pattern_;
  std::vector<VecX<S>> scratch_;
  std::uint64_t version_ = 0;
};

namespace detail {
/// The pattern a direct solver last analysed (SparseCholesky, CholmodCholesky): the symbolic
/// analysis is redone only when the caller's pattern version, the size or the nonzero count changes.
struct AnalysedPattern {
  bool analysed = false;
  std::uint64_t version = 0;
  Index rows = 0, nonzeros = 0;
  /// True when A's pattern is not the one analysed last, which it then records.
  template <class Matrix>
  bool changed(const Matrix& A, std::uint64_t pattern_version) {
    if (analysed && pattern_version == version && A.rows() == rows && A.nonZeros() == nonzeros) return false;
    analysed = true;
    version = pattern_version;
    rows = A.rows();
    nonzeros = A.nonZeros();
    return true;
  }
};

/// What a direct solver's solve reports: the relative residual ‖b − A x‖ / ‖b‖ computed under the
/// policy into the kept buffer Ax (no allocation per Newton iteration); converged when finite
/// and `factored` (the factorization's own success).
template <exec::HostPolicy P, class S, class StorageIndex>
LinearSolveInfo direct_solve_info(P policy, const Eigen::SparseMatrix<S, Eigen::RowMajor, StorageIndex>& A, const VecX<S>& b, const VecX<S>& x,
                                  VecX<S>& Ax, bool factored = true) {
  LinearSolveInfo info;
  const S bn = b.norm();
  sparse_multiply(policy, A, x, Ax);
  info.relative_residual = bn > S(0) ? double((b - Ax).norm() / bn) : 0.0;
  info.converged = factored && std::isfinite(info.relative_residual);
  return info;
}
}  // namespace detail

}  // namespace simsr::physics
