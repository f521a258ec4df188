#include <doctest/doctest.h>

#include <simsr/mesh/closest_point.hpp>

#include <random>

namespace mesh_test_closest_point {

using namespace simsr;

TEST_CASE("closest_point_on_triangle: no sampled point of the triangle is closer; weights are barycentric") {
  std::mt19937 rng(31);
  std::normal_distribution<double> n;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    Vec3<> a(n(rng), n(rng), n(rng)), b(n(rng), n(rng), n(rng)), c(n(rng), n(rng), n(rng));
    if (trial % 10 == 0) c = a + 0.3 * (b - a);  // degenerate: collinear
    if (trial % 10 == 1) b = a;                   // degenerate: two corners coincide
    const Vec3<> p = 2.0 * Vec3<>(n(rng), n(rng), n(rng));
    const Vec3<> w = closest_point_on_triangle(p, a, b, c);
    CHECK(w.minCoeff() >= 0);
    CHECK(w.sum() == doctest::Approx(1.0).epsilon(1e-12));
    const double d = (w[0] * a + w[1] * b + w[2] * c - p).norm();
    for (int s = 0; s < 500; ++s) {
      double x = u(rng), y = u(rng);
      if (x + y > 1) x = 1 - x, y = 1 - y;
      CHECK(d <= ((1 - x - y) * a + x * b + y * c - p).norm() + 1e-12);
    }
  }
}

}  // namespace mesh_test_closest_point
