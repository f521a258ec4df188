#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::PositionalEncoding: the table against std::sin / std::cos") {
  const Index N = 500, D = 32;
  nn::PositionalEncoding<double> pe(N);
  nn::PositionalEncoding<float> pef(N);
  REQUIRE(pe.table().rows() == N);
  REQUIRE(pe.table().cols() == D);
  double err = 0, errf = 0;
  for (Index i = 0; i < N; ++i)
    for (Index m = 0; m < D / 2; ++m) {
      const double a = double(i) / std::pow(10000.0, double(2 * m) / double(D));
      err = std::max({err, std::abs(pe.table()(i, 2 * m) - std::sin(a)), std::abs(pe.table()(i, 2 * m + 1) - std::cos(a))});
      errf = std::max({errf, std::abs(pef.table()(i, 2 * m) - std::sin(a)), std::abs(pef.table()(i, 2 * m + 1) - std::cos(a))});
    }
  CHECK(err < 1e-12);
  CHECK(errf < 1e-4);  // float arguments up to 500: a few ulps of 500 ≈ 1e-4
  CHECK(pe.table()(0, 0) == 0.0);
  CHECK(pe.table()(0, 1) == 1.0);
  CHECK(pe.table()(7, 0) == std::sin(7.0));
}

TEST_CASE("nn::PositionalEncoding: [input, PE(vertex index)] per batch item, gradient passes the input part") {
  std::mt19937_64 rng(41);
  const Index N = 6, B = 3;
  nn::PositionalEncoding<double> pe(N, 8);
  const Matrix<double> x = random_matrix(rng, B * N, 3);
  Matrix<double> y;
  pe.forward(exec::seq, nn::Mode::train, x, y);
  REQUIRE(y.cols() == 11);
  for (Index b = 0; b < B; ++b)
    for (Index n = 0; n < N; ++n) {
      CHECK(y.row(b * N + n).head(3) == x.row(b * N + n));
      CHECK(y.row(b * N + n).tail(8) == pe.table().row(n));
    }
  test::check_gradients(test::layer_gradient_check(pe, nullptr, x, nn::Mode::train, rng));
  CHECK_THROWS_AS(pe.forward(exec::seq, nn::Mode::train, Matrix<double>(7, 3), y), ShapeError);
  CHECK_THROWS_AS(nn::PositionalEncoding<double>(5, 7), ArgumentError);
  const Matrix<float> xf = random_matrix(rng, 40 * N, 3).cast<float>();
  nn::PositionalEncoding<float> pf(N);
  test::check_seq_equals_omp(pf, (nn::ParameterStore<float>*)nullptr, xf, nn::Mode::eval, rng);
  test::check_warm_no_allocation(exec::omp, pf, xf, nn::Mode::eval);
}
