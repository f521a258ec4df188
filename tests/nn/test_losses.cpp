#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn losses: values against plain loops, gradients against finite differences") {
  std::mt19937_64 rng(71);
  const Matrix<double> a = test::random_away_from_zero(rng, 17, 3), b = random_matrix(rng, 17, 3, -0.01, 0.01);
  long double l1 = 0, ab = 0, sq = 0;
  for (Index i = 0; i < a.size(); ++i) {
    l1 += std::abs((long double)a.data()[i] - b.data()[i]);
    ab += std::abs((long double)a.data()[i]);
    sq += (long double)a.data()[i] * a.data()[i];
  }
  const double n = double(a.size());
  Matrix<double> d1, d2, d3;
  CHECK(nn::l1_loss(exec::seq, a, b, &d1, 10.0) == doctest::Approx(double(l1 / n)).epsilon(1e-14));
  CHECK(nn::mean_abs(exec::seq, a, &d2, 2.0) == doctest::Approx(double(ab / n)).epsilon(1e-14));
  CHECK(nn::mean_square(exec::seq, a, &d3) == doctest::Approx(double(sq / n)).epsilon(1e-14));
  // finite differences of each loss (entries away from the kinks of |·|)
  const double h = 1e-6;
  auto fd = [&](auto&& f, const Matrix<double>& x, const Matrix<double>& g, double scale) {
    Matrix<double> xp = x;
    double err = 0, s = 0;
    for (Index i = 0; i < x.size(); ++i) {
      const double v = xp.data()[i];
      xp.data()[i] = v + h;
      const double lp = f(xp);
      xp.data()[i] = v - h;
      const double lm = f(xp);
      xp.data()[i] = v;
      err = std::max(err, std::abs(scale * (lp - lm) / (2 * h) - g.data()[i]));
      s = std::max(s, std::abs(g.data()[i]));
    }
    CHECK(s > 0);
    return err / s;
  };
  CHECK(fd([&](const Matrix<double>& x) { return nn::l1_loss(exec::seq, x, b); }, a, d1, 10.0) < 1e-6);
  CHECK(fd([&](const Matrix<double>& x) { return nn::mean_abs(exec::seq, x); }, a, d2, 2.0) < 1e-6);
  CHECK(fd([&](const Matrix<double>& x) { return nn::mean_square(exec::seq, x); }, a, d3, 1.0) < 1e-6);
  Matrix<double> eq;
  nn::l1_loss(exec::seq, a, a, &eq);
  CHECK(eq.cwiseAbs().maxCoeff() == 0.0);  // sign(0) = 0, as PyTorch
  CHECK_THROWS_AS(nn::l1_loss(exec::seq, a, Matrix<double>(17, 2)), ShapeError);
  CHECK_THROWS_AS(nn::mean_abs(exec::seq, Matrix<double>(0, 3)), ArgumentError);
}

TEST_CASE("nn losses: seq == omp bitwise") {
  std::mt19937_64 rng(72);
  const Matrix<float> a = random_matrix(rng, 5000, 3).cast<float>(), b = random_matrix(rng, 5000, 3).cast<float>();
  Matrix<float> d1, d2;
  const float s1 = nn::l1_loss(exec::seq, a, b, &d1, 10.0), s2 = nn::l1_loss(exec::omp, a, b, &d2, 10.0);
  CHECK(s1 == s2);
  CHECK(test::bitwise_equal(d1, d2));
  CHECK(nn::mean_square(exec::seq, a) == nn::mean_square(exec::omp, a));
  CHECK(nn::mean_abs(exec::seq, a, &d1) == nn::mean_abs(exec::omp, a, &d2));
  CHECK(test::bitwise_equal(d1, d2));
}
