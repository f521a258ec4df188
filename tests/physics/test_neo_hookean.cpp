#include "material_checks.hpp"

#include <simsr/core/error.hpp>

using namespace simsr::physics;
using namespace simsr::physics::testing;

TEST_CASE("NeoHookean: parameters") {
  static_assert(Material<NeoHookean<double>>);
  static_assert(Material<NeoHookean<float>>);
  const auto m = NeoHookean<>::from_young_poisson(1e5, 0.3);
  CHECK(m.mu() == doctest::Approx(1e5 / 2.6));
  CHECK(m.lambda() == doctest::Approx(1e5 * 0.3 / (1.3 * 0.4)));
  CHECK(NeoHookean<>::from_lame(2.0, 3.0).lambda() == 3.0);
  CHECK_THROWS_AS(NeoHookean<>::from_young_poisson(0.0, 0.3), simsr::ArgumentError);
  CHECK_THROWS_AS(NeoHookean<>::from_young_poisson(-1.0, 0.3), simsr::ArgumentError);
  CHECK_THROWS_AS(NeoHookean<>::from_young_poisson(1e5, 0.5), simsr::ArgumentError);
  CHECK_THROWS_AS(NeoHookean<>::from_young_poisson(1e5, -1.0), simsr::ArgumentError);
  CHECK_THROWS_AS(NeoHookean<>::from_young_poisson(1e5, std::nan("")), simsr::ArgumentError);
  CHECK_THROWS_AS(NeoHookean<>::from_lame(0.0, 1.0), simsr::ArgumentError);
  CHECK_THROWS_AS(NeoHookean<>::from_lame(1.0, -1.0), simsr::ArgumentError);
  CHECK_THROWS_AS(NeoHookean<>::from_lame(1.0, 1.0, 1.0), simsr::ArgumentError);
  CHECK_THROWS_AS(NeoHookean<>::from_lame(1.0, 1.0, 0.0), simsr::ArgumentError);
  try {
    NeoHookean<>::from_young_poisson(1e5, 0.7);
  } catch (const simsr::ArgumentError& e) {
    CHECK(std::string(e.what()).find("0.7") != std::string::npos);
  }
}

TEST_CASE("NeoHookean: rest state, small strain, derivatives, projection, inversion") {
  const auto m = NeoHookean<>::from_young_poisson(1e5, 0.45);
  check_rest_state(m, {}, m.mu());
  check_linear_elasticity(m, m.mu(), m.lambda(), 1);
  check_derivatives(m, deformation_samples(101), {}, m.mu());
  check_element_stiffness(m, deformation_samples(101), {}, m.mu());
  std::mt19937 rng(3);
  check_projection_keeps_psd(m, Mat3d::Identity(), {}, m.mu());
  for (int i = 0; i < 5; ++i) check_projection_keeps_psd(m, with_singular_values(rng, 1.05, 1.02, 1.01), {}, m.mu());
  for (unsigned s = 0; s < 3; ++s) check_uninversion(m, {}, s, -1.0, 0.9);
  // The energy is finite and consistent for degenerate F.
  CHECK(std::isfinite(m.energy(Mat3d::Zero(), {})));
  CHECK(m.stress(Mat3d::Zero(), {}).allFinite());
  CHECK(m.stress_derivative(Mat3d::Zero(), {}, Definiteness::project).allFinite());
}
