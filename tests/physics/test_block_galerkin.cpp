#include <simsr/physics/linear_solvers/block_galerkin.hpp>
#include <simsr/physics/linear_solvers/multigrid.hpp>

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <random>

#include "stiffness_system.hpp"

using namespace simsr;
using namespace simsr::physics;

using simsr_test::stiffness_system;

namespace {

/// P = D (W ⊗ I₃) as a dense matrix, from the vertex weights and the dropped DOFs.
Eigen::MatrixXd dense_prolongation(const SparseMatrix<>& W, const std::vector<char>& dropped) {
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(3 * W.rows(), 3 * W.cols());
  for (Index v = 0; v < W.rows(); ++v)
    for (SparseMatrix<>::InnerIterator it(W, v); it; ++it)
      for (int d = 0; d < 3; ++d)
        if (!dropped[std::size_t(3 * v + d)]) P(3 * v + d, 3 * it.col() + d) = it.value();
  return P;
}

}  // namespace

TEST_CASE("vertex_weights: lattice_hierarchy's prolongations are W ⊗ I3; other forms are refused") {
  auto s = stiffness_system(8, 3, 1);
  const auto levels = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 30});
  REQUIRE(!levels.prolongations.empty());
  for (const auto& P : levels.prolongations) {
    const auto W = vertex_weights(P);
    REQUIRE(W.has_value());
    std::vector<char> none(std::size_t(P.rows()), 0);
    CHECK((dense_prolongation(*W, none) - Eigen::MatrixXd(P)).cwiseAbs().maxCoeff() == 0.0);
  }
  SparseMatrix<> P = levels.prolongations[0];
  P.valuePtr()[1] *= 0.5;  // row 0's second weight no longer row 1's: not W ⊗ I3
  CHECK_FALSE(vertex_weights(P).has_value());
  SparseMatrix<> mixed(6, 6);  // a coupling across coordinates
  mixed.insert(0, 1) = 1.0;
  mixed.makeCompressed();
  CHECK_FALSE(vertex_weights(mixed).has_value());
}

TEST_CASE("BlockGalerkin equals the dense D(W⊗I)ᵀ A D(W⊗I) on stiffness systems with random dropped DOFs; seq == omp bitwise; patterns rebuild") {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> coin(0, 1);
  for (unsigned seed = 1; seed <= 4; ++seed) {
    auto s = stiffness_system(6 + 2 * seed, 3, seed);
    const SparseMatrix<>& A = s.A();
    // the cell size doubling per level (coarsening 0): these small beams keep a second coarse
    // level, whose weights the end of the case multiplies with
    const auto levels = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 20, .coarsening = 0});
    REQUIRE(levels.prolongations.size() > 1);
    const SparseMatrix<> W = *vertex_weights(levels.prolongations[0]);
    // dropped: the system's fixed DOFs and random single DOFs (partly dropped vertices)
    std::vector<char> dropped(std::size_t(A.rows()));
    for (Index k = 0; k < A.rows(); ++k) dropped[std::size_t(k)] = s.fixed[std::size_t(k)] || coin(rng) < 0.1;
    BlockCsr<double> Ab;
    Ab.assign(exec::seq, A);
    BlockGalerkin<double> seq, omp;
    const Eigen::MatrixXd Ac = Eigen::MatrixXd(seq.compute(exec::seq, Ab, W, dropped));
    const Eigen::MatrixXd P = dense_prolongation(W, dropped);
    const Eigen::MatrixXd ref = P.transpose() * Eigen::MatrixXd(A) * P;
    CAPTURE(seed);
    CHECK((Ac - ref).cwiseAbs().maxCoeff() <= 1e-12 * ref.cwiseAbs().maxCoeff());
    CHECK(Eigen::MatrixXd(omp.compute(exec::omp, Ab, W, dropped)) == Ac);
    // whole 3×3 blocks: every row of a coarse vertex stores the same columns
    const SparseMatrix<>& C = seq.result();
    for (Index c = 0; c < C.rows() / 3; ++c)
      for (int d = 1; d < 3; ++d) CHECK(C.outerIndexPtr()[3 * c + d + 1] - C.outerIndexPtr()[3 * c + d] == C.outerIndexPtr()[3 * c + 1] - C.outerIndexPtr()[3 * c]);
    // new values, same patterns: no new structure, the new product
    const auto version = seq.structure_version();
    SparseMatrix<> A2 = A;
    for (Index k = 0; k < A2.nonZeros(); ++k) A2.valuePtr()[k] *= 1.0 + 0.5 * coin(rng);
    Ab.assign(exec::seq, A2);
    const Eigen::MatrixXd Ac2 = Eigen::MatrixXd(seq.compute(exec::seq, Ab, W, dropped));
    CHECK(seq.structure_version() == version);
    const Eigen::MatrixXd ref2 = P.transpose() * Eigen::MatrixXd(A2) * P;
    CHECK((Ac2 - ref2).cwiseAbs().maxCoeff() <= 1e-12 * ref2.cwiseAbs().maxCoeff());
    // the next level's weights: another pattern, rebuilt
    if (levels.prolongations.size() > 1) {
      const SparseMatrix<> Ac_sparse = seq.result();
      const SparseMatrix<> W1 = *vertex_weights(levels.prolongations[1]);
      BlockCsr<double> Cb;
      Cb.assign(exec::seq, Ac_sparse);
      const std::vector<char> none(std::size_t(Ac_sparse.rows()), 0);
      const Eigen::MatrixXd Ac1 = Eigen::MatrixXd(seq.compute(exec::seq, Cb, W1, none));
      CHECK(seq.structure_version() != version);
      const Eigen::MatrixXd P1 = dense_prolongation(W1, none);
      const Eigen::MatrixXd ref1 = P1.transpose() * Eigen::MatrixXd(Ac_sparse) * P1;
      CHECK((Ac1 - ref1).cwiseAbs().maxCoeff() <= 1e-12 * ref1.cwiseAbs().maxCoeff());
    }
  }
}

TEST_CASE("BlockGalerkin: bad input is a typed error") {
  auto s = stiffness_system(6, 3, 2);
  const auto levels = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 20});
  const SparseMatrix<> W = *vertex_weights(levels.prolongations[0]);
  BlockCsr<double> Ab;
  Ab.assign(exec::seq, s.A());
  BlockGalerkin<double> g;
  CHECK_THROWS_AS(g.compute(exec::seq, Ab, W, std::vector<char>(3, 0)), ShapeError);
  const SparseMatrix<> W_short = W.topRows(W.rows() - 1);
  CHECK_THROWS_AS(g.compute(exec::seq, Ab, W_short, std::vector<char>(std::size_t(s.A().rows()), 0)), ShapeError);
}

TEST_CASE("Multigrid: block and scalar Galerkin levels give the same V-cycle to rounding, with Dirichlet rows") {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    auto s = stiffness_system(16, 4, seed);
    // coarsening 0: three levels or more on this beam (the default coarsening stops at two)
    const auto prolongations = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 40, .coarsening = 0}).prolongations;
    Multigrid<> scalar(prolongations, {.storage = MultigridOptions::Storage::csr}), blocks(prolongations, {.storage = MultigridOptions::Storage::block});
    scalar.compute(exec::omp, s.A());
    blocks.compute(exec::omp, s.A());
    REQUIRE(blocks.num_levels() >= 3);
    VecX<> z_scalar, z_blocks;
    scalar.apply(exec::omp, s.b, z_scalar);
    blocks.apply(exec::omp, s.b, z_blocks);
    CAPTURE(seed);
    CHECK((z_blocks - z_scalar).norm() <= 1e-10 * z_scalar.norm());
    for (Index l = 0; l + 1 < blocks.num_levels(); ++l) CHECK(std::abs(blocks.damping(l) - scalar.damping(l)) <= 1e-10 * scalar.damping(l));
    // the caller's block copy of A (ConjugateGradient's) in place of the multigrid's own: the same V-cycle, bitwise
    for (const auto storage : {MultigridOptions::Storage::block, MultigridOptions::Storage::block_single}) {
      BlockCsr<double> Ab;
      Ab.assign(exec::omp, s.A());
      Multigrid<> own(prolongations, {.storage = storage}), given(prolongations, {.storage = storage});
      own.compute(exec::omp, s.A());
      given.compute(exec::omp, s.A(), Ab);
      VecX<> z_own, z_given;
      own.apply(exec::omp, s.b, z_own);
      given.apply(exec::omp, s.b, z_given);
      CHECK(z_given == z_own);
    }
    BlockCsr<double> wrong;
    wrong.assign(exec::seq, SparseMatrix<>(3, 3));
    Multigrid<> mg(prolongations);
    CHECK_THROWS_AS(mg.compute(exec::seq, s.A(), wrong), ShapeError);
  }
}
