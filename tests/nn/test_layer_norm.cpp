#include "gradient_check.hpp"

namespace nn_test_layer_norm {

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::LayerNorm: each row normalized to mean 0 / variance 1 before γ, β; gradients by finite differences; seq == omp") {
  std::mt19937_64 rng(41);
  nn::ParameterStore<double> store;
  nn::LayerNorm<double> ln(store, "norm", 6);
  const Matrix<double> x = random_matrix(rng, 70, 6, -3, 5);
  Matrix<double> y;
  ln.forward(exec::seq, nn::Mode::train, x, y);
  for (Index r = 0; r < y.rows(); ++r) {
    CHECK(std::abs(y.row(r).mean()) < 1e-12);
    const double var = (y.row(r).array() - y.row(r).mean()).square().mean();
    CHECK(var == doctest::Approx(1.0).epsilon(1e-4));  // eps = 1e-5 under the root
  }
  // γ and β away from their initial 1 and 0, so their gradients are checked in general position
  ln.weight() = random_matrix(rng, 1, 6, 0.5, 2);
  ln.bias() = random_matrix(rng, 1, 6, -1, 1);
  test::check_gradients(test::layer_gradient_check(ln, &store, x, nn::Mode::train, rng), 1e-6);
  test::check_seq_equals_omp(ln, &store, x, nn::Mode::train, rng);
  CHECK_THROWS_AS(nn::LayerNorm<double>(store, "bad", 0), ArgumentError);
  CHECK_THROWS_AS(ln.forward(exec::seq, nn::Mode::train, Matrix<double>(Matrix<double>::Zero(3, 5)), y), ShapeError);
}

}  // namespace nn_test_layer_norm
