#include <simsr/physics/linear_solvers/block_csr.hpp>
#include <simsr/physics/linear_solvers/linear_solvers.hpp>

#include <doctest/doctest.h>

#include <Eigen/SparseCholesky>
#include <random>

#include "stiffness_system.hpp"

using namespace simsr;
using namespace simsr::physics;

using simsr_test::stiffness_system;

namespace {

/// A random (3·br)×(3·bc) CSR matrix: random blocks present, each holding a random subset of its
/// nine entries (full blocks, partial ones and single entries, as a Hessian with Dirichlet rows has).
SparseMatrix<> random_blocked(Index br, Index bc, double density, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-2, 2), coin(0, 1);
  std::vector<Eigen::Triplet<double, int>> t;
  for (Index i = 0; i < br; ++i)
    for (Index j = 0; j < bc; ++j) {
      if (coin(rng) >= density) continue;
      const double fill = coin(rng) < 0.5 ? 1.0 : coin(rng);  // half the blocks full
      for (int e = 0; e < 9; ++e)
        if (coin(rng) < fill) t.emplace_back(int(3 * i + e / 3), int(3 * j + e % 3), U(rng));
    }
  SparseMatrix<> M(3 * br, 3 * bc);
  M.setFromTriplets(t.begin(), t.end());
  M.makeCompressed();
  return M;
}

/// |y − A x| ≤ `ulps`·ε·(|A| |x|) row by row: the rounding bound of a sum of products in any
/// fusing of its multiplies and adds.
bool within_rounding(const VecX<>& y, const SparseMatrix<>& A, const VecX<>& x, double ulps = 4) {
  const VecX<> exact = Eigen::MatrixXd(A) * x;  // a dense product: independent of both sparse kernels
  const VecX<> bound = (Eigen::MatrixXd(A).cwiseAbs() * x.cwiseAbs()) * (ulps * 0x1p-52) + VecX<>::Constant(x.size() ? A.rows() : 0, 1e-300);
  return ((y - exact).cwiseAbs() - bound).maxCoeff() <= 0;
}

VecX<> random_vector(Index n, std::mt19937& rng) {
  std::normal_distribution<double> N;
  VecX<> v(n);
  for (Index i = 0; i < n; ++i) v[i] = N(rng);
  return v;
}

}  // namespace

TEST_CASE("BlockCsr: the product is A x to rounding on random block patterns; seq == omp bitwise; values refresh, patterns rebuild") {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 60; ++trial) {
    const Index br = 1 + trial % 23, bc = 1 + (trial * 7) % 19;
    const double density = 0.05 + 0.9 * double(trial % 10) / 10;
    SparseMatrix<> A = random_blocked(br, bc, density, rng);
    CAPTURE(trial);
    const VecX<> x = random_vector(A.cols(), rng);
    VecX<> ref, y_seq, y_omp;
    sparse_multiply(exec::seq, A, x, ref);
    BlockCsr<double> seq, omp;
    seq.assign(exec::seq, A);
    omp.assign(exec::omp, A);
    seq.multiply(exec::seq, x, y_seq);
    omp.multiply(exec::omp, x, y_omp);
    CHECK(within_rounding(y_seq, A, x));
    CHECK(within_rounding(ref, A, x));
    CHECK(y_omp == y_seq);
    CHECK(seq.rows() == A.rows());
    CHECK(seq.cols() == A.cols());
    // every block holds A's entries (zero where A stores none)
    const Eigen::MatrixXd dense(A);
    Index nonzero_blocks = 0;
    for (Index i = 0; i < br; ++i)
      for (Index j = 0; j < bc; ++j) {
        CHECK(seq.block(i, j) == dense.block<3, 3>(3 * i, 3 * j));
        bool any = false;
        for (int e = 0; e < 9; ++e) any = any || A.coeff(3 * i + e / 3, 3 * j + e % 3) != 0.0;
        nonzero_blocks += any;
      }
    CHECK(seq.num_blocks() >= nonzero_blocks);
    // new values on the same pattern: the blocks follow
    for (Index k = 0; k < A.nonZeros(); ++k) A.valuePtr()[k] = -0.5 * A.valuePtr()[k] + 0.25;
    seq.assign(exec::seq, A);
    seq.multiply(exec::seq, x, y_seq);
    CHECK(within_rounding(y_seq, A, x));
    // another pattern (and size) in the same object: rebuilt
    const SparseMatrix<> B = random_blocked(bc, br, density, rng);
    const VecX<> xb = random_vector(B.cols(), rng);
    seq.assign(exec::seq, B);
    seq.multiply(exec::seq, xb, y_seq);
    CHECK(within_rounding(y_seq, B, xb));
  }
}

TEST_CASE("BlockCsr<double, float>: the product of the matrix rounded to single precision, summed in double") {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 30; ++trial) {
    const SparseMatrix<> A = random_blocked(4 + trial, 3 + 2 * trial, 0.3, rng);
    const VecX<> x = random_vector(A.cols(), rng);
    SparseMatrix<> rounded = A;
    for (Index k = 0; k < rounded.nonZeros(); ++k) rounded.valuePtr()[k] = double(float(rounded.valuePtr()[k]));
    VecX<> exact, y, y_seq;
    sparse_multiply(exec::seq, A, x, exact);
    BlockCsr<double, float> B;
    B.assign(exec::omp, A);
    B.multiply(exec::omp, x, y);
    B.multiply(exec::seq, x, y_seq);
    CHECK(within_rounding(y, rounded, x));
    CHECK(y == y_seq);
    CHECK(y != exact);  // the rounding shows (else this test could not tell the storage apart)
    // and within single precision's rounding of the double product
    const VecX<> bound = (Eigen::MatrixXd(A).cwiseAbs() * x.cwiseAbs()) * 1e-7;
    CHECK(((y - exact).cwiseAbs() - bound).maxCoeff() <= 0);
    CHECK(B.matrix_bytes() == (9 * sizeof(float) + sizeof(int)) * std::size_t(B.num_blocks()) + sizeof(int) * std::size_t(A.rows() / 3 + 1));
  }
}

TEST_CASE("BlockCsr: bad input is a typed error") {
  BlockCsr<double> B;
  SparseMatrix<> odd(4, 6);
  CHECK_THROWS_AS(B.assign(exec::seq, odd), ShapeError);
  SparseMatrix<> uncompressed(6, 6);
  uncompressed.insert(0, 1) = 1.0;
  CHECK_THROWS_AS(B.assign(exec::seq, uncompressed), ArgumentError);
  SparseMatrix<> A(6, 9);
  A.insert(1, 7) = 2.0;
  A.makeCompressed();
  B.assign(exec::seq, A);
  VecX<> y;
  CHECK_THROWS_AS(B.multiply(exec::seq, VecX<>::Ones(6), y), ShapeError);
  B.multiply(exec::seq, VecX<>::Ones(9), y);
  CHECK(y == (VecX<>(6) << 0, 2, 0, 0, 0, 0).finished());
}

TEST_CASE("PCG's block products and the multigrid's block storage: the CSR iterates to rounding; single-precision levels converge alike; seq == omp") {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    auto s = stiffness_system(20, 4, seed);
    const SparseMatrix<>& A = s.A();
    const auto prolongations = lattice_hierarchy(exec::omp, s.mesh, {.max_coarse_vertices = 40}).prolongations;
    auto solve = [&](auto policy, bool block_products, MultigridOptions::Storage storage, VecX<>& x) {
      ConjugateGradient<Multigrid<>> pcg({.tolerance = 1e-10, .block_products = block_products}, Multigrid<>(prolongations, {.storage = storage}));
      pcg.compute(policy, A);
      return pcg.solve(policy, s.b, x);
    };
    using Storage = MultigridOptions::Storage;
    VecX<> x_csr, x_block, x_block_seq, x_single, x_single_seq, x_mixed;
    const auto csr = solve(exec::omp, false, Storage::csr, x_csr);
    const auto block = solve(exec::omp, true, Storage::block, x_block);
    const auto mixed = solve(exec::omp, true, Storage::csr, x_mixed);
    const auto single = solve(exec::omp, true, Storage::block_single, x_single);
    solve(exec::seq, true, Storage::block, x_block_seq);
    solve(exec::seq, true, Storage::block_single, x_single_seq);
    CAPTURE(seed);
    const Eigen::SimplicialLDLT<SparseMatrix<>> ldlt(A);
    const VecX<> ref = ldlt.solve(s.b);
    for (const auto* run : {&csr, &block, &mixed}) {
      CHECK(run->converged);
      CHECK(std::abs(run->iterations - csr.iterations) <= 1);
    }
    CHECK((x_block - ref).norm() <= 1e-8 * ref.norm());
    CHECK((x_mixed - ref).norm() <= 1e-8 * ref.norm());
    CHECK(x_block_seq == x_block);
    CHECK(x_single_seq == x_single);
    // the V-cycle of the rounded matrices: still a preconditioner PCG converges with, to A's solution
    CHECK(single.converged);
    CHECK((x_single - ref).norm() <= 1e-8 * ref.norm());
    CHECK(single.iterations <= csr.iterations + 2);
    MESSAGE("seed ", seed, ": PCG iterations, double levels ", csr.iterations, ", single-precision levels ", single.iterations);
  }
}
