#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::BatchNorm1d train: two-pass batch statistics, PyTorch's running-average update") {
  std::mt19937_64 rng(21);
  nn::ParameterStore<double> store;
  nn::BatchNorm1d<double> bn(store, "bn", 4);
  bn.weight() << 1.5, -0.5, 2.0, 0.25;
  bn.bias() << 0.1, 0.2, -0.3, 0.0;
  Matrix<double> x = random_matrix(rng, 37, 4, -2, 3);
  x.col(2).array() += 100;  // a large offset: one-pass E[x²] − E[x]² would lose digits here
  Matrix<double> y;
  bn.forward(exec::seq, nn::Mode::train, x, y);
  const Index R = x.rows();
  for (Index c = 0; c < 4; ++c) {
    long double mean = 0, var = 0;
    for (Index r = 0; r < R; ++r) mean += x(r, c);
    mean /= R;
    for (Index r = 0; r < R; ++r) var += (x(r, c) - mean) * (x(r, c) - mean);
    var /= R;
    for (Index r = 0; r < R; ++r) {
      const long double ref = (x(r, c) - mean) / std::sqrt(var + 1e-5L) * bn.weight()[c] + bn.bias()[c];
      CHECK(std::abs(double(ref - y(r, c))) < 1e-13);
    }
    CHECK(bn.running_mean()[c] == doctest::Approx(double(0.1L * mean)).epsilon(1e-14));
    CHECK(bn.running_var()[c] == doctest::Approx(double(0.9L + 0.1L * var * R / (R - 1))).epsilon(1e-14));
  }
  CHECK(bn.num_batches_tracked() == 1.0);
  bn.forward(exec::seq, nn::Mode::train, x, y);
  CHECK(bn.num_batches_tracked() == 2.0);
}

TEST_CASE("nn::BatchNorm1d eval: normalizes with the running statistics and leaves them alone") {
  std::mt19937_64 rng(22);
  nn::ParameterStore<double> store;
  nn::BatchNorm1d<double> bn(store, "bn", 3);
  bn.running_mean() << 1, -2, 0.5;
  bn.running_var() << 4, 0.25, 9;
  bn.weight() << 2, 1, -1;
  bn.bias() << 0, 1, 0.5;
  const Matrix<double> x = random_matrix(rng, 5, 3);
  Matrix<double> y;
  const nn::Vector<double> buffers = store.buffers();
  bn.forward(exec::seq, nn::Mode::eval, x, y);
  CHECK(test::bitwise_equal(buffers, nn::Vector<double>(store.buffers())));
  for (Index r = 0; r < 5; ++r)
    for (Index c = 0; c < 3; ++c)
      CHECK(y(r, c) == doctest::Approx((x(r, c) - bn.running_mean()[c]) / std::sqrt(bn.running_var()[c] + 1e-5) * bn.weight()[c] + bn.bias()[c]).epsilon(1e-14));
  Matrix<double> one = x.topRows(1), y1;
  bn.forward(exec::seq, nn::Mode::eval, one, y1);  // one row is fine in eval
  CHECK(y1.row(0) == y.row(0));
  CHECK_THROWS_AS(bn.forward(exec::seq, nn::Mode::train, one, y1), ArgumentError);
}

TEST_CASE("nn::BatchNorm1d: full Jacobian-vector products match finite differences (train and eval)") {
  std::mt19937_64 rng(23);
  std::uniform_int_distribution<int> size(2, 12);
  for (int trial = 0; trial < 10; ++trial) {
    const Index rows = trial == 0 ? 2 : size(rng), channels = size(rng) / 2;
    const bool affine = trial % 3 != 2;
    INFO("rows " << rows << " channels " << channels << " affine " << affine);
    nn::ParameterStore<double> store;
    nn::BatchNorm1d<double> bn(store, "bn", channels, {.affine = affine});
    if (affine) {
      bn.weight() = random_matrix(rng, channels, 1, 0.5, 2);
      bn.bias() = random_matrix(rng, channels, 1);
    }
    bn.running_mean() = random_matrix(rng, channels, 1);
    bn.running_var() = random_matrix(rng, channels, 1, 0.5, 2);
    const Matrix<double> x = random_matrix(rng, rows, channels, -2, 2);
    test::check_gradients(test::layer_gradient_check(bn, &store, x, nn::Mode::train, rng));
    test::check_gradients(test::layer_gradient_check(bn, &store, x, nn::Mode::eval, rng));
  }
}

TEST_CASE("nn::BatchNorm1d: state-dict tensors, seq == omp bitwise, warm calls allocate nothing") {
  std::mt19937_64 rng(24);
  nn::ParameterStore<float> store;
  nn::BatchNorm1d<float> bn(store, "fc_out.1", 96);
  CHECK(store.num_parameters() == 192);
  CHECK(store.at("fc_out.1.running_var").shape == std::vector<Index>{96});
  CHECK(store.at("fc_out.1.num_batches_tracked").shape.empty());
  bn.weight() = random_matrix(rng, 96, 1, 0.5, 2).cast<float>();
  const Matrix<float> x = random_matrix(rng, 2000, 96, -3, 5).cast<float>();
  test::check_seq_equals_omp(bn, &store, x, nn::Mode::train, rng);
  test::check_seq_equals_omp(bn, &store, x, nn::Mode::eval, rng);
  test::check_warm_no_allocation(exec::omp, bn, x, nn::Mode::train);
  test::check_warm_no_allocation(exec::seq, bn, x, nn::Mode::eval);
  CHECK_THROWS_AS(nn::BatchNorm1d<float>(store, "bad", 3, {.momentum = 2}), ArgumentError);
  Matrix<float> y;
  CHECK_THROWS_AS(bn.forward(exec::seq, nn::Mode::train, Matrix<float>(4, 95), y), ShapeError);
}
