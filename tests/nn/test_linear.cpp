#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::Linear: forward is in·Wᵀ + b, row by row") {
  std::mt19937_64 rng(1);
  nn::Rng init(2);
  for (bool bias : {true, false}) {
    nn::ParameterStore<double> store;
    nn::Linear<double> l(store, "l", 6, 4, init, {.bias = bias});
    const Matrix<double> x = random_matrix(rng, 150, 6);
    Matrix<double> y;
    l.forward(exec::seq, nn::Mode::train, x, y);
    REQUIRE(y.rows() == 150);
    REQUIRE(y.cols() == 4);
    double err = 0;
    for (Index r = 0; r < 150; ++r)
      for (Index o = 0; o < 4; ++o) {
        long double s = bias ? l.bias()[o] : 0.0;
        for (Index i = 0; i < 6; ++i) s += (long double)x(r, i) * l.weight()(o, i);
        err = std::max(err, double(std::abs(s - y(r, o))));
      }
    CHECK(err < 1e-14);
  }
}

TEST_CASE("nn::Linear: a column block of a wider matrix is read in place") {
  std::mt19937_64 rng(5);
  nn::Rng init(6);
  nn::ParameterStore<float> store;
  nn::Linear<float> l(store, "l", 5, 3, init);
  const Matrix<float> wide = random_matrix(rng, 40, 9).cast<float>();
  const Matrix<float> part = wide.middleCols(2, 5);
  Matrix<float> a, b;
  l.forward(exec::seq, nn::Mode::eval, wide.middleCols(2, 5), a);
  l.forward(exec::seq, nn::Mode::eval, part, b);
  CHECK(test::bitwise_equal(a, b));
}

TEST_CASE("nn::Linear: gradients match finite differences over random shapes") {
  std::mt19937_64 rng(7);
  nn::Rng init(8);
  std::uniform_int_distribution<int> size(1, 9);
  for (int trial = 0; trial < 12; ++trial) {
    const Index rows = trial == 0 ? 1 : size(rng) * 3, in = size(rng), out = size(rng);
    const bool bias = trial % 2 == 0;
    INFO("rows " << rows << " in " << in << " out " << out << " bias " << bias);
    nn::ParameterStore<double> store;
    nn::Linear<double> l(store, "l", in, out, init, {.bias = bias});
    test::check_gradients(test::layer_gradient_check(l, &store, random_matrix(rng, rows, in), nn::Mode::train, rng));
  }
}

TEST_CASE("nn::Linear: gradients accumulate across backward calls until zero_grad") {
  std::mt19937_64 rng(9);
  nn::Rng init(10);
  nn::ParameterStore<double> store;
  nn::Linear<double> l(store, "l", 3, 2, init);
  const Matrix<double> x = random_matrix(rng, 5, 3), d = random_matrix(rng, 5, 2);
  Matrix<double> y;
  l.forward(exec::seq, nn::Mode::train, x, y);
  l.backward(exec::seq, x, y, d, nullptr);
  const nn::Vector<double> once = store.gradients();
  l.backward(exec::seq, x, y, d, nullptr);
  CHECK((store.gradients() - 2 * once).cwiseAbs().maxCoeff() < 1e-14);
  CHECK(once.cwiseAbs().maxCoeff() > 0);
  CHECK((Matrix<double>(l.weight_grad()) - 2 * d.transpose() * x).cwiseAbs().maxCoeff() < 1e-13);
}

TEST_CASE("nn::Linear: PyTorch default init U(±1/√in), explicit setters, errors") {
  nn::Rng init(11);
  nn::ParameterStore<float> store;
  nn::Linear<float> l(store, "fc", 64, 48, init);
  const double bound = 1.0 / 8.0;
  CHECK(l.weight().cwiseAbs().maxCoeff() <= bound);
  CHECK(l.weight().cwiseAbs().maxCoeff() > 0.95 * bound);
  CHECK(l.bias().cwiseAbs().maxCoeff() <= bound);
  CHECK(std::abs(l.weight().mean()) < 0.01);
  Matrix<double> W = Matrix<double>::Constant(48, 64, 0.5);
  l.set_weight(W);
  CHECK(l.weight()(3, 7) == 0.5f);
  CHECK_THROWS_AS(l.set_weight(Matrix<double>(64, 48)), ShapeError);
  CHECK_THROWS_AS(l.set_bias(nn::Vector<float>(3)), ShapeError);
  Matrix<float> x(10, 63), y;
  try {
    l.forward(exec::seq, nn::Mode::train, x, y);
    FAIL("no ShapeError");
  } catch (const ShapeError& e) {
    CHECK(std::string(e.what()).find("nn::Linear 'fc'") != std::string::npos);
    CHECK(e.expected() == std::vector<std::int64_t>{-1, 64});
    CHECK(e.got() == std::vector<std::int64_t>{10, 63});
  }
  CHECK_THROWS_AS(nn::Linear<float>(store, "zero", 0, 3, init), ArgumentError);
}

TEST_CASE("nn::Linear: exec::seq and exec::omp agree bit for bit; warm calls allocate nothing") {
  std::mt19937_64 rng(12);
  nn::Rng init(13);
  nn::ParameterStore<float> store;
  nn::Linear<float> l(store, "net_feat_emb.blocks.0.fc_out.0", 35, 64, init);
  const Matrix<float> x = random_matrix(rng, 1000, 35).cast<float>();
  test::check_seq_equals_omp(l, &store, x, nn::Mode::train, rng);
  nn::Linear<float> nb(store, "nb", 35, 19, init, {.bias = false});
  test::check_seq_equals_omp(nb, &store, x, nn::Mode::train, rng);
  test::check_warm_no_allocation(exec::seq, l, x, nn::Mode::train);
  test::check_warm_no_allocation(exec::omp, l, x, nn::Mode::train);
}
