#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::LeakyReLU: values and gradients (slope 0.2 default)") {
  std::mt19937_64 rng(31);
  nn::LeakyReLU<double> act;
  CHECK(act.slope() == 0.2);
  Matrix<double> x(1, 4), y, d;
  x << -2, 0, 3, -0.5;
  act.forward(exec::seq, nn::Mode::train, x, y);
  CHECK(y(0, 0) == doctest::Approx(-0.4));
  CHECK(y(0, 1) == 0.0);
  CHECK(y(0, 2) == 3.0);
  CHECK(y(0, 3) == doctest::Approx(-0.1));
  act.backward(exec::seq, x, y, Matrix<double>::Ones(1, 4), &d);
  CHECK(d(0, 1) == doctest::Approx(0.2));  // PyTorch: slope at 0
  for (double slope : {0.2, 0.01, 1.5}) {
    nn::LeakyReLU<double> a(slope);
    test::check_gradients(test::layer_gradient_check(a, nullptr, test::random_away_from_zero(rng, 13, 5), nn::Mode::train, rng));
  }
}

TEST_CASE("nn::Sine: sin(ω₀x) and its gradient") {
  std::mt19937_64 rng(32);
  for (double w0 : {1.0, 30.0}) {
    nn::Sine<double> s(w0);
    const Matrix<double> x = random_matrix(rng, 11, 6, -0.2, 0.2);
    Matrix<double> y;
    s.forward(exec::seq, nn::Mode::eval, x, y);
    for (Index i = 0; i < x.size(); ++i) CHECK(y.data()[i] == std::sin(w0 * x.data()[i]));
    test::check_gradients(test::layer_gradient_check(s, nullptr, x, nn::Mode::train, rng));
  }
}

TEST_CASE("nn::Tanh: tanh and its gradient") {
  std::mt19937_64 rng(36);
  nn::Tanh<double> t;
  const Matrix<double> x = random_matrix(rng, 9, 4, -2, 2);
  Matrix<double> y;
  t.forward(exec::seq, nn::Mode::eval, x, y);
  for (Index i = 0; i < x.size(); ++i) CHECK(y.data()[i] == std::tanh(x.data()[i]));
  test::check_gradients(test::layer_gradient_check(t, nullptr, x, nn::Mode::train, rng));
}

TEST_CASE("nn::Tanh<float>: Eigen's vectorized tanh within a few ulp of std::tanh over many inputs, contiguous or strided; seq and omp the same bits") {
  std::mt19937_64 rng(37);
  nn::Tanh<float> t;
  for (int trial = 0; trial < 20; ++trial) {
    const double range = trial < 10 ? 3.0 : 40.0;  // saturation too
    const Index rows = 1 + Index(rng() % 700), cols = 1 + Index(rng() % 12);
    const Matrix<float> x = random_matrix(rng, rows, cols, -range, range).cast<float>();
    Matrix<float> y, y_omp, y_strided;
    t.forward(exec::seq, nn::Mode::train, x, y);
    t.forward(exec::omp, nn::Mode::train, x, y_omp);
    CHECK(y == y_omp);
    double worst = 0;
    for (Index i = 0; i < x.size(); ++i) worst = std::max(worst, double(std::abs(y.data()[i] - std::tanh(x.data()[i]))));
    CHECK(worst <= 4 * std::numeric_limits<float>::epsilon());
    CHECK(y.cwiseAbs().maxCoeff() <= 1.0f);
    // a view whose rows are not packed (a block of a wider matrix): row by row, the same values
    Matrix<float> wide = Matrix<float>::Zero(rows, cols + 3);
    wide.leftCols(cols) = x;
    const nn::ConstView<float> view(wide.leftCols(cols));
    t.forward(exec::omp, nn::Mode::train, view, y_strided);
    CHECK(y_strided == y);
    // the gradient from the output: d_in = d_out ⊙ (1 − y²)
    const Matrix<float> g = random_matrix(rng, rows, cols, -1, 1).cast<float>();
    Matrix<float> d;
    t.backward(exec::omp, x, y, g, &d);
    CHECK(d.isApprox(g.cwiseProduct((1 - y.array().square()).matrix())));
  }
}

TEST_CASE("nn::Sine<float>: Eigen's vectorized sin and cos within a few ulp of std::sin / std::cos over many inputs, contiguous or strided; seq and omp the same bits") {
  std::mt19937_64 rng(38);
  for (int trial = 0; trial < 24; ++trial) {
    const float w0 = trial % 3 == 0 ? 30.0f : 1.0f;
    const double range = trial < 12 ? 3.0 : (trial < 20 ? 200.0 : 2e5);  // the huge-argument fallback too
    const Index rows = 1 + Index(rng() % 700), cols = 1 + Index(rng() % 12);
    const Matrix<float> x = random_matrix(rng, rows, cols, -range, range).cast<float>();
    nn::Sine<float> s(w0);
    Matrix<float> y, y_omp, y_strided;
    s.forward(exec::seq, nn::Mode::train, x, y);
    s.forward(exec::omp, nn::Mode::train, x, y_omp);
    CHECK(y == y_omp);
    const Matrix<float> g = random_matrix(rng, rows, cols, -1, 1).cast<float>();
    Matrix<float> d, d_omp, d_strided;
    s.backward(exec::seq, x, y, g, &d);
    s.backward(exec::omp, x, y, g, &d_omp);
    CHECK(d == d_omp);
    double worst_sin = 0, worst_grad = 0;
    for (Index i = 0; i < x.size(); ++i) {
      const float a = w0 * x.data()[i];  // the argument as the layer forms it, in float
      worst_sin = std::max(worst_sin, double(std::abs(y.data()[i] - std::sin(a))));
      worst_grad = std::max(worst_grad, std::abs(double(d.data()[i]) - double(g.data()[i]) * double(w0) * std::cos(double(a))) / double(w0));
    }
    CHECK(worst_sin <= 4 * std::numeric_limits<float>::epsilon());
    CHECK(worst_grad <= 4 * std::numeric_limits<float>::epsilon());
    // views whose rows are not packed: row by row, the same values
    Matrix<float> wide = Matrix<float>::Zero(rows, cols + 3), wide_g = Matrix<float>::Zero(rows, cols + 2);
    wide.leftCols(cols) = x;
    wide_g.leftCols(cols) = g;
    const nn::ConstView<float> view(wide.leftCols(cols)), view_g(wide_g.leftCols(cols));
    s.forward(exec::omp, nn::Mode::train, view, y_strided);
    CHECK(y_strided == y);
    s.backward(exec::omp, view, y, view_g, &d_strided);
    CHECK(d_strided == d);
  }
}

TEST_CASE("nn::siren_init: first layer U(±1/fan_in), later U(±√(6/fan_in)/ω₀), biases likewise") {
  nn::Rng rng(33);
  nn::ParameterStore<float> store;
  nn::Linear<float> first(store, "layers.0.fc", 227, 256, rng), later(store, "layers.1.fc", 256, 128, rng);
  nn::siren_init(first, rng, 30.0, true);
  nn::siren_init(later, rng, 1.0, false);
  const double b0 = 1.0 / 227, b1 = std::sqrt(6.0 / 256);
  CHECK(first.weight().cwiseAbs().maxCoeff() <= b0);
  CHECK(first.weight().cwiseAbs().maxCoeff() > 0.99 * b0);
  CHECK(first.bias().cwiseAbs().maxCoeff() <= b0);
  CHECK(first.bias().cwiseAbs().maxCoeff() > 0.9 * b0);
  CHECK(later.weight().cwiseAbs().maxCoeff() <= b1);
  CHECK(later.weight().cwiseAbs().maxCoeff() > 0.99 * b1);
  CHECK(nn::siren_bound(16, 30.0, false) == doctest::Approx(std::sqrt(6.0 / 16) / 30));
  CHECK_THROWS_AS(nn::siren_bound(0, 1.0, true), ArgumentError);
}

TEST_CASE("nn activations: a Linear → Sine chain matches finite differences (SIREN layer)") {
  std::mt19937_64 rng(34);
  nn::Rng init(35);
  nn::ParameterStore<double> store;
  nn::Linear<double> l(store, "l", 7, 5, init);
  nn::siren_init(l, init, 30.0, true);
  nn::Sine<double> s(30.0);
  Matrix<double> h;
  test::check_gradients(test::gradient_check(
      random_matrix(rng, 9, 7), &store,
      [&](const Matrix<double>& x, Matrix<double>& y) {
        l.forward(exec::seq, nn::Mode::train, x, h);
        s.forward(exec::seq, nn::Mode::train, h, y);
      },
      [&](const Matrix<double>& x, const Matrix<double>& y, const Matrix<double>& d, Matrix<double>* dx) {
        Matrix<double> dh;
        s.backward(exec::seq, h, y, d, &dh);
        l.backward(exec::seq, x, h, dh, dx);
      },
      rng));
}

TEST_CASE("nn activations: seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(36);
  const Matrix<float> x = random_matrix(rng, 3000, 40).cast<float>();
  nn::LeakyReLU<float> a;
  nn::Sine<float> s(30.0f);
  test::check_seq_equals_omp(a, (nn::ParameterStore<float>*)nullptr, x, nn::Mode::train, rng);
  test::check_seq_equals_omp(s, (nn::ParameterStore<float>*)nullptr, x, nn::Mode::train, rng);
  test::check_warm_no_allocation(exec::omp, a, x, nn::Mode::train);
  test::check_warm_no_allocation(exec::seq, s, x, nn::Mode::train);
}
