#pragma once
/// \file
/// Incomplete Cholesky preconditioning for ConjugateGradient: Eigen's IncompleteCholesky (Lin &
/// Moré's limited-memory IC with diagonal shift, AMD ordering). Setup and the two triangular
/// solves are sequential whatever the policy; it pays where it saves more PCG iterations than the
/// parallel block-Jacobi loses in per-iteration speed.
///
///     physics::ConjugateGradient<physics::IncompleteCholesky<>> pcg({.tolerance = 1e-4});

#include <memory>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "linear_solver.hpp"

namespace simsr::physics {

/// z ≈ A⁻¹ r through an incomplete factorization L Lᵀ ≈ A (see the file comment).
template <class S = Scalar>
class IncompleteCholesky {
 public:
  template <exec::HostPolicy P>
  void compute(P, const SparseMatrix<S>& A) {
    if (!ic_) ic_ = std::make_shared<Factorization>();
    // A symmetric row-major CSR read as column-major is the same matrix.
    const Eigen::Map<const Eigen::SparseMatrix<S, Eigen::ColMajor, int>> Ac(A.rows(), A.cols(), A.nonZeros(), A.outerIndexPtr(),
                                                                          A.innerIndexPtr(), A.valuePtr());
    ic_->compute(Ac);
    if (ic_->info() != Eigen::Success)
      throw ConvergenceError("IncompleteCholesky (factorization failed: the shifted matrix is not positive definite)", 0, 0.0);
  }
  template <exec::HostPolicy P>
  void apply(P, const VecX<S>& r, VecX<S>& z) const {
    z = ic_->solve(r);
  }

 private:
  // Eigen's factorizations can be neither copied nor moved.
  using Factorization = Eigen::IncompleteCholesky<S, Eigen::Lower, Eigen::AMDOrdering<int>>;
  std::shared_ptr<Factorization> ic_;
};

}  // namespace simsr::physics
