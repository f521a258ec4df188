#pragma once
/// \file
/// The LinearSolver concept: how the Newton solver solves H d = −g (SPEC §3: PCG with Jacobi or
/// block-Jacobi preconditioning, or Eigen's sparse Cholesky, swapped by one type).
///
///     solver.compute(A, pattern_version);   // numeric setup; symbolic too when the version changed
///     LinearSolveInfo info = solver.solve(b, x);
///
/// A is symmetric positive (semi-)definite, row-major CSR (physics::SparseMatrix); it must stay
/// alive and unchanged between compute() and the solves that use it.

#include <concepts>
#include <cstdint>

#include "../../core/types.hpp"
#include "../hessian.hpp"

namespace simsr::physics {

/// What one solve did.
struct LinearSolveInfo {
  Index iterations = 0;            ///< iterations (0 for direct solvers)
  double relative_residual = 0;    ///< ‖b − A x‖ / ‖b‖ (0 when b = 0)
  bool converged = true;           ///< met its tolerance (direct solvers: factorization succeeded)
};

/// A solver for the Newton systems (see the file comment).
template <class L>
concept LinearSolver = requires(L& l, const SparseMatrix<typename L::scalar_type>& A, const VecX<typename L::scalar_type>& b,
                                VecX<typename L::scalar_type>& x, std::uint64_t version) {
  typename L::scalar_type;
  l.compute(A, version);
  { l.solve(b, x) } -> std::same_as<LinearSolveInfo>;
};

}  // namespace simsr::physics
