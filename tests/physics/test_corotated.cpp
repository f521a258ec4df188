#include "material_checks.hpp"

#include <simsr/core/error.hpp>

using namespace simsr::physics;
using namespace simsr::physics::testing;

TEST_CASE("Corotated: parameters") {
  static_assert(Material<Corotated<double>>);
  const auto m = Corotated<>::from_young_poisson(1e5, 0.3);
  CHECK(m.mu() == doctest::Approx(1e5 / 2.6));
  CHECK(m.lambda() == doctest::Approx(1e5 * 0.3 / (1.3 * 0.4)));
  CHECK_THROWS_AS(Corotated<>::from_young_poisson(0.0, 0.3), simsr::ArgumentError);
  CHECK_THROWS_AS(Corotated<>::from_young_poisson(1e5, 0.5), simsr::ArgumentError);
  CHECK_THROWS_AS(Corotated<>::from_lame(-1.0, 1.0), simsr::ArgumentError);
  CHECK_THROWS_AS(Corotated<>::from_lame(1.0, -1.0), simsr::ArgumentError);
}

TEST_CASE("Corotated: rest state, small strain, derivatives, projection, inversion") {
  const auto m = Corotated<>::from_young_poisson(1e5, 0.45);
  check_rest_state(m, {}, m.mu());
  check_linear_elasticity(m, m.mu(), m.lambda(), 2);
  // σ2 + σ3 = 0 (inverted, |σ2| = |σ3|) is the model's genuine singularity: left out.
  check_derivatives(m, deformation_samples(102, false), {}, m.mu());
  std::mt19937 rng(4);
  check_projection_keeps_psd(m, Mat3d::Identity(), {}, m.mu());
  for (int i = 0; i < 5; ++i) check_projection_keeps_psd(m, with_singular_values(rng, 1.05, 1.02, 1.01), {}, m.mu());
  for (unsigned s = 0; s < 3; ++s) check_uninversion(m, {}, s, -1.0, 0.9);
  SUBCASE("the guarded twist term stays finite at sigma2 + sigma3 = 0") {
    const Mat3d F = with_singular_values(rng, 1.2, 0.8, -0.8);
    CHECK(std::isfinite(m.energy(F, {})));
    CHECK(m.stress_derivative(F, {}, Definiteness::exact).allFinite());
    const Mat9d Dp = m.stress_derivative(F, {}, Definiteness::project);
    CHECK(Eigen::SelfAdjointEigenSolver<Mat9d>(Dp).eigenvalues().minCoeff() >= -1e-10 * Dp.norm());
  }
}
