#include "material_checks.hpp"

#include <simsr/core/error.hpp>

using namespace simsr::physics;
using namespace simsr::physics::testing;

TEST_CASE("MooneyRivlin: parameters") {
  static_assert(Material<MooneyRivlin<double>>);
  const MooneyRivlin<> m;
  CHECK(m.mu10() == 6e4);
  CHECK(m.mu01() == 2e4);
  CHECK(m.kappa() == 1.6e6);
  CHECK(m.inversion_threshold() == 0.1);
  CHECK_THROWS_AS(MooneyRivlin<>(-1.0), simsr::ArgumentError);
  CHECK_THROWS_AS(MooneyRivlin<>(1.0, -1.0), simsr::ArgumentError);
  CHECK_THROWS_AS(MooneyRivlin<>(0.0, 0.0), simsr::ArgumentError);
  CHECK_THROWS_AS(MooneyRivlin<>(1.0, 1.0, 0.0), simsr::ArgumentError);
  CHECK_THROWS_AS(MooneyRivlin<>(1.0, 1.0, 1.0, 1.5), simsr::ArgumentError);
  CHECK_NOTHROW(MooneyRivlin<>(1.0, 0.0, 1.0));
}

TEST_CASE("MooneyRivlin: rest state, small strain, derivatives, projection, inversion") {
  const MooneyRivlin<> m;
  const double mu = 2 * (m.mu10() + m.mu01());
  check_rest_state(m, {}, mu);
  check_linear_elasticity(m, mu, m.kappa() - 2 * mu / 3, 3);
  check_derivatives(m, deformation_samples(103), {}, mu);
  const MooneyRivlin<> only10(1e4, 0.0, 1e5), only01(0.0, 1e4, 1e5);
  check_derivatives(only10, deformation_samples(104), {}, 2e4);
  check_derivatives(only01, deformation_samples(105), {}, 2e4);
  check_element_stiffness(m, deformation_samples(103), {}, mu);
  check_element_stiffness(only01, deformation_samples(105), {}, 2e4);
  std::mt19937 rng(5);
  check_projection_keeps_psd(m, Mat3d::Identity(), {}, mu);
  for (int i = 0; i < 5; ++i) check_projection_keeps_psd(m, with_singular_values(rng, 1.05, 1.02, 1.01), {}, mu);
  for (unsigned s = 0; s < 3; ++s) check_uninversion(m, {}, s, -1.0, 0.9);
}
