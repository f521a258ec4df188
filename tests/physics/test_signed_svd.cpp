#include "material_checks.hpp"

using namespace simsr::physics;
using namespace simsr::physics::testing;

namespace {
void check_signed_svd(const Mat3d& F) {
  CAPTURE(F);
  const SignedSvd<double> r = signed_svd(F);
  const double scale = std::max(F.norm(), 1e-300);
  CHECK((r.U * r.U.transpose() - Mat3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((r.V * r.V.transpose() - Mat3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(r.U.determinant() == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(r.V.determinant() == doctest::Approx(1.0).epsilon(1e-12));
  CHECK((r.U * r.sigma.asDiagonal() * r.V.transpose() - F).cwiseAbs().maxCoeff() <= 1e-12 * scale);
  CHECK(r.sigma(0) >= 0);
  CHECK(r.sigma(1) >= 0);
  CHECK(std::abs(r.sigma(0)) >= std::abs(r.sigma(1)));
  CHECK(std::abs(r.sigma(1)) >= std::abs(r.sigma(2)));
  const double det = F.determinant();
  if (std::abs(det) > 1e-12 * scale * scale * scale) CHECK((r.sigma(2) < 0) == (det < 0));
}
}  // namespace

TEST_CASE("signed SVD: rotations, reconstruction and the sign convention") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int i = 0; i < 200; ++i) {
    Mat3d F;
    for (int k = 0; k < 9; ++k) F(k % 3, k / 3) = u(rng);
    check_signed_svd(F);
    check_signed_svd(-F);
  }
  for (const Sample& s : deformation_samples(11)) check_signed_svd(s.F);
  SUBCASE("inverted: the negative value is the smallest in magnitude") {
    const Mat3d F = with_singular_values(rng, 2.0, 1.0, -0.5);
    const auto r = signed_svd(F);
    CHECK(r.sigma(0) == doctest::Approx(2.0));
    CHECK(r.sigma(1) == doctest::Approx(1.0));
    CHECK(r.sigma(2) == doctest::Approx(-0.5));
    CHECK(signed_svd(Mat3d(Eigen::Vector3d(1, 1, -1).asDiagonal())).sigma(2) == doctest::Approx(-1.0));
    CHECK(signed_svd(Mat3d(-Mat3d::Identity())).sigma.isApprox(Eigen::Vector3d(1, 1, -1)));
  }
  SUBCASE("rank-deficient and repeated") {
    check_signed_svd(with_singular_values(rng, 1.5, 0.7, 0.0));
    check_signed_svd(with_singular_values(rng, 1.5, 0.0, 0.0));
    check_signed_svd(Mat3d::Zero());
    Eigen::Vector3d a(1, 2, 3), b(-1, 0.5, 2);
    check_signed_svd(a * b.transpose());
    const Mat3d F = with_singular_values(rng, 1.2, 1.2, 0.8);
    check_signed_svd(F);
    CHECK(signed_svd(F).sigma.isApprox(Eigen::Vector3d(1.2, 1.2, 0.8), 1e-12));
    check_signed_svd(with_singular_values(rng, 1.0, 1.0, -1.0));
  }
}
