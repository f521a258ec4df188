// VolumeTarget (SoftDECA's E_vol with target determinant v): closed form and finite differences
// over every family of F (a polynomial: exact on degenerate and inverted F as well).
#include <simsr/physics/materials/volume_target.hpp>

#include <doctest/doctest.h>

#include "material_checks.hpp"

using namespace simsr;
using namespace simsr::physics;
using namespace simsr::physics::testing;

TEST_CASE("VolumeTarget: psi = w (det F - v)^2, P = 2w (J - v) cof F, and dP/dF by finite differences") {
  for (double v : {0.5, 1.0, 1.5}) {
    CAPTURE(v);
    const VolumeTarget<> m(3.0, v);
    const auto samples = deformation_samples(13);
    for (const Sample& s : samples) {
      const double J = s.F.determinant();
      CHECK(m.energy(s.F) == doctest::Approx(3.0 * (J - v) * (J - v)).epsilon(1e-10));
      CHECK(relative_error(m.stress(s.F), (6.0 * (J - v) * cofactor(s.F)).eval(), 1.0) < 1e-10);
    }
    const FdReport r = check_derivatives(m, samples, {}, 3.0, 1e-6);
    CHECK(r.derivative < 1e-6);
    check_element_stiffness(m, samples, {}, 3.0);
  }
  // v scaling: a uniform stretch s^{1/3} I with s = v costs nothing
  const VolumeTarget<> m(1.0, 0.8);
  CHECK(m.energy(Mat3<>(std::cbrt(0.8) * Mat3<>::Identity())) == doctest::Approx(0).epsilon(1e-14));
  CHECK(m.projective_stiffness() == doctest::Approx(6 * std::pow(0.8, 4.0 / 3)));
}

TEST_CASE("VolumeTarget: bad parameters are named") {
  CHECK_THROWS_AS(VolumeTarget<>(-1.0, 1.0), ArgumentError);
  CHECK_THROWS_WITH_AS(VolumeTarget<>(1.0, 0.0), doctest::Contains("target determinant v"), ArgumentError);
  CHECK_THROWS_AS(VolumeTarget<>(1.0, std::nan("")), ArgumentError);
}
