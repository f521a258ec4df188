#include "material_checks.hpp"

using namespace simsr::physics;
using namespace simsr::physics::testing;

namespace {
// A generic polynomial Ψ(I1, I2, J) to test the invariant machinery independently of a material.
struct PolynomialMaterial {
  using scalar_type = double;
  using Element = NoElementData;
  InvariantPartials<double> partials(const Invariants<double>& v) const {
    InvariantPartials<double> p;
    p.psi = 0.5 * v.I1 * v.I1 + 0.3 * v.I1 * v.I2 + 0.2 * v.J * v.J * v.J + 0.1 * v.I2 * v.J;
    p.d = Eigen::Vector3d(v.I1 + 0.3 * v.I2, 0.3 * v.I1 + 0.1 * v.J, 0.6 * v.J * v.J + 0.1 * v.I2);
    p.dd << 1.0, 0.3, 0.0, 0.3, 0.0, 0.1, 0.0, 0.1, 1.2 * v.J;
    return p;
  }
  double energy(const Mat3d& F, const Element&) const { return partials(invariants(F)).psi; }
  Mat3d stress(const Mat3d& F, const Element&) const {
    const auto inv = invariants(F);
    return invariant_stress(F, inv, partials(inv).d);
  }
  Mat9d stress_derivative(const Mat3d& F, const Element&, Definiteness d) const {
    const auto svd = signed_svd(F);
    return isotropic_stress_derivative(svd, principal_from_invariants(svd.sigma, partials(invariants(svd.sigma))), d);
  }
};
}  // namespace

TEST_CASE("extended J functions: exact above J0, C2 at J0, pushing toward J > 0 below") {
  const double J0 = 0.1, e = 1e-9;
  for (double J : {0.1, 0.5, 1.0, 3.0}) {
    CHECK(extended_log(J, J0).value == doctest::Approx(std::log(J)).epsilon(1e-15));
    CHECK(extended_power(J, -2.0 / 3, J0).value == doctest::Approx(std::pow(J, -2.0 / 3)).epsilon(1e-15));
  }
  for (double p : {-2.0 / 3, -4.0 / 3}) {
    const auto a = extended_power(J0 + e, p, J0), b = extended_power(J0 - e, p, J0);
    CHECK(a.value == doctest::Approx(b.value).epsilon(1e-7));
    CHECK(a.first == doctest::Approx(b.first).epsilon(1e-7));
    CHECK(a.second == doctest::Approx(b.second).epsilon(1e-7));
  }
  const auto a = extended_log(J0 + e, J0), b = extended_log(J0 - e, J0);
  CHECK(a.value == doctest::Approx(b.value).epsilon(1e-7));
  CHECK(a.first == doctest::Approx(b.first).epsilon(1e-7));
  CHECK(a.second == doctest::Approx(b.second).epsilon(1e-7));
  for (double J = -3.0; J < J0; J += 0.01) {
    CHECK(extended_log(J, J0).first > 0);
    CHECK(extended_power(J, -2.0 / 3, J0).first < 0);
    CHECK(extended_power(J, -2.0 / 3, J0).value > 0);
    const auto h = 1e-6;
    CHECK(extended_log(J, J0).first ==
          doctest::Approx((extended_log(J + h, J0).value - extended_log(J - h, J0).value) / (2 * h)).epsilon(1e-7));
  }
}

TEST_CASE("invariants from F and from signed singular values agree") {
  for (const Sample& s : deformation_samples(3)) {
    const auto a = invariants(s.F), b = invariants(signed_svd(s.F).sigma);
    CHECK(a.I1 == doctest::Approx(b.I1).epsilon(1e-12));
    CHECK(a.I2 == doctest::Approx(b.I2).epsilon(1e-12).scale(a.I1 * a.I1));
    CHECK(a.J == doctest::Approx(b.J).epsilon(1e-12).scale(1.0));
  }
  std::mt19937 rng(5);
  const Mat3d F = with_singular_values(rng, 1.3, 0.9, 0.6);
  CHECK(cofactor(F).isApprox(F.determinant() * F.inverse().transpose(), 1e-12));
}

TEST_CASE("isotropic machinery: P and the 9 eigen-modes of dP/dF match finite differences") {
  static_assert(Material<PolynomialMaterial>);
  const PolynomialMaterial m;
  for (const Sample& s : deformation_samples(17)) {
    const auto svd = signed_svd(s.F);
    const auto d = principal_from_invariants(svd.sigma, m.partials(invariants(svd.sigma)));
    CHECK(relative_error(isotropic_stress(svd, d.g), m.stress(s.F, {}), 1.0) < 1e-12);
  }
  check_derivatives(m, deformation_samples(19), {}, 1.0);
}
