#include <cmath>
#include <vector>

#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::row_norm_sum: value against plain loops, gradient against finite differences") {
  std::mt19937_64 rng(601);
  const Matrix<double> z = random_matrix(rng, 23, 5);
  for (const bool mean : {false, true}) {
    CAPTURE(mean);
    long double ref = 0;
    for (Index r = 0; r < z.rows(); ++r) {
      long double sq = 0;
      for (Index j = 0; j < z.cols(); ++j) sq += (long double)z(r, j) * z(r, j);
      ref += std::sqrt(sq);
    }
    if (mean) ref /= z.rows();
    Matrix<double> d;
    const double l = nn::row_norm_sum(exec::seq, z, &d, 1.5, mean);
    CHECK(l == doctest::Approx(double(ref)).epsilon(1e-14));
    // gradient rows: 1.5·z_r/‖z_r‖ (/rows): unit rows scaled
    for (Index r = 0; r < z.rows(); ++r)
      CHECK(d.row(r).norm() == doctest::Approx(mean ? 1.5 / double(z.rows()) : 1.5).epsilon(1e-14));
    const double h = 1e-6;
    Matrix<double> x = z;
    double err = 0, s = 0;
    for (Index i = 0; i < x.size(); ++i) {
      const double v = x.data()[i];
      x.data()[i] = v + h;
      const double lp = nn::row_norm_sum(exec::seq, x, nullptr, 1.0, mean);
      x.data()[i] = v - h;
      const double lm = nn::row_norm_sum(exec::seq, x, nullptr, 1.0, mean);
      x.data()[i] = v;
      err = std::max(err, std::abs(1.5 * (lp - lm) / (2 * h) - d.data()[i]));
      s = std::max(s, std::abs(d.data()[i]));
    }
    CHECK(s > 0);
    CHECK(err / s < 1e-7);
  }
}

TEST_CASE("nn::row_norm_sum: a zero row adds 0 and gets the subgradient 0; column blocks are read in place") {
  Matrix<double> z(3, 4);
  z << 3, 0, 4, 0, 0, 0, 0, 0, 1, 2, 2, 0;
  Matrix<double> d;
  CHECK(nn::row_norm_sum(exec::seq, z, &d, 2.0) == 8.0);
  CHECK(d.row(1).cwiseAbs().maxCoeff() == 0.0);
  CHECK(d(0, 0) == doctest::Approx(2.0 * 0.6));
  CHECK(d(0, 2) == doctest::Approx(2.0 * 0.8));
  CHECK(d(2, 1) == doctest::Approx(2.0 * 2.0 / 3.0));
  CHECK(nn::row_norm_sum(exec::seq, z, &d, 1.0, true) == doctest::Approx(8.0 / 3.0));
  // Eq. 6 per feature block: a column block of a wider activation (no copy)
  const nn::ConstView<double> block = z.leftCols(2);
  CHECK(nn::row_norm_sum(exec::seq, block, &d) == doctest::Approx(3.0 + std::sqrt(5.0)));
  CHECK(nn::row_norm_sum(exec::seq, z.leftCols(2), &d) == doctest::Approx(3.0 + std::sqrt(5.0)));
  CHECK(d.rows() == 3);
  CHECK(d.cols() == 2);
  Matrix<double> all_zero = Matrix<double>::Zero(2, 3);
  CHECK(nn::row_norm_sum(exec::seq, all_zero, &d) == 0.0);
  CHECK(d.cwiseAbs().maxCoeff() == 0.0);
  CHECK_THROWS_AS(nn::row_norm_sum(exec::seq, Matrix<double>(0, 3)), ArgumentError);
  CHECK_THROWS_AS(nn::row_norm_sum(exec::seq, Matrix<double>(3, 0)), ArgumentError);
  CHECK_THROWS_AS(nn::row_norm_sum(exec::seq, z, &z), ArgumentError);
}

TEST_CASE("nn::row_norm_sum: seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(602);
  Matrix<float> z = random_matrix(rng, 7000, 64).cast<float>();
  z.row(17).setZero();
  Matrix<float> d1, d2;
  const double s1 = nn::row_norm_sum(exec::seq, z, &d1, 0.25), s2 = nn::row_norm_sum(exec::omp, z, &d2, 0.25);
  CHECK(s1 == s2);
  CHECK(test::bitwise_equal(d1, d2));
  CHECK(nn::row_norm_sum(exec::seq, z, nullptr, 1.0, true) == nn::row_norm_sum(exec::omp, z, nullptr, 1.0, true));
  const float* ptr = d1.data();
  long before = simsr_test_malloc_count();
  const double a = nn::row_norm_sum(exec::seq, z, &d1, 0.25);
  SIMSR_CHECK_NO_ALLOCATION(exec::seq, simsr_test_malloc_count() - before);
  before = simsr_test_malloc_count();
  const double b = nn::row_norm_sum(exec::omp, z, &d1, 0.25);
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before);
  CHECK(d1.data() == ptr);
  CHECK(a == s1);
  CHECK(b == s1);
}

TEST_CASE("nn::RampedWeight: endpoints, monotone, errors") {
  using K = nn::RampedWeight::Kind;
  for (const K kind : {K::linear, K::geometric}) {
    CAPTURE(int(kind));
    const nn::RampedWeight beta{0.001, 20, 1000, kind};
    CHECK(beta.at(0) == 0.001);
    CHECK(beta.at(1000) == 20.0);
    CHECK(beta.at(5000) == 20.0);
    double prev = beta.at(0);
    for (long s = 1; s <= 1200; ++s) {
      const double v = beta.at(s);
      CHECK(v >= prev);
      CHECK(v <= 20.0);
      prev = v;
    }
    // halfway: arithmetic mean (linear) or geometric mean (geometric)
    CHECK(beta.at(500) == doctest::Approx(kind == K::linear ? (0.001 + 20) / 2 : std::sqrt(0.001 * 20)).epsilon(1e-12));
    // decreasing ramps are allowed and monotone the other way
    const nn::RampedWeight down{5, 0.5, 10, kind};
    CHECK(down.at(0) == 5.0);
    CHECK(down.at(10) == 0.5);
    for (long s = 1; s <= 10; ++s) CHECK(down.at(s) <= down.at(s - 1));
  }
  CHECK(nn::RampedWeight{.ramp_steps = 4}.at(1) == doctest::Approx(0.001 + (20 - 0.001) / 4));
  CHECK(nn::RampedWeight{.start = 0, .end = 1, .ramp_steps = 4}.at(2) == 0.5);
  CHECK_THROWS_AS(nn::RampedWeight{}.at(0), ArgumentError);  // ramp_steps not set
  CHECK_THROWS_AS((nn::RampedWeight{.ramp_steps = 10}.at(-1)), ArgumentError);
  CHECK_THROWS_AS((nn::RampedWeight{.start = -0.1, .ramp_steps = 10}.at(0)), ArgumentError);
  CHECK_THROWS_AS((nn::RampedWeight{.end = -1, .ramp_steps = 10}.at(0)), ArgumentError);
  CHECK_THROWS_AS((nn::RampedWeight{.end = std::nan(""), .ramp_steps = 10}.at(0)), ArgumentError);
  CHECK_THROWS_AS((nn::RampedWeight{.start = 0, .ramp_steps = 10, .kind = nn::RampedWeight::Kind::geometric}.at(3)), ArgumentError);
  CHECK_THROWS_AS((nn::RampedWeight{.ramp_steps = -5}.at(0)), ArgumentError);
}
