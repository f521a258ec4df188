#include "gradient_check.hpp"

#include <simsr/mesh/generators.hpp>

namespace nn_test_mesh_conv {

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::MeshConv: Eq. 5 by hand on a sheet, over a batch of two; gradients by finite differences; seq == omp") {
  std::mt19937_64 rng(42);
  nn::Rng init(43);
  const TriMesh<> sheet = square_sheet(1.0, 3);  // 16 vertices
  const Adjacency A = vertex_adjacency(sheet.F, sheet.V.rows());
  nn::ParameterStore<double> store;
  nn::MeshConv<double> conv(store, "conv", A, 4, 3, init);
  const Index V = 16;
  const Matrix<double> x = random_matrix(rng, 2 * V, 4);
  Matrix<double> y;
  conv.forward(exec::seq, nn::Mode::train, x, y);
  REQUIRE(y.rows() == 2 * V);
  const auto Wp = conv.point().weight(), Wn = conv.neighbor().weight();
  const auto b = conv.point().bias();
  for (Index item = 0; item < 2; ++item)
    for (Index i = 0; i < V; ++i) {
      Eigen::RowVectorXd mean = Eigen::RowVectorXd::Zero(4);
      for (const VIndex j : A[i]) mean += x.row(item * V + j);
      mean /= double(A.degree(i));
      const Eigen::RowVectorXd expect = x.row(item * V + i) * Wp.transpose() + mean * Wn.transpose() + b.transpose();
      CHECK((y.row(item * V + i) - expect).norm() < 1e-12);
    }
  test::check_gradients(test::layer_gradient_check(conv, &store, x, nn::Mode::train, rng), 1e-6);
  test::check_seq_equals_omp(conv, &store, x, nn::Mode::train, rng);
  CHECK_THROWS_AS(conv.forward(exec::seq, nn::Mode::train, Matrix<double>(random_matrix(rng, V + 1, 4)), y), ShapeError);
  Adjacency one_way;
  one_way.offsets = {0, 1, 1};
  one_way.neighbors = {1};
  CHECK_THROWS_AS(nn::MeshConv<double>(store, "bad", one_way, 2, 2, init), ArgumentError);
}

}  // namespace nn_test_mesh_conv
