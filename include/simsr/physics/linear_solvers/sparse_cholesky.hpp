#pragma once
/// \file
/// Sparse direct solver: Eigen's simplicial LDLᵀ with AMD ordering. The symbolic analysis is
/// redone only when the Hessian's pattern changes; each Newton iteration refactorizes.
///
///     physics::QuasistaticSolver<physics::SparseCholesky<>> newton(mesh.num_vertices(), mesh.T);
///     chol.compute(exec::seq, A, pattern_version);  chol.solve(exec::seq, b, x);
///
/// The factorization and the triangular solves are sequential whatever the policy; the policy
/// runs the residual check ‖b − A x‖ (under exec::seq no thread is started: Eigen's own sparse
/// product would start OpenMP threads).

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "linear_solver.hpp"
#include "sparse_ops.hpp"

namespace simsr::physics {

/// LDLᵀ of a symmetric positive definite matrix (see the file comment). Sequential (Eigen's
/// simplicial factorization has no parallel path).
template <class S = Scalar>
class SparseCholesky {
 public:
  using scalar_type = S;

  SparseCholesky() = default;
  /// Factorizes A + relative_shift·max|A_ii|·I instead of A (Multigrid's coarsest level, which
  /// may be only semidefinite).
  explicit SparseCholesky(double relative_shift) : relative_shift_(relative_shift) {}

  /// Throws ConvergenceError (0 iterations, residual NaN) when the factorization breaks down
  /// (a zero pivot: the matrix is singular, e.g. rigid motions left unconstrained).
  template <exec::HostPolicy P>
  void compute(P, const SparseMatrix<S>& A, std::uint64_t pattern_version = 0) {
    if (A.rows() != A.cols()) throw ShapeError("SparseCholesky: matrix", {A.rows(), A.rows()}, {A.rows(), A.cols()});
    // A symmetric row-major CSR read as column-major is its transpose, i.e. itself.
    const Eigen::Map<const Eigen::SparseMatrix<S, Eigen::ColMajor, int>> Ac(A.rows(), A.cols(), A.nonZeros(), A.outerIndexPtr(),
                                                                          A.innerIndexPtr(), A.valuePtr());
    if (!ldlt_) ldlt_ = std::make_unique<Factorization>();
    if (pattern_.changed(A, pattern_version)) ldlt_->analyzePattern(Ac);
    if (relative_shift_ != 0) ldlt_->setShift(S(relative_shift_) * A.diagonal().cwiseAbs().maxCoeff());
    ldlt_->factorize(Ac);
    if (ldlt_->info() != Eigen::Success)
      throw ConvergenceError("SparseCholesky (LDLT factorization: singular matrix)", 0, std::numeric_limits<double>::quiet_NaN());
    A_ = &A;
  }

  /// Whether the last factorized matrix was positive definite (every pivot of D > 0).
  bool positive_definite() const { return ldlt_ && (ldlt_->vectorD().array() > S(0)).all(); }

  /// x = A⁻¹ b; the relative residual is computed under `policy`.
  template <exec::HostPolicy P>
  LinearSolveInfo solve(P policy, const VecX<S>& b, VecX<S>& x) {
    if (!A_) throw Error("SparseCholesky::solve called before compute");
    if (b.size() != pattern_.rows) throw ShapeError("SparseCholesky: right-hand side", {pattern_.rows}, {b.size()});
    x = ldlt_->solve(b);
    return detail::direct_solve_info(policy, *A_, b, x, Ax_);
  }

 private:
  // Eigen's factorizations can be neither copied nor moved: held by pointer so the solver can be
  // passed by value into QuasistaticSolver.
  using Factorization = Eigen::SimplicialLDLT<Eigen::SparseMatrix<S, Eigen::ColMajor, int>, Eigen::Lower, Eigen::AMDOrdering<int>>;
  std::unique_ptr<Factorization> ldlt_;
  const SparseMatrix<S>* A_ = nullptr;
  VecX<S> Ax_;
  detail::AnalysedPattern pattern_;
  double relative_shift_ = 0;
};

}  // namespace simsr::physics
