#pragma once
/// \file
/// The global Hessian of a quasistatic problem, and the one sink every EnergyTerm adds its
/// Hessian to: a symmetric matrix of 3×3 vertex blocks whose pattern (every vertex pair sharing a
/// tet) is built once, plus a scalar CSR copy with a fixed structure for the linear solvers, so a
/// Newton iteration allocates nothing.
///
///     physics::BlockHessian<> H(num_vertices, mesh.T);   // pattern from the tets
///     H.set_zero();
///     elastic.add_hessian(exec::omp, x, H, Definiteness::exact);   // every term, one form
///     const auto& A = H.assemble(exec::omp, fixed_dof_mask);       // Eigen RowMajor CSR, 3V×3V
///
/// Two ways in, one object: terms that touch few vertices (springs, contact) call `add(i, j,
/// block)` like a triplet list; a term that fills the pattern (the elastic energy) looks up
/// `slot(i, j)` once and writes `block(slot)` directly, in parallel over slots. Blocks outside the
/// pattern (self-contact between far-apart vertices) grow the pattern: the matrix is rebuilt and
/// `pattern_version()` changes, which tells users of slots (the elastic energy's gather lists, a
/// Cholesky's symbolic analysis) to refresh. `BlockHessian(n)` starts from the diagonal only and
/// grows to whatever is added (a term's Hessian on its own, e.g. in a test).

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"

namespace simsr::physics {

/// 3×3 blocks (row vertex, column vertex, block) in the order added; duplicates are summed when
/// added to a BlockHessian (which keeps its out-of-pattern blocks here until it grows).
template <class S = Scalar>
class BlockTriplets {
 public:
  void add(VIndex row, VIndex col, const Mat3<S>& block) {
    rows_.push_back(row);
    cols_.push_back(col);
    blocks_.push_back(block);
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

/// Scalar sparse matrix handed to linear solvers (symmetric; row-major CSR).
template <class S = Scalar>
using SparseMatrix = Eigen::SparseMatrix<S, Eigen::RowMajor, int>;

/// Block-sparse symmetric Hessian over #V vertices (see the file comment).
template <class S = Scalar>
class BlockHessian {
 public:
  BlockHessian() = default;

  /// Pattern: the diagonal blocks only; every other block added grows it.
  explicit BlockHessian(Index num_vertices) : BlockHessian(num_vertices, Tets(0, 4)) {}

  /// Pattern: every (i, j) with i and j in a common tet of T (diagonal included).
  BlockHessian(Index num_vertices, const Tets& T) : n_(num_vertices) {
    std::vector<std::uint64_t> keys;
    keys.reserve(std::size_t(T.rows()) * 16 + std::size_t(num_vertices));
    for (Index v = 0; v < num_vertices; ++v) keys.push_back(key(VIndex(v), VIndex(v)));
    for (Index t = 0; t < T.rows(); ++t)
      for (int a = 0; a < 4; ++a) {
        if (T(t, a) < 0 || T(t, a) >= num_vertices)
          throw MeshError("tet", t, "vertex index " + std::to_string(T(t, a)) + " out of range [0, " + std::to_string(num_vertices) + ")");
        for (int b = 0; b < 4; ++b) keys.push_back(key(T(t, a), T(t, b)));
      }
    build(std::move(keys));
  }

  Index num_vertices() const { return n_; }
  Index num_blocks() const { return Index(cols_.size()); }
  /// Changes whenever the pattern grows (slots and the scalar structure are then new).
  std::uint64_t pattern_version() const { return version_; }

  /// Slot of block (i, j), or −1 if it is not in the pattern.
  Index slot(VIndex i, VIndex j) const {
    const auto b = cols_.begin() + row_offsets_[std::size_t(i)];
    const auto e = cols_.begin() + row_offsets_[std::size_t(i) + 1];
    const auto it = std::lower_bound(b, e, j);
    return (it != e && *it == j) ? Index(it - cols_.begin()) : Index(-1);
  }
  /// Block at a slot (column-major 3×3 view).
  Eigen::Map<Mat3<S>> block(Index slot) { return Eigen::Map<Mat3<S>>(values_.data() + 9 * slot); }
  Eigen::Map<const Mat3<S>> block(Index slot) const { return Eigen::Map<const Mat3<S>>(values_.data() + 9 * slot); }
  /// Row vertex of every slot is implicit in the CSR; the column vertex:
  VIndex slot_col(Index slot) const { return cols_[std::size_t(slot)]; }
  const std::vector<Index>& row_offsets() const { return row_offsets_; }

  void set_zero() {
    std::fill(values_.begin(), values_.end(), S(0));
    overflow_.clear();
  }

  /// Adds blocks (duplicates summed). Blocks outside the pattern are kept and merged into the
  /// pattern by the next assemble(). Not thread-safe: one caller at a time (direct writes to
  /// distinct slots through block(slot) may run in parallel).
  void add(const BlockTriplets<S>& h) {
    for (Index k = 0; k < h.size(); ++k) add(h.row(k), h.col(k), h.block(k));
  }
  /// Adds `b` to block (i, j). ShapeError for a vertex outside [0, num_vertices).
  void add(VIndex i, VIndex j, const Mat3<S>& b) {
    if (i < 0 || j < 0 || i >= n_ || j >= n_)
      throw ShapeError("BlockHessian::add: block (" + std::to_string(i) + ", " + std::to_string(j) + ")", {n_, n_}, {i, j});
    const Index s = slot(i, j);
    if (s >= 0)
      block(s) += b;
    else
      overflow_.add(i, j, b);
  }

  /// The scalar 3V×3V matrix. DOFs with fixed[d] != 0 get an identity row and column (Dirichlet
  /// elimination keeps the pattern). The reference stays valid until the next assemble().
  template <exec::HostPolicy P>
  const SparseMatrix<S>& assemble(P policy, const std::vector<char>& fixed) {
    if (overflow_.size() > 0) grow();
    if (fixed.size() != std::size_t(3 * n_))
      throw ShapeError("BlockHessian::assemble: fixed-DOF mask", {3 * n_}, {Index(fixed.size())});
    S* val = scalar_.valuePtr();
    const int* outer = scalar_.outerIndexPtr();
    exec::parallel_for(policy, n_, [&](Index v) {
      const Index b0 = row_offsets_[std::size_t(v)], b1 = row_offsets_[std::size_t(v) + 1];
      for (int r = 0; r < 3; ++r) {
        const Index row = 3 * v + r;
        S* out = val + outer[row];
        const bool row_fixed = fixed[std::size_t(row)] != 0;
        for (Index s = b0; s < b1; ++s) {
          const VIndex c = cols_[std::size_t(s)];
          for (int k = 0; k < 3; ++k) {
            const Index col = 3 * Index(c) + k;
            S value = values_[std::size_t(9 * s + r + 3 * k)];
            if (row_fixed || fixed[std::size_t(col)]) value = (row == col) ? S(1) : S(0);
            *out++ = value;
          }
        }
      }
    });
    return scalar_;
  }

  /// The matrix the last assemble() returned (its values as assembled then).
  const SparseMatrix<S>& assembled() const { return scalar_; }

  /// Whether every block is a multiple of the identity, c·I (exactly: the terms of projective
  /// dynamics add only such blocks). Then the matrix is A ⊗ I₃ with A the #V×#V matrix of the
  /// c's, and a solver can factor A (a third of the unknowns, a ninth of the nonzeros) and
  /// solve the three coordinates one by one. Pending blocks (outside the pattern) are merged
  /// into it first.
  bool isotropic() {
    if (overflow_.size() > 0) grow();
    for (std::size_t s = 0; s < cols_.size(); ++s) {
      const S* b = values_.data() + 9 * s;
      if (b[1] != S(0) || b[2] != S(0) || b[3] != S(0) || b[5] != S(0) || b[6] != S(0) || b[7] != S(0) || b[4] != b[0] || b[8] != b[0])
        return false;
    }
    return true;
  }

  /// The #V×#V matrix A of an isotropic Hessian (A ⊗ I₃ is this matrix; isotropic() must hold,
  /// ArgumentError otherwise): A_ij = block(i, j)(0, 0). Vertices with fixed_vertices[v] != 0 get
  /// an identity row and column. The reference stays valid until the next call; its pattern is
  /// the blocks' and is identified by isotropic_pattern_version().
  template <exec::HostPolicy P>
  const SparseMatrix<S>& assemble_isotropic(P policy, const std::vector<char>& fixed_vertices) {
    if (!isotropic()) throw ArgumentError("BlockHessian::assemble_isotropic: a block is not a multiple of the identity");
    if (fixed_vertices.size() != std::size_t(n_))
      throw ShapeError("BlockHessian::assemble_isotropic: fixed-vertex mask", {n_}, {Index(fixed_vertices.size())});
    if (isotropic_version_ != version_) {
      isotropic_.resize(n_, n_);
      isotropic_.resizeNonZeros(Index(cols_.size()));
      std::copy(row_offsets_.begin(), row_offsets_.end(), isotropic_.outerIndexPtr());
      std::copy(cols_.begin(), cols_.end(), isotropic_.innerIndexPtr());
      isotropic_version_ = version_;
      isotropic_pattern_version_ = next_version();
    }
    S* val = isotropic_.valuePtr();
    exec::parallel_for(policy, n_, [&](Index v) {
      const bool row_fixed = fixed_vertices[std::size_t(v)] != 0;
      for (Index s = row_offsets_[std::size_t(v)]; s < row_offsets_[std::size_t(v) + 1]; ++s) {
        const VIndex c = cols_[std::size_t(s)];
        val[s] = (row_fixed || fixed_vertices[std::size_t(c)]) ? S(c == v ? 1 : 0) : values_[std::size_t(9 * s)];
      }
    });
    return isotropic_;
  }
  /// Identifies the pattern of the last assemble_isotropic() (unique across all matrices, like
  /// pattern_version()).
  std::uint64_t isotropic_pattern_version() const { return isotropic_pattern_version_; }

 private:
  static std::uint64_t key(VIndex i, VIndex j) { return (std::uint64_t(std::uint32_t(i)) << 32) | std::uint32_t(j); }

  void build(std::vector<std::uint64_t> keys) {
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    row_offsets_.assign(std::size_t(n_) + 1, 0);
    cols_.resize(keys.size());
    for (std::size_t k = 0; k < keys.size(); ++k) {
      ++row_offsets_[std::size_t(keys[k] >> 32) + 1];
      cols_[k] = VIndex(std::uint32_t(keys[k]));
    }
    for (Index v = 0; v < n_; ++v) row_offsets_[std::size_t(v) + 1] += row_offsets_[std::size_t(v)];
    values_.assign(9 * cols_.size(), S(0));
    // Scalar CSR: scalar row 3v+r holds 3 entries per block of vertex row v, in block order.
    scalar_.resize(3 * n_, 3 * n_);
    scalar_.resizeNonZeros(Index(9 * cols_.size()));
    int* outer = scalar_.outerIndexPtr();
    int* inner = scalar_.innerIndexPtr();
    outer[0] = 0;
    for (Index v = 0; v < n_; ++v) {
      const Index b0 = row_offsets_[std::size_t(v)], b1 = row_offsets_[std::size_t(v) + 1];
      for (int r = 0; r < 3; ++r) {
        const Index row = 3 * v + r;
        int pos = outer[row];
        for (Index s = b0; s < b1; ++s)
          for (int k = 0; k < 3; ++k) inner[pos++] = int(3 * cols_[std::size_t(s)] + k);
        outer[row + 1] = pos;
      }
    }
    version_ = next_version();
  }

  /// Versions are unique across all BlockHessian objects, so a cached slot map can never be
  /// mistaken for another matrix's.
  static std::uint64_t next_version() {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
  }

  /// Merges the overflow blocks into a larger pattern, keeping every value.
  void grow() {
    std::vector<std::uint64_t> keys;
    keys.reserve(cols_.size() + std::size_t(overflow_.size()));
    for (Index v = 0; v < n_; ++v)
      for (Index s = row_offsets_[std::size_t(v)]; s < row_offsets_[std::size_t(v) + 1]; ++s) keys.push_back(key(VIndex(v), cols_[std::size_t(s)]));
    for (Index k = 0; k < overflow_.size(); ++k) keys.push_back(key(overflow_.row(k), overflow_.col(k)));
    std::vector<S> old_values = std::move(values_);
    std::vector<Index> old_offsets = row_offsets_;
    std::vector<VIndex> old_cols = cols_;
    build(std::move(keys));
    for (Index v = 0; v < n_; ++v)
      for (Index s = old_offsets[std::size_t(v)]; s < old_offsets[std::size_t(v) + 1]; ++s)
        block(slot(VIndex(v), old_cols[std::size_t(s)])) = Eigen::Map<const Mat3<S>>(old_values.data() + 9 * s);
    BlockTriplets<S> pending = std::move(overflow_);
    overflow_.clear();
    for (Index k = 0; k < pending.size(); ++k) block(slot(pending.row(k), pending.col(k))) += pending.block(k);
  }

  Index n_ = 0;
  std::vector<Index> row_offsets_{0};
  std::vector<VIndex> cols_;
  std::vector<S> values_;
  BlockTriplets<S> overflow_;
  SparseMatrix<S> scalar_;
  std::uint64_t version_ = 0;
  SparseMatrix<S> isotropic_;  // assemble_isotropic
  std::uint64_t isotropic_version_ = 0, isotropic_pattern_version_ = 0;
};

}  // namespace simsr::physics
