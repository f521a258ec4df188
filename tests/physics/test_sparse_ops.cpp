#include <simsr/physics/hessian.hpp>
#include <simsr/physics/linear_solvers/sparse_ops.hpp>

#include <doctest/doctest.h>

#include <random>

using namespace simsr;
using namespace simsr::physics;

namespace {

SparseMatrix<> random_sparse(Index rows, Index cols, double density, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1), coin(0, 1);
  std::vector<Eigen::Triplet<double, int>> t;
  for (Index i = 0; i < rows; ++i)
    for (Index j = 0; j < cols; ++j)
      if (coin(rng) < density) t.emplace_back(int(i), int(j), U(rng));
  SparseMatrix<> M(rows, cols);
  M.setFromTriplets(t.begin(), t.end());
  M.makeCompressed();
  return M;
}

}  // namespace

TEST_CASE("SparseProduct equals Eigen's sparse product on random matrices; values refresh, patterns rebuild; seq == omp bitwise") {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    const Index n = 5 + trial * 3, m = 4 + trial, k = 3 + 2 * trial;
    const double density = 0.05 + 0.02 * (trial % 10);
    SparseMatrix<> A = random_sparse(n, m, density, rng), B = random_sparse(m, k, density, rng);
    SparseProduct<double> seq, omp;
    const SparseMatrix<> ref = A * B;
    const Eigen::MatrixXd C = Eigen::MatrixXd(seq.compute(exec::seq, A, B));
    CHECK((C - Eigen::MatrixXd(ref)).cwiseAbs().maxCoeff() <= 1e-14);
    const auto version = seq.structure_version();
    // same patterns, new values: only values change
    for (Index q = 0; q < A.nonZeros(); ++q) A.valuePtr()[q] *= -2.5;
    const Eigen::MatrixXd C2 = Eigen::MatrixXd(seq.compute(exec::seq, A, B));
    CHECK(seq.structure_version() == version);
    CHECK((C2 - Eigen::MatrixXd(SparseMatrix<>(A * B))).cwiseAbs().maxCoeff() <= 1e-14);
    const SparseMatrix<>& Co = omp.compute(exec::omp, A, B);
    CHECK(std::equal(Co.valuePtr(), Co.valuePtr() + Co.nonZeros(), seq.result().valuePtr()));
    // a new pattern rebuilds the structure
    const SparseMatrix<> A3 = random_sparse(n, m, density + 0.1, rng);
    const Eigen::MatrixXd C3 = Eigen::MatrixXd(seq.compute(exec::seq, A3, B));
    CHECK(seq.structure_version() != version);
    CHECK((C3 - Eigen::MatrixXd(SparseMatrix<>(A3 * B))).cwiseAbs().maxCoeff() <= 1e-14);
  }
  SparseProduct<double> p;
  std::mt19937 r2(1);
  CHECK_THROWS_AS(p.compute(exec::seq, random_sparse(3, 4, 0.5, r2), random_sparse(5, 2, 0.5, r2)), ShapeError);
}

TEST_CASE("sparse_multiply equals Eigen's product; seq == omp bitwise") {
  std::mt19937 rng(8);
  for (int trial = 0; trial < 10; ++trial) {
    const SparseMatrix<> A = random_sparse(50 + trial, 40 + trial, 0.1, rng);
    VecX<> v = VecX<>::Random(A.cols()), y_seq, y_omp;
    sparse_multiply(exec::seq, A, v, y_seq);
    sparse_multiply(exec::omp, A, v, y_omp);
    CHECK((y_seq - A * v).cwiseAbs().maxCoeff() <= 1e-13);
    CHECK(y_seq == y_omp);
    CHECK(std::abs(dot(exec::seq, v, v) - v.squaredNorm()) <= 1e-12 * v.squaredNorm());
  }
}
