#pragma once
/// \file
/// Preconditioned conjugate gradients with Jacobi (1/A_ii), block-Jacobi (the inverse 3×3 vertex
/// blocks), incomplete Cholesky or Multigrid (multigrid.hpp) preconditioning. compute() and solve()
/// take the execution policy first; products and dot products run under it with fixed chunking,
/// so seq and omp iterate identically.
///
///     physics::ConjugateGradient<physics::BlockJacobi<>> pcg({.tolerance = 1e-6});
///     pcg.compute(exec::omp, A);
///     LinearSolveInfo info = pcg.solve(exec::omp, b, x);

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "block_csr.hpp"
#include "linear_solver.hpp"
#include "sparse_ops.hpp"

namespace simsr::physics {

/// z = D⁻¹ r with D = diag(A). Non-positive diagonal entries (rows with no stiffness) act as 1.
template <class S = Scalar>
class Jacobi {
 public:
  template <exec::HostPolicy P>
  void compute(P policy, const SparseMatrix<S>& A) {
    inv_.resize(A.rows());
    exec::parallel_for(policy, A.rows(), [&](Index r) {
      const S d = A.coeff(r, r);
      inv_[r] = d > S(0) ? S(1) / d : S(1);
    });
  }
  template <exec::HostPolicy P>
  void apply(P policy, const VecX<S>& r, VecX<S>& z) const {
    exec::parallel_for(policy, r.size(), [&](Index i) { z[i] = inv_[i] * r[i]; });
  }

 private:
  VecX<S> inv_;
};

/// z_v = B_v⁻¹ r_v with B_v the 3×3 diagonal block of vertex v (A is 3V×3V, vertex-major). A
/// singular block falls back to its diagonal.
template <class S = Scalar>
class BlockJacobi {
 public:
  template <exec::HostPolicy P>
  void compute(P policy, const SparseMatrix<S>& A) {
    if (A.rows() % 3 != 0) throw ShapeError("BlockJacobi: matrix rows (3 per vertex)", {-1}, {A.rows()});
    inv_.resize(std::size_t(A.rows() / 3));
    exec::parallel_for(policy, A.rows() / 3, [&](Index v) {
      Mat3<S> B;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) B(i, j) = A.coeff(3 * v + i, 3 * v + j);
      const S scale = B.cwiseAbs().maxCoeff();
      const S det = B.determinant();
      Mat3<S> inv = Mat3<S>::Zero();
      if (scale > S(0) && det > S(1e-12) * scale * scale * scale) {
        inv = B.inverse();
      } else {
        for (int i = 0; i < 3; ++i) inv(i, i) = B(i, i) > S(0) ? S(1) / B(i, i) : S(1);
      }
      inv_[std::size_t(v)] = inv;
    });
  }
  template <exec::HostPolicy P>
  void apply(P policy, const VecX<S>& r, VecX<S>& z) const {
    exec::parallel_for(policy, Index(inv_.size()), [&](Index v) { z.template segment<3>(3 * v).noalias() = inv_[std::size_t(v)] * r.template segment<3>(3 * v); });
  }
  /// The inverse of vertex v's 3×3 diagonal block (as apply uses it), after compute().
  const Mat3<S>& inverse_block(Index v) const { return inv_[std::size_t(v)]; }

 private:
  std::vector<Mat3<S>, Eigen::aligned_allocator<Mat3<S>>> inv_;
};

/// Options of ConjugateGradient.
struct ConjugateGradientOptions {
  double tolerance = 1e-6;     ///< stop when ‖b − A x‖ ≤ tolerance·‖b‖
  Index max_iterations = 0;    ///< 0: the system size
  /// Run the products A·p on a 3×3 block copy of A (BlockCsr) when A's size is a multiple of 3:
  /// the same iterates to rounding for fewer bytes per product; false: on A's CSR (the baseline).
  bool block_products = true;
};

/// PCG from x = 0 (see the file comment). Buffers are kept between solves.
template <class Preconditioner = BlockJacobi<Scalar>, class S = Scalar>
class ConjugateGradient {
 public:
  using scalar_type = S;
  ConjugateGradient() = default;
  explicit ConjugateGradient(ConjugateGradientOptions options) : options_(options) {}
  /// With a preconditioner that needs more than the matrix (Multigrid: its prolongations).
  ConjugateGradient(ConjugateGradientOptions options, Preconditioner preconditioner)
      : options_(options), preconditioner_(std::move(preconditioner)) {}

  ConjugateGradientOptions& options() { return options_; }
  Preconditioner& preconditioner() { return preconditioner_; }

  /// Keeps A (which must outlive the solves) and sets the preconditioner up for it.
  template <exec::HostPolicy P>
  void compute(P policy, const SparseMatrix<S>& A, std::uint64_t /*pattern_version*/ = 0) {
    if (A.rows() != A.cols()) throw ShapeError("ConjugateGradient: matrix", {A.rows(), A.rows()}, {A.rows(), A.cols()});
    A_ = &A;
    blocked_ = options_.block_products && A.rows() % 3 == 0;
    if (blocked_) A_block_.assign(policy, A);
    // a preconditioner that reads A's blocks too (Multigrid) takes this copy instead of making its own
    if constexpr (requires { preconditioner_.compute(policy, A, A_block_); }) {
      if (blocked_) return preconditioner_.compute(policy, A, A_block_);
    }
    preconditioner_.compute(policy, A);
  }

  /// x = A⁻¹ b to the relative tolerance, from x = 0.
  template <exec::HostPolicy P>
  LinearSolveInfo solve(P policy, const VecX<S>& b, VecX<S>& x) {
    if (!A_) throw Error("ConjugateGradient::solve called before compute");
    const Index n = A_->rows();
    if (b.size() != n) throw ShapeError("ConjugateGradient: right-hand side", {n}, {b.size()});
    x.setZero(n);
    r_ = b;
    z_.resize(n);
    p_.resize(n);
    q_.resize(n);
    const S bnorm = std::sqrt(physics::dot(policy, b, b));
    LinearSolveInfo info;
    if (bnorm == S(0)) return info;
    const Index max_it = options_.max_iterations > 0 ? options_.max_iterations : n;
    preconditioner_.apply(policy, r_, z_);
    p_ = z_;
    S rz = physics::dot(policy, r_, z_);
    S rnorm = bnorm;
    // rᵀM⁻¹r ≤ 0 for r ≠ 0: the preconditioner is not positive definite (a V-cycle whose smoother
    // amplifies some modes, MultigridOptions::spectrum). CG has no meaning then and would run its
    // whole count without meeting pᵀAp ≤ 0: report it unconverged at once, as negative curvature is
    if (!(rz > S(0))) {
      info.converged = false;
      info.relative_residual = 1;
      return info;
    }
    for (Index it = 0; it < max_it; ++it) {
      if (blocked_)
        A_block_.multiply(policy, p_, q_);
      else
        sparse_multiply(policy, *A_, p_, q_);
      const S pq = physics::dot(policy, p_, q_);
      if (!(pq > S(0))) {  // zero or negative curvature along p: A is not positive definite
        info.converged = false;
        info.relative_residual = double(rnorm / bnorm);
        return info;
      }
      const S alpha = rz / pq;
      exec::parallel_for(policy, n, [&](Index i) {
        x[i] += alpha * p_[i];
        r_[i] -= alpha * q_[i];
      });
      info.iterations = it + 1;
      rnorm = std::sqrt(physics::dot(policy, r_, r_));
      if (rnorm <= S(options_.tolerance) * bnorm) break;
      preconditioner_.apply(policy, r_, z_);
      const S rz_new = physics::dot(policy, r_, z_);
      if (!(rz_new > S(0))) break;  // the preconditioner is not positive definite (above): unconverged
      const S beta = rz_new / rz;
      rz = rz_new;
      exec::parallel_for(policy, n, [&](Index i) { p_[i] = z_[i] + beta * p_[i]; });
    }
    info.relative_residual = double(rnorm / bnorm);
    info.converged = info.relative_residual <= options_.tolerance;
    return info;
  }

 private:
  ConjugateGradientOptions options_;
  Preconditioner preconditioner_;
  const SparseMatrix<S>* A_ = nullptr;
  BlockCsr<S, S> A_block_;  ///< A as 3×3 blocks (ConjugateGradientOptions::block_products)
  bool blocked_ = false;
  VecX<S> r_, z_, p_, q_;
};

}  // namespace simsr::physics
