#include <doctest/doctest.h>

#include <simsr/shell/polar_rotation.hpp>

#include <Eigen/Eigenvalues>
#include <numbers>
#include <random>

namespace shell_test_polar_rotation {

using namespace simsr;
using namespace simsr::shell;

TEST_CASE("polar_decomposition: T = R S, R a proper rotation, S symmetric, over random T of both signs") {
  std::mt19937 rng(1);
  std::normal_distribution<double> g;
  int inverted = 0;
  for (int k = 0; k < 500; ++k) {
    Mat3<> T;
    for (int i = 0; i < 9; ++i) T(i / 3, i % 3) = g(rng);
    if (k % 5 == 0) T = Mat3<>::Identity() + 0.1 * T;  // near the rest state too
    const PolarParts<double> p = polar_decomposition(T);
    CHECK((p.R * p.stretch - T).norm() < 1e-12 * (1 + T.norm()));
    CHECK((p.R.transpose() * p.R - Mat3<>::Identity()).norm() < 1e-12);
    CHECK(p.R.determinant() == doctest::Approx(1.0).epsilon(1e-12));
    CHECK((p.stretch - p.stretch.transpose()).norm() == 0.0);
    const Eigen::SelfAdjointEigenSolver<Mat3<>> es(p.stretch);
    if (T.determinant() > 0) {
      CHECK(es.eigenvalues().minCoeff() > 0);
    } else {
      ++inverted;  // one negative stretch keeps R proper
      CHECK(es.eigenvalues().minCoeff() < 0);
      CHECK(es.eigenvalues()[1] > 0);
    }
  }
  CHECK(inverted > 100);
}

TEST_CASE("principal_axis_angle and rotation_from_vector: every axis-angle form of R maps back to R") {
  std::mt19937 rng(2);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0, std::numbers::pi);
  for (int k = 0; k < 500; ++k) {
    const Vec3<> w = Vec3<>(g(rng), g(rng), g(rng)).normalized();
    const double theta = k == 0 ? std::numbers::pi : u(rng);
    const Mat3<> R = Eigen::AngleAxisd(theta, w).toRotationMatrix();
    const AxisAngle<double> aa = principal_axis_angle(R);
    CHECK(aa.angle >= 0);
    CHECK(aa.angle <= std::numbers::pi + 1e-15);
    CHECK(aa.angle == doctest::Approx(theta).epsilon(1e-9));
    if (theta < std::numbers::pi - 1e-6) CHECK((aa.axis - w).norm() < 1e-9);
    for (int turns = -2; turns <= 2; ++turns) {
      const double big = theta + 2 * std::numbers::pi * turns;
      CHECK((rotation_from_vector(Vec3<>(big * w)) - R).norm() < 1e-12);
      CHECK((rotation_from_vector(Vec3<>(-big * -w)) - R).norm() < 1e-12);  // (−ω, −θ) is the same rotation
    }
  }
  CHECK((rotation_from_vector(Vec3<>(Vec3<>::Zero())) - Mat3<>::Identity()).norm() == 0.0);
  CHECK(principal_axis_angle(Mat3<>(Mat3<>::Identity())).angle == 0.0);
}

}  // namespace shell_test_polar_rotation
