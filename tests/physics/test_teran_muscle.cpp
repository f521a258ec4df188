#include "material_checks.hpp"

#include <simsr/core/error.hpp>

using namespace simsr::physics;
using namespace simsr::physics::testing;

TEST_CASE("TeranMuscle: element data and parameters") {
  static_assert(Material<TeranMuscle<double>>);
  using M = TeranMuscle<>;
  const auto e = M::element(Eigen::Vector3d(0, 3, 4), 0.5);
  CHECK(e.fibre.isApprox(Eigen::Vector3d(0, 0.6, 0.8)));
  CHECK(e.activation == 0.5);
  CHECK_NOTHROW(M::check(e));
  CHECK_NOTHROW(M::check(MuscleFibre<>{}));
  CHECK_THROWS_AS(M::check(MuscleFibre<>{Eigen::Vector3d(0, 3, 4), 0.5}), simsr::ArgumentError);
  CHECK_THROWS_AS(M::element(Eigen::Vector3d::Zero(), 0.5), simsr::ArgumentError);
  CHECK_THROWS_AS(M::element(Eigen::Vector3d(1, 0, 0), 1.5), simsr::ArgumentError);
  CHECK_THROWS_AS(M::element(Eigen::Vector3d(1, 0, 0), -0.1), simsr::ArgumentError);
  CHECK_THROWS_AS(M::element(Eigen::Vector3d(1, 0, 0), std::nan("")), simsr::ArgumentError);
  try {
    M::element(Eigen::Vector3d(1, 0, 0), 1.5);
  } catch (const simsr::ArgumentError& err) {
    CHECK(std::string(err.what()).find("activation = 1.5") != std::string::npos);
  }
  CHECK_THROWS_AS(M(MooneyRivlin<>(), -1.0), simsr::ArgumentError);
  CHECK_THROWS_AS(M(MooneyRivlin<>(), 3e5, PassiveFibreCurve<>{0.05, 6.6, 0.9}), simsr::ArgumentError);
  CHECK_THROWS_AS(M(MooneyRivlin<>(), 3e5, {}, ActiveFibreCurve<>{-1.0}), simsr::ArgumentError);
  CHECK(M().max_stress() == 3e5);
}

TEST_CASE("TeranMuscle: rest state and activation contracts the fibre") {
  const TeranMuscle<> m;
  std::mt19937 rng(8);
  const Eigen::Vector3d a = random_rotation(rng).col(0);
  check_rest_state(m, TeranMuscle<>::element(a, 0.0), 1e5);
  for (double act : {0.2, 1.0}) {
    const auto e = TeranMuscle<>::element(a, act);
    const Mat3d P = m.stress(Mat3d::Identity(), e);
    // Tension along the fibre: a·P·a = σ_max α f_a(1) > 0, so shortening lowers the energy.
    CHECK(a.dot(P * a) == doctest::Approx(3e5 * act));
    const Mat3d shorter = Mat3d::Identity() - 0.01 * a * a.transpose();
    CHECK(m.energy(shorter, e) < m.energy(Mat3d::Identity(), e));
    CHECK(a.dot(m.stress(Mat3d::Identity(), TeranMuscle<>::element(a, act)) * a) >
          a.dot(m.stress(Mat3d::Identity(), TeranMuscle<>::element(a, act / 2)) * a));
  }
}

TEST_CASE("TeranMuscle: derivatives, projection and inversion") {
  const TeranMuscle<> m;
  std::mt19937 rng(9);
  auto samples = deformation_samples(106);
  // The passive curve's slope jumps at λ = 1 (Blemker's curve): stencils across it are left out.
  for (double act : {0.0, 0.3, 1.0})
    for (int t = 0; t < 3; ++t) {
      CAPTURE(act);
      const auto e = TeranMuscle<>::element(random_rotation(rng).col(0), act);
      std::vector<Sample> away;
      for (const Sample& s : samples)
        if (std::abs((s.F * e.fibre).norm() - 1) > 1e-4) away.push_back(s);
      check_derivatives(m, away, e, 1e5);
      check_element_stiffness(m, samples, e, 1e5, unsigned(7 * t + 1));
    }
  SUBCASE("fibre collapsed to zero length: the fibre term is flat") {
    const auto e = TeranMuscle<>::element(Eigen::Vector3d(1, 0, 0), 1.0);
    const Mat3d F = Eigen::Vector3d(0, 1, 1).asDiagonal();
    CHECK(m.stress(F, e).allFinite());
    CHECK(m.stress(F, e).isApprox(m.isotropic().stress(F, {})));
    CHECK(m.stress_derivative(F, e, Definiteness::exact).isApprox(m.isotropic().stress_derivative(F, {}, Definiteness::exact)));
  }
  const auto rest = TeranMuscle<>::element(Eigen::Vector3d(1, 0, 0), 0.0);
  check_projection_keeps_psd(m, Mat3d::Identity(), rest, 1e5);
  for (int i = 0; i < 5; ++i) check_projection_keeps_psd(m, with_singular_values(rng, 1.05, 1.02, 1.01), rest, 1e5);
  for (unsigned s = 0; s < 3; ++s) {
    check_uninversion(m, TeranMuscle<>::element(random_rotation(rng).col(0), 0.5), s, -1.0, -0.01);
    check_uninversion(m, rest, s, -1.0, 0.9);
  }
}
