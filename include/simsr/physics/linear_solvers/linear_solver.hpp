#pragma once
/// \file
/// The LinearSolver concept: how the Newton solver solves H d = −g (SPEC §3: PCG with Jacobi or
/// block-Jacobi preconditioning, or Eigen's sparse Cholesky, swapped by one type).
///
///     solver.compute(policy, A, pattern_version);   // numeric setup; symbolic too when the version changed
///     LinearSolveInfo info = solver.solve(policy, b, x);
///
/// The policy comes first in both calls (exec::seq or exec::omp; a sequential solver such as
/// SparseCholesky takes it too and starts no thread under exec::seq).
///
/// A is symmetric positive (semi-)definite, row-major CSR (physics::SparseMatrix); it must stay
/// alive and unchanged between compute() and the solves that use it.

#include <concepts>
#include <cstdint>

#include "../../core/exec/policy.hpp"
#include "../../core/types.hpp"
#include "../hessian.hpp"

namespace simsr::physics {

/// What one solve did.
struct LinearSolveInfo {
  Index iterations = 0;            ///< iterations (0 for direct solvers)
  double relative_residual = 0;    ///< ‖b − A x‖ / ‖b‖ (0 when b = 0)
  bool converged = true;           ///< met its tolerance (direct solvers: factorization succeeded)
};

namespace detail {
template <class L>
concept HasLinearScalar = requires { typename L::scalar_type; };
template <class L>
concept HasLinearCompute =
    HasLinearScalar<L> && requires(L& l, const SparseMatrix<typename L::scalar_type>& A, std::uint64_t version) {
      l.compute(exec::seq, A, version);
      l.compute(exec::omp, A, version);
    };
template <class L>
concept HasLinearSolve =
    HasLinearScalar<L> && requires(L& l, const VecX<typename L::scalar_type>& b, VecX<typename L::scalar_type>& x) {
      { l.solve(exec::seq, b, x) } -> std::same_as<LinearSolveInfo>;
      { l.solve(exec::omp, b, x) } -> std::same_as<LinearSolveInfo>;
    };
}  // namespace detail

/// A solver for the Newton systems (see the file comment).
template <class L>
concept LinearSolver = detail::HasLinearScalar<L> && detail::HasLinearCompute<L> && detail::HasLinearSolve<L>;

/// `static_assert(assert_linear_solver<L>())`: a type that is not a LinearSolver stops the build
/// with one sentence naming the first thing it lacks (and nothing else: the function returns true
/// once its own assertion has spoken).
template <class L>
constexpr bool assert_linear_solver() {
  using namespace detail;
  constexpr int lacks = !HasLinearScalar<L> ? 0 : !HasLinearCompute<L> ? 1 : !HasLinearSolve<L> ? 2 : -1;
  static_assert(lacks != 0, "this type is not a physics::LinearSolver: it lacks the member type scalar_type");
  static_assert(lacks != 1, "this type is not a physics::LinearSolver: it lacks compute(policy, const SparseMatrix& A, std::uint64_t "
                            "pattern_version) for exec::seq and exec::omp, e.g. SparseCholesky<> or ConjugateGradient<BlockJacobi<>>");
  static_assert(lacks != 2, "this type is not a physics::LinearSolver: it lacks solve(policy, const VecX& b, VecX& x) -> LinearSolveInfo "
                            "for exec::seq and exec::omp");
  return true;
}

namespace detail {
/// L's scalar_type, or Scalar when L lacks one (so a class that asserts LinearSolver<L> reports
/// that sentence and no follow-on error).
template <class L>
struct linear_scalar {
  using type = Scalar;
};
template <HasLinearScalar L>
struct linear_scalar<L> {
  using type = typename L::scalar_type;
};
}  // namespace detail

}  // namespace simsr::physics
