// StrainLimit (SoftDECA's E_str with the maximum strain ε): derivatives by finite differences
// over random, stretched, inverted and near-degenerate F; the band's meaning; the projection
// against brute force.
#include <simsr/physics/materials/strain_limit.hpp>

#include <doctest/doctest.h>

#include <Eigen/SVD>

#include <random>

#include "material_checks.hpp"

using namespace simsr;
using namespace simsr::physics;
using namespace simsr::physics::testing;

namespace test_strain_limit {

/// The samples whose FD stencil (h ~ 1e-6) stays off the band's kinks |σ_i| = lo, hi, where ψ
/// is only C¹ (its curvature jumps).
std::vector<Sample> off_kinks(const StrainLimit<>& m, const std::vector<Sample>& all) {
  std::vector<Sample> r;
  for (const Sample& s : all) {
    const Vec3<> sigma = signed_svd(s.F).sigma;
    bool near = false;
    for (int i = 0; i < 3; ++i) near = near || std::abs(sigma(i) - m.lo()) < 1e-4 || std::abs(sigma(i) - m.hi()) < 1e-4;
    if (!near) r.push_back(s);
  }
  return r;
}

}  // namespace test_strain_limit

TEST_CASE("StrainLimit: P and dP/dF match finite differences, including near-degenerate and inverted F") {
  for (double eps : {0.7, 1.0, 1.3}) {
    CAPTURE(eps);
    const StrainLimit<> m(2.5, eps);
    const auto all = deformation_samples(7, /*include_flip_singularity=*/false);
    const auto samples = test_strain_limit::off_kinks(m, all);
    CHECK(samples.size() > all.size() * 3 / 4);
    const FdReport r = check_derivatives(m, samples, {}, 2.5, 1e-6);
    CHECK(r.derivative < 1e-6);
    // ψ is C¹ everywhere: P matches the energy's differences on the kinks too.
    for (const Sample& s : all) {
      CAPTURE(s.kind);
      CHECK(relative_error(m.stress(s.F), fd_stress(m, s.F, {}, 1e-7), 2.5) < 1e-5);
    }
  }
}

TEST_CASE("StrainLimit: the band runs from 1 to eps, and only stretches outside it cost energy") {
  std::mt19937 rng(3);
  const double w = 4;
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3<> Q = random_rotation(rng), R = random_rotation(rng);
    const auto F = [&](double a, double b, double c) -> Mat3<> { return Q * Vec3<>(a, b, c).asDiagonal() * R.transpose(); };
    const StrainLimit<> loose(w, 1.3), tight(w, 0.7), rigid(w, 1.0);
    CHECK(loose.lo() == 1.0);
    CHECK(loose.hi() == 1.3);
    CHECK(tight.lo() == 0.7);
    CHECK(tight.hi() == 1.0);
    // ε = 1.3: stretches up to 1.3 are free, compression and larger stretch are not
    CHECK(loose.energy(F(1.25, 1.1, 1.0)) == doctest::Approx(0).epsilon(1e-12));
    CHECK(loose.energy(F(1.4, 1.1, 1.0)) == doctest::Approx(w * 0.01).epsilon(1e-9));
    CHECK(loose.energy(F(1.0, 1.0, 0.9)) == doctest::Approx(w * 0.01).epsilon(1e-9));
    // ε = 0.7: compression down to 0.7 is free, any stretch is not
    CHECK(tight.energy(F(0.75, 0.8, 1.0)) == doctest::Approx(0).epsilon(1e-12));
    CHECK(tight.energy(F(1.1, 0.8, 0.8)) == doctest::Approx(w * 0.01).epsilon(1e-9));
    CHECK(tight.energy(F(0.6, 0.8, 0.8)) == doctest::Approx(w * 0.01).epsilon(1e-9));
    // an inverted element is pulled back through σ₃ = lo
    CHECK(loose.energy(F(1.0, 1.0, -0.2)) == doctest::Approx(w * 1.44).epsilon(1e-9));
    // ε = 1 is the supplement's E_str = w min_R ‖F − R‖² (R the polar rotation where det F > 0)
    const Mat3<> G = F(1.3, 0.9, 0.6);
    const Eigen::JacobiSVD<Mat3<>> svd(G, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Mat3<> polar = svd.matrixU() * svd.matrixV().transpose();
    CHECK(rigid.energy(G) == doctest::Approx(w * (G - polar).squaredNorm()).epsilon(1e-10));
  }
}

TEST_CASE("StrainLimit: project(F) is the nearest member of the band set (brute force over random members)") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const StrainLimit<> m(1.0, 1.2);
  for (int trial = 0; trial < 30; ++trial) {
    Mat3<> F = Mat3<>::Identity();
    for (int k = 0; k < 9; ++k) F(k % 3, k / 3) += 0.8 * u(rng);
    const Mat3<> P = m.project(F);
    const Vec3<> s = signed_svd(P).sigma;
    CHECK(s.minCoeff() >= m.lo() - 1e-12);
    CHECK(s.maxCoeff() <= m.hi() + 1e-12);
    CHECK(P.determinant() > 0);
    const double d = (F - P).squaredNorm();
    CHECK(m.energy(F) == doctest::Approx(d).epsilon(1e-10));
    std::uniform_real_distribution<double> band(m.lo(), m.hi());
    for (int k = 0; k < 2000; ++k) {
      const Mat3<> T = random_rotation(rng) * Vec3<>(band(rng), band(rng), band(rng)).asDiagonal() * random_rotation(rng).transpose();
      CHECK((F - T).squaredNorm() >= d - 1e-12);
    }
  }
}

TEST_CASE("StrainLimit: bad parameters are named") {
  CHECK_THROWS_AS(StrainLimit<>(-1.0, 1.0), ArgumentError);
  CHECK_THROWS_AS(StrainLimit<>(1.0, 0.0), ArgumentError);
  CHECK_THROWS_AS(StrainLimit<>(std::nan(""), 1.0), ArgumentError);
  CHECK_THROWS_AS(StrainLimit<>::from_band(1.0, 1.2, 1.1), ArgumentError);
  CHECK_THROWS_WITH_AS(StrainLimit<>(1.0, -0.5), doctest::Contains("maximum strain eps"), ArgumentError);
}
