#pragma once
/// \file
/// The Galerkin product A_c = Pᵀ A P of a multigrid level, in 3×3 blocks, for the prolongations
/// of a vertex hierarchy: P = D (W ⊗ I₃), W the vertex weights (fine vertices × coarse ones) and
/// D the 0/1 diagonal that drops the fine level's Dirichlet DOFs. Block (c, c') of A_c is
///
///     Σ_i Σ_j w_ic w_jc' · D_i A_ij D_j          (A_ij the 3×3 block of fine vertices i, j)
///
/// Why: the scalar SparseProduct (A·P, then Pᵀ·(AP)) does the same multiply-adds but looks up an
/// index and scatters into a scattered accumulator for each of them; here an index lookup carries
/// nine multiply-adds into a contiguous 3×3 accumulator. On the 73k-tet face lattice the scalar
/// products were a fifth of an LR frame.
///
/// The result is a scalar row-major CSR made of whole 3×3 blocks (zeros stored), so the next
/// level's BlockCsr copies it one to one. Like SparseProduct, the structure is built once per
/// pattern (of A's blocks and of W) and the values are recomputed row by row under the policy,
/// each row by one worker in a fixed order: seq and omp agree bitwise.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "../hessian.hpp"
#include "block_csr.hpp"

namespace simsr::physics {

/// The vertex weights W of a DOF-level prolongation P with P(3v+d, 3c+d) = W(v, c) for d = 0, 1, 2
/// and no other entries (lattice_hierarchy's); nullopt when P is not of that form.
template <class S>
std::optional<SparseMatrix<S>> vertex_weights(const SparseMatrix<S>& P) {
  if (P.rows() % 3 || P.cols() % 3 || !P.isCompressed()) return std::nullopt;
  const Index rows = P.rows() / 3;
  const int* outer = P.outerIndexPtr();
  const int* inner = P.innerIndexPtr();
  const S* val = P.valuePtr();
  SparseMatrix<S> W(rows, P.cols() / 3);
  W.resizeNonZeros(Index(outer[P.rows()]) / 3);
  int* wo = W.outerIndexPtr();
  int* wi = W.innerIndexPtr();
  S* wv = W.valuePtr();
  wo[0] = 0;
  for (Index v = 0; v < rows; ++v) {
    const int n = outer[3 * v + 1] - outer[3 * v];
    for (int d = 1; d < 3; ++d)
      if (outer[3 * v + d + 1] - outer[3 * v + d] != n) return std::nullopt;
    for (int q = 0; q < n; ++q) {
      const int c = inner[outer[3 * v] + q];
      if (c % 3) return std::nullopt;
      for (int d = 1; d < 3; ++d) {
        const int k = outer[3 * v + d] + q;
        if (inner[k] != c + d || val[k] != val[outer[3 * v] + q]) return std::nullopt;
      }
      wi[wo[v] + q] = c / 3;
      wv[wo[v] + q] = val[outer[3 * v] + q];
    }
    wo[v + 1] = wo[v] + n;
  }
  return W;
}

/// A_c = Pᵀ A P for P = D (W ⊗ I₃) (see the file comment).
template <class S = Scalar>
class BlockGalerkin {
 public:
  /// A: the fine matrix as 3×3 blocks; W: vertex weights (vertex_weights); dropped[k] ≠ 0 for the
  /// fine DOFs P leaves out (D_kk = 0). Returns the coarse matrix, kept until the next call.
  template <exec::HostPolicy P>
  const SparseMatrix<S>& compute(P policy, const BlockCsr<S, S>& A, const SparseMatrix<S>& W, const std::vector<char>& dropped) {
    if (A.rows() != 3 * W.rows() || A.cols() != A.rows())
      throw ShapeError("BlockGalerkin: the fine matrix (3 × W's rows, square)", {3 * W.rows(), 3 * W.rows()}, {A.rows(), A.cols()});
    if (Index(dropped.size()) != A.rows()) throw ShapeError("BlockGalerkin: dropped DOFs", {A.rows()}, {Index(dropped.size())});
    if (!a_pattern_.matches(A.rows() / 3, A.cols() / 3, A.block_outer(), A.block_inner(), A.num_blocks()) || !w_pattern_.matches(W))
      symbolic(A, W);
    const Index nf = W.rows(), nc = W.cols();
    const int* ao = A.block_outer();
    const int* ai = A.block_inner();
    const S* av = A.block_values();
    const int* wo = W.outerIndexPtr();
    const int* wi = W.innerIndexPtr();
    const S* wv = W.valuePtr();
    const char* drop = dropped.data();
    // AP = A D (W ⊗ I): block row i accumulates w_jc · A_ij D_j over its blocks j
    exec::parallel_for(policy, kChunks, [&](Index chunk) {
      std::vector<S>& acc = scratch_[std::size_t(chunk)];
      for (Index i = chunk * nf / kChunks; i < (chunk + 1) * nf / kChunks; ++i) {
        for (int k = ao[i]; k < ao[i + 1]; ++k) {
          const Index j = ai[k];
          S a[9];
          for (int e = 0; e < 9; ++e) a[e] = drop[3 * j + e % 3] ? S(0) : av[9 * std::size_t(k) + std::size_t(e)];
          for (int m = wo[j]; m < wo[j + 1]; ++m) {
            S* t = acc.data() + 9 * std::size_t(wi[m]);
            const S w = wv[m];
            for (int e = 0; e < 9; ++e) t[e] += w * a[e];
          }
        }
        for (int p = ap_outer_[std::size_t(i)]; p < ap_outer_[std::size_t(i) + 1]; ++p) {
          S* t = acc.data() + 9 * std::size_t(ap_inner_[std::size_t(p)]);
          std::copy(t, t + 9, ap_values_.data() + 9 * std::size_t(p));
          std::fill(t, t + 9, S(0));
        }
      }
    });
    // A_c = (W ⊗ I)ᵀ D AP: coarse block row c accumulates w_ic · D_i AP_ic' over the fine i of W's column c
    const int* co = Ac_.outerIndexPtr();
    S* cv = Ac_.valuePtr();
    exec::parallel_for(policy, kChunks, [&](Index chunk) {
      std::vector<S>& acc = scratch_[std::size_t(chunk)];
      for (Index c = chunk * nc / kChunks; c < (chunk + 1) * nc / kChunks; ++c) {
        for (int m = wt_outer_[std::size_t(c)]; m < wt_outer_[std::size_t(c) + 1]; ++m) {
          const Index i = wt_inner_[std::size_t(m)];
          const S w = wt_values_[std::size_t(m)];
          const bool keep[3] = {!drop[3 * i], !drop[3 * i + 1], !drop[3 * i + 2]};
          for (int p = ap_outer_[std::size_t(i)]; p < ap_outer_[std::size_t(i) + 1]; ++p) {
            const S* b = ap_values_.data() + 9 * std::size_t(p);
            S* t = acc.data() + 9 * std::size_t(ap_inner_[std::size_t(p)]);
            for (int e = 0; e < 9; ++e)
              if (keep[e / 3]) t[e] += w * b[e];
          }
        }
        // block q of row c → entries 3q..3q+2 of scalar rows 3c, 3c+1, 3c+2
        const int first = ac_block_outer_[std::size_t(c)], count = ac_block_outer_[std::size_t(c) + 1] - first;
        for (int q = 0; q < count; ++q) {
          S* t = acc.data() + 9 * std::size_t(ac_block_inner_[std::size_t(first + q)]);
          for (int d = 0; d < 3; ++d)
            for (int e = 0; e < 3; ++e) cv[co[3 * c + d] + 3 * q + e] = t[3 * d + e];
          std::fill(t, t + 9, S(0));
        }
      }
    });
    return Ac_;
  }

  const SparseMatrix<S>& result() const { return Ac_; }
  /// The coarse matrix, for adjusting values in place (its structure is the product's).
  SparseMatrix<S>& result() { return Ac_; }
  /// Changes whenever the structure of the result is rebuilt.
  std::uint64_t structure_version() const { return version_; }

 private:
  static constexpr Index kChunks = 16;

  /// `row` ← the sorted, distinct columns `each` passes to its callback (mark: all zero on entry and exit).
  template <class Each>
  static void row_union(std::vector<char>& mark, std::vector<int>& row, Each&& each) {
    row.clear();
    each([&](int c) {
      if (!mark[std::size_t(c)]) mark[std::size_t(c)] = 1, row.push_back(c);
    });
    std::sort(row.begin(), row.end());
    for (const int c : row) mark[std::size_t(c)] = 0;
  }

  void symbolic(const BlockCsr<S, S>& A, const SparseMatrix<S>& W) {
    const Index nf = W.rows(), nc = W.cols();
    const int* ao = A.block_outer();
    const int* ai = A.block_inner();
    const int* wo = W.outerIndexPtr();
    const int* wi = W.innerIndexPtr();
    std::vector<char> mark(std::size_t(nc), 0);
    std::vector<int> row;
    // AP's block pattern: row i = ∪ over A's blocks j of W's row j
    ap_outer_.assign(std::size_t(nf) + 1, 0);
    ap_inner_.clear();
    for (Index i = 0; i < nf; ++i) {
      row_union(mark, row, [&](auto add) {
        for (int k = ao[i]; k < ao[i + 1]; ++k)
          for (int m = wo[ai[k]]; m < wo[ai[k] + 1]; ++m) add(wi[m]);
      });
      ap_inner_.insert(ap_inner_.end(), row.begin(), row.end());
      ap_outer_[std::size_t(i) + 1] = int(ap_inner_.size());
    }
    ap_values_.assign(9 * ap_inner_.size(), S(0));
    // Wᵀ (coarse vertex → its fine vertices and weights, fine vertices ascending)
    const SparseMatrix<S> Wt = W.transpose();
    wt_outer_.assign(Wt.outerIndexPtr(), Wt.outerIndexPtr() + nc + 1);
    wt_inner_.assign(Wt.innerIndexPtr(), Wt.innerIndexPtr() + Wt.nonZeros());
    wt_values_.assign(Wt.valuePtr(), Wt.valuePtr() + Wt.nonZeros());
    // A_c's block pattern: row c = ∪ over the fine i of Wᵀ's row c of AP's row i
    ac_block_outer_.assign(std::size_t(nc) + 1, 0);
    ac_block_inner_.clear();
    for (Index c = 0; c < nc; ++c) {
      row_union(mark, row, [&](auto add) {
        for (int m = wt_outer_[std::size_t(c)]; m < wt_outer_[std::size_t(c) + 1]; ++m)
          for (int p = ap_outer_[std::size_t(wt_inner_[std::size_t(m)])]; p < ap_outer_[std::size_t(wt_inner_[std::size_t(m)]) + 1]; ++p)
            add(ap_inner_[std::size_t(p)]);
      });
      ac_block_inner_.insert(ac_block_inner_.end(), row.begin(), row.end());
      ac_block_outer_[std::size_t(c) + 1] = int(ac_block_inner_.size());
    }
    // the scalar CSR of whole blocks
    const std::size_t blocks = ac_block_inner_.size();
    Ac_ = SparseMatrix<S>(3 * nc, 3 * nc);
    Ac_.resizeNonZeros(Index(9 * blocks));
    int* co = Ac_.outerIndexPtr();
    int* ci = Ac_.innerIndexPtr();
    co[0] = 0;
    for (Index c = 0; c < nc; ++c) {
      const int first = ac_block_outer_[std::size_t(c)], count = ac_block_outer_[std::size_t(c) + 1] - first;
      for (int d = 0; d < 3; ++d) {
        const int start = co[3 * c + d];
        for (int q = 0; q < count; ++q)
          for (int e = 0; e < 3; ++e) ci[start + 3 * q + e] = 3 * ac_block_inner_[std::size_t(first + q)] + e;
        co[3 * c + d + 1] = start + 3 * count;
      }
    }
    std::fill(Ac_.valuePtr(), Ac_.valuePtr() + 9 * blocks, S(0));
    scratch_.assign(std::size_t(kChunks), std::vector<S>(9 * std::size_t(nc), S(0)));
    a_pattern_.remember(A.rows() / 3, A.cols() / 3, ao, ai, A.num_blocks());
    w_pattern_.remember(W);
    ++version_;
  }

  std::vector<int> ap_outer_, ap_inner_;  ///< AP's block pattern (fine rows × coarse columns)
  std::vector<S> ap_values_;              ///< 9 per block
  std::vector<int> wt_outer_, wt_inner_;  ///< Wᵀ
  std::vector<S> wt_values_;
  std::vector<int> ac_block_outer_, ac_block_inner_;  ///< A_c's block pattern
  SparseMatrix<S> Ac_;
  std::vector<std::vector<S>> scratch_;  ///< one dense row of 3×3 accumulators per chunk
  detail::CsrPattern<int> a_pattern_, w_pattern_;  ///< A's block pattern and W's at the last symbolic()
  std::uint64_t version_ = 0;
};

}  // namespace simsr::physics
