#include <simsr/nn/dropout.hpp>

#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::Dropout: eval and p = 0 are exact identities; train masks with scale 1/(1-p)") {
  std::mt19937_64 rng(81);
  const Matrix<double> x = random_matrix(rng, 200, 30);
  Matrix<double> y, d;
  nn::Dropout<double> drop(0.25, nn::Rng(3));
  drop.forward(exec::seq, nn::Mode::eval, x, y);
  CHECK(test::bitwise_equal(x, y));
  drop.backward(exec::seq, x, y, x, &d);
  CHECK(test::bitwise_equal(x, d));
  nn::Dropout<double> none(0.0, nn::Rng(3));
  none.forward(exec::seq, nn::Mode::train, x, y);
  CHECK(test::bitwise_equal(x, y));

  drop.forward(exec::seq, nn::Mode::train, x, y);
  Index dropped = 0;
  for (Index i = 0; i < x.size(); ++i) {
    const double m = drop.mask().data()[i];
    CHECK((m == 0 || m == 1 / 0.75));
    CHECK(y.data()[i] == x.data()[i] * m);
    dropped += m == 0;
  }
  const double frac = double(dropped) / double(x.size());
  CHECK(frac > 0.22);
  CHECK(frac < 0.28);
  // backward reuses the mask (the linear map's gradient, checked by finite differences on a fixed mask)
  const Matrix<double> g = random_matrix(rng, x.rows(), x.cols());
  drop.backward(exec::seq, x, y, g, &d);
  CHECK(test::bitwise_equal(d, Matrix<double>(g.cwiseProduct(drop.mask()))));

  nn::Dropout<double> all(1.0, nn::Rng(3));
  all.forward(exec::seq, nn::Mode::train, x, y);
  CHECK(y.cwiseAbs().maxCoeff() == 0);
  CHECK_THROWS_AS(nn::Dropout<double>(1.5), ArgumentError);
  CHECK_THROWS_AS(nn::Dropout<double>(-0.1), ArgumentError);
}

TEST_CASE("nn::Dropout: the same seed gives the same masks; seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(82);
  const Matrix<float> x = random_matrix(rng, 1000, 64).cast<float>();
  const Matrix<float> r = random_matrix(rng, 1000, 64).cast<float>();
  nn::Dropout<float> a(0.1, nn::Rng(9)), b(0.1, nn::Rng(9));
  Matrix<float> ya, yb, da, db;
  for (int it = 0; it < 2; ++it) {
    a.forward(exec::seq, nn::Mode::train, x, ya);
    a.backward(exec::seq, x, ya, r, &da);
    b.forward(exec::omp, nn::Mode::train, x, yb);
    b.backward(exec::omp, x, yb, r, &db);
    CHECK(test::bitwise_equal(ya, yb));
    CHECK(test::bitwise_equal(da, db));
  }
  test::check_warm_no_allocation(exec::omp, a, x, nn::Mode::train);
  test::check_warm_no_allocation(exec::seq, a, x, nn::Mode::eval);
}
