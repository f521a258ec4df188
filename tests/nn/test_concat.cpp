#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::Concat: column blocks forward, split (or accumulate) backward") {
  std::mt19937_64 rng(61);
  const Matrix<double> a = random_matrix(rng, 5, 2), b = random_matrix(rng, 5, 3), c = random_matrix(rng, 5, 1);
  nn::Concat<double> cat({2, 3, 1});
  CHECK(cat.out_features() == 6);
  CHECK(cat.offset(2) == 5);
  Matrix<double> y;
  cat.forward(exec::seq, {a, b, c}, y);
  CHECK(y.leftCols(2) == a);
  CHECK(y.middleCols(2, 3) == b);
  CHECK(y.rightCols(1) == c);
  const Matrix<double> d = random_matrix(rng, 5, 6);
  Matrix<double> da, dc;
  cat.backward(exec::seq, d, {&da, nullptr, &dc});
  CHECK(da == d.leftCols(2));
  CHECK(dc == d.rightCols(1));
  Matrix<double> acc = Matrix<double>::Ones(5, 2);
  cat.backward(exec::seq, d, {&acc, nullptr, nullptr}, true);
  CHECK((acc.array() - 1 - d.leftCols(2).array()).abs().maxCoeff() < 1e-15);
  CHECK_THROWS_AS(cat.forward(exec::seq, {a, b}, y), ArgumentError);
  CHECK_THROWS_AS(cat.forward(exec::seq, {a, a, c}, y), ShapeError);
  Matrix<double> wrong(4, 2);
  CHECK_THROWS_AS(cat.backward(exec::seq, d, {&wrong, nullptr, nullptr}, true), ShapeError);
}

TEST_CASE("nn composition: fc_out-like Linear → BatchNorm → LeakyReLU on cat(h, max, mean) matches finite differences") {
  // x feeds the concatenation twice (directly and through the pools): gradients of branches add.
  std::mt19937_64 rng(62);
  nn::Rng init(63);
  const Index N = 5, B = 2, C = 3;
  nn::ParameterStore<double> store;
  nn::GroupPool<double> gmax(nn::PoolKind::max, N), gmean(nn::PoolKind::mean, N);
  nn::Concat<double> cat({C, C, C});
  nn::Linear<double> fc0(store, "fc_out.0", 3 * C, 4, init, {.bias = false, .kernel_dims = 1});
  nn::BatchNorm1d<double> bn(store, "fc_out.1", 4);
  nn::LeakyReLU<double> act;
  nn::Linear<double> fc1(store, "fc_out.3", 4, 2, init, {.bias = true, .kernel_dims = 1});
  Matrix<double> pmax, pmean, h, a, b, c;
  auto fwd = [&](const Matrix<double>& x, Matrix<double>& y) {
    gmax.forward(exec::seq, nn::Mode::train, x, pmax);
    gmean.forward(exec::seq, nn::Mode::train, x, pmean);
    cat.forward(exec::seq, {x, pmax, pmean}, h);
    fc0.forward(exec::seq, nn::Mode::train, h, a);
    bn.forward(exec::seq, nn::Mode::train, a, b);
    act.forward(exec::seq, nn::Mode::train, b, c);
    fc1.forward(exec::seq, nn::Mode::train, c, y);
  };
  auto bwd = [&](const Matrix<double>& x, const Matrix<double>& y, const Matrix<double>& dy, Matrix<double>* dx) {
    Matrix<double> dc, db, da, dh, dmax, dmean, dtmp;
    fc1.backward(exec::seq, c, y, dy, &dc);
    act.backward(exec::seq, b, c, dc, &db);
    bn.backward(exec::seq, a, b, db, &da);
    fc0.backward(exec::seq, h, a, da, &dh);
    cat.backward(exec::seq, dh, {dx, &dmax, &dmean});
    gmax.backward(exec::seq, x, pmax, dmax, &dtmp);
    *dx += dtmp;
    gmean.backward(exec::seq, x, pmean, dmean, &dtmp);
    *dx += dtmp;
  };
  Matrix<double> x(B * N, C);
  std::vector<double> v(static_cast<std::size_t>(x.size()));
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 0.13 * double(i) - 1.7;
  std::shuffle(v.begin(), v.end(), rng);
  std::copy(v.begin(), v.end(), x.data());
  test::check_gradients(test::gradient_check(x, &store, fwd, bwd, rng));
}

TEST_CASE("nn::Concat: seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(64);
  const Matrix<float> a = random_matrix(rng, 3000, 35).cast<float>(), b = random_matrix(rng, 3000, 64).cast<float>();
  nn::Concat<float> cat({35, 64});
  Matrix<float> y1, y2, da1, db1, da2, db2;
  cat.forward(exec::seq, {a, b}, y1);
  cat.forward(exec::omp, {a, b}, y2);
  CHECK(test::bitwise_equal(y1, y2));
  cat.backward(exec::seq, y1, {&da1, &db1}, false);
  cat.backward(exec::omp, y1, {&da2, &db2}, false);
  CHECK(test::bitwise_equal(da2, a));
  CHECK(test::bitwise_equal(db2, b));
  const float* p = y1.data();
  const long before = simsr_test_malloc_count();
  cat.forward(exec::omp, {a, b}, y1);
  cat.backward(exec::omp, y1, {&da1, &db1}, true);
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before);
  CHECK(y1.data() == p);
}
