#include <simsr/mesh/generators.hpp>
#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/linear_solvers/linear_solvers.hpp>

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <random>

#include "stiffness_system.hpp"

using namespace simsr;
using namespace simsr::physics;

namespace {

/// An SPD system from a real stiffness matrix: a 4×2×2-cell StVK beam with its x = 0 end fixed.
simsr_test::StiffnessSystem make_system(unsigned seed) { return simsr_test::stiffness_system(4, 2, seed); }

template <class L>
void check_solver(auto policy, L solver, double tol) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    auto s = make_system(seed);
    const SparseMatrix<>& A = s.H.assemble(exec::seq, s.fixed);
    const Eigen::MatrixXd Ad(A);
    const VecX<> ref = Ad.ldlt().solve(s.b);
    solver.compute(policy, A, s.H.pattern_version());
    VecX<> x;
    const LinearSolveInfo info = solver.solve(policy, s.b, x);
    CHECK(info.converged);
    CHECK((x - ref).norm() <= tol * ref.norm());
    CHECK((Ad * x - s.b).norm() <= 10 * tol * s.b.norm());
  }
}

}  // namespace

TEST_CASE("linear solvers model the concept") {
  static_assert(LinearSolver<SparseCholesky<>>);
  static_assert(LinearSolver<ConjugateGradient<Jacobi<>>>);
  static_assert(LinearSolver<ConjugateGradient<BlockJacobi<>>>);
  static_assert(LinearSolver<ConjugateGradient<IncompleteCholesky<>>>);
  static_assert(LinearSolver<ConjugateGradient<Multigrid<>>>);
  static_assert(assert_linear_solver<ConjugateGradient<Multigrid<float>, float>>());
}

TEST_CASE("SparseCholesky and PCG (Jacobi, block-Jacobi; seq, omp) solve stiffness systems like a dense LDLT") {
  check_solver(exec::seq, SparseCholesky<>{}, 1e-10);
  check_solver(exec::omp, SparseCholesky<>{}, 1e-10);
  check_solver(exec::seq, ConjugateGradient<Jacobi<>>({.tolerance = 1e-11}), 1e-8);
  check_solver(exec::seq, ConjugateGradient<BlockJacobi<>>({.tolerance = 1e-11}), 1e-8);
  check_solver(exec::omp, ConjugateGradient<BlockJacobi<>>({.tolerance = 1e-11}), 1e-8);
  check_solver(exec::seq, ConjugateGradient<IncompleteCholesky<>>({.tolerance = 1e-11}), 1e-8);
}

TEST_CASE("PCG: block-Jacobi needs no more iterations than Jacobi, incomplete Cholesky fewer still; seq and omp iterate identically") {
  auto s = make_system(9);
  const SparseMatrix<>& A = s.H.assemble(exec::seq, s.fixed);
  ConjugateGradient<Jacobi<>> jac({.tolerance = 1e-8});
  ConjugateGradient<BlockJacobi<>> blk({.tolerance = 1e-8});
  ConjugateGradient<BlockJacobi<>> blk_omp({.tolerance = 1e-8});
  VecX<> x1, x2, x3;
  jac.compute(exec::seq, A);
  blk.compute(exec::seq, A);
  blk_omp.compute(exec::omp, A);
  const auto i1 = jac.solve(exec::seq, s.b, x1), i2 = blk.solve(exec::seq, s.b, x2), i3 = blk_omp.solve(exec::omp, s.b, x3);
  CHECK(i2.iterations <= i1.iterations);
  ConjugateGradient<IncompleteCholesky<>> ic({.tolerance = 1e-8});
  ic.compute(exec::seq, A);
  VecX<> x4;
  const auto i4 = ic.solve(exec::seq, s.b, x4);
  CHECK(i4.converged);
  CHECK(i4.iterations < i2.iterations);  // a stronger preconditioner: fewer (but sequential) iterations
  CHECK(i2.iterations == i3.iterations);
  CHECK((x2 - x3).cwiseAbs().maxCoeff() == 0.0);
}

/// Jacobi with the sign flipped on the DOFs where `flip` is set: not positive definite.
struct SignFlippedJacobi {
  Jacobi<> inner;
  std::vector<char> flip;
  template <exec::HostPolicy P>
  void compute(P policy, const SparseMatrix<>& A) {
    inner.compute(policy, A);
  }
  template <exec::HostPolicy P>
  void apply(P policy, const VecX<>& r, VecX<>& z) const {
    inner.apply(policy, r, z);
    for (Index i = 0; i < z.size(); ++i)
      if (flip[std::size_t(i)]) z[i] = -z[i];
  }
};

TEST_CASE("PCG stops at the first rᵀM⁻¹r ≤ 0 (a preconditioner that is not positive definite), unconverged, instead of running its whole count") {
  auto s = make_system(3);
  const SparseMatrix<>& A = s.H.assemble(exec::seq, s.fixed);
  const Index n = A.rows();
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    SignFlippedJacobi M;
    M.flip.assign(std::size_t(n), 0);
    // all DOFs (rᵀz < 0 at once) in the first trial, a random third of them in the others
    for (Index i = 0; i < n; ++i) M.flip[std::size_t(i)] = trial == 0 || rng() % 3 == 0;
    ConjugateGradient<SignFlippedJacobi> pcg({.tolerance = 1e-10}, M);
    pcg.compute(exec::seq, A);
    VecX<> x;
    const auto info = pcg.solve(exec::seq, s.b, x);
    CAPTURE(trial);
    // stopped at rᵀz ≤ 0, not at the count (without the check 18 of these trials ran the whole
    // count and 3 reached 1e-10 through the indefinite iteration anyway)
    CHECK_FALSE(info.converged);
    CHECK(info.iterations < n);
    if (trial == 0) {
      CHECK(info.iterations == 0);
      CHECK(x.norm() == 0.0);
    }
  }
}

TEST_CASE("PCG reports non-convergence; Cholesky of a singular matrix is a ConvergenceError; b = 0 gives x = 0") {
  auto s = make_system(3);
  const SparseMatrix<>& A = s.H.assemble(exec::seq, s.fixed);
  ConjugateGradient<Jacobi<>> pcg({.tolerance = 1e-12, .max_iterations = 3});
  pcg.compute(exec::seq, A);
  VecX<> x;
  const auto info = pcg.solve(exec::seq, s.b, x);
  CHECK_FALSE(info.converged);
  CHECK(info.iterations == 3);
  CHECK(info.relative_residual > 1e-12);
  CHECK(pcg.solve(exec::seq, VecX<>::Zero(s.b.size()), x).converged);
  CHECK(x.norm() == 0.0);

  // rank 2 in exact arithmetic: every symmetric pivot order meets an exact zero pivot
  Eigen::Matrix3d Sd;
  Sd << 1, 1, 0, 1, 1, 0, 0, 0, 1;
  const SparseMatrix<> singular = Eigen::MatrixXd(Sd).sparseView();
  SparseCholesky<> chol;
  CHECK_THROWS_WITH_AS(chol.compute(exec::seq, singular, 1), doctest::Contains("SparseCholesky"), ConvergenceError);
  chol.compute(exec::seq, A, s.H.pattern_version());
  CHECK_THROWS_AS(chol.solve(exec::seq, VecX<>::Zero(5), x), ShapeError);
}
