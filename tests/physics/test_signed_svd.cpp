#include "material_checks.hpp"

using namespace simsr::physics;
using namespace simsr::physics::testing;

namespace {
void check_decomposition(const Mat3d& F, const SignedSvd<double>& r) {
  CAPTURE(F);
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
void check_signed_svd(const Mat3d& F) { check_decomposition(F, signed_svd(F)); }
/// signed_svd_from_eigen: the same conventions, and the same singular values as the Jacobi SVD.
void check_from_eigen(const Mat3d& F) {
  const SignedSvd<double> fast = signed_svd_from_eigen(F);
  check_decomposition(F, fast);
  CHECK((fast.sigma - signed_svd(F).sigma).cwiseAbs().maxCoeff() <= 1e-12 * std::max(F.norm(), 1e-300));
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

TEST_CASE("signed_svd_from_eigen: the Jacobi SVD's conventions and values on random, near-rotation, repeated, inverted and near-flat F") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-2.0, 2.0), small(-1e-3, 1e-3), log_scale(-9, 2);
  for (int i = 0; i < 2000; ++i) {
    Mat3d F;
    for (int k = 0; k < 9; ++k) F(k % 3, k / 3) = u(rng);
    check_from_eigen(F);
    check_from_eigen(-F);
    // near a rotation (the elastic body near rest: all three singular values close, eigenvectors ill-posed)
    Mat3d E;
    for (int k = 0; k < 9; ++k) E(k % 3, k / 3) = small(rng) * std::pow(10.0, log_scale(rng) / 3);
    const Mat3d R = with_singular_values(rng, 1.0, 1.0, 1.0);
    check_from_eigen(R + E);
    check_from_eigen(R * Mat3d(Eigen::Vector3d(1, 1, -1).asDiagonal()) + E);  // inverted near a reflection
    // random singular values over decades, either sign of the smallest
    const double s1 = std::pow(10.0, log_scale(rng) / 4), s2 = s1 * std::pow(10.0, -std::abs(log_scale(rng)) / 4),
                 s3 = s2 * std::pow(10.0, -std::abs(log_scale(rng)) / 2);
    check_from_eigen(with_singular_values(rng, s1, s2, i % 2 ? s3 : -s3));
  }
  for (const Sample& s : deformation_samples(13)) check_from_eigen(s.F);
  // where the squared matrix cannot resolve F the Jacobi SVD is returned, bit for bit
  std::mt19937 rng2(5);
  for (const Mat3d& F : {Mat3d(Mat3d::Zero()), with_singular_values(rng2, 1.5, 0.7, 0.0), with_singular_values(rng2, 1.5, 0.7, 1e-9),
                         with_singular_values(rng2, 1.5, 0.0, 0.0), with_singular_values(rng2, 2.0, 1.0, -1e-6)}) {
    check_from_eigen(F);
    const SignedSvd<double> fast = signed_svd_from_eigen(F), jacobi = signed_svd(F);
    CHECK(fast.U == jacobi.U);
    CHECK(fast.V == jacobi.V);
    CHECK(fast.sigma == jacobi.sigma);
  }
  // a case the closed form keeps is not the Jacobi SVD's bits (the fast path really runs)
  const Mat3d F = with_singular_values(rng2, 1.3, 0.9, 0.6);
  CHECK(!(signed_svd_from_eigen(F).U == signed_svd(F).U && signed_svd_from_eigen(F).V == signed_svd(F).V));
}

TEST_CASE("signed_svd_one_sided (the device's fallback): the Jacobi SVD's conventions and values, degenerate F included") {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-2.0, 2.0), log_scale(-9, 2);
  auto check_one_sided = [](const Mat3d& F) {
    const SignedSvd<double> r = signed_svd_one_sided(F);
    check_decomposition(F, r);
    CHECK((r.sigma - signed_svd(F).sigma).cwiseAbs().maxCoeff() <= 1e-12 * std::max(F.norm(), 1e-300));
  };
  for (int i = 0; i < 2000; ++i) {
    Mat3d F;
    for (int k = 0; k < 9; ++k) F(k % 3, k / 3) = u(rng);
    check_one_sided(F);
    check_one_sided(-F);
    const double s1 = std::pow(10.0, log_scale(rng) / 4), s2 = s1 * std::pow(10.0, -std::abs(log_scale(rng)) / 4),
                 s3 = s2 * std::pow(10.0, -std::abs(log_scale(rng)) / 2);
    check_one_sided(with_singular_values(rng, s1, s2, i % 2 ? s3 : -s3));
    check_one_sided(1e150 * F);
    check_one_sided(1e-150 * F);
  }
  for (const Sample& s : deformation_samples(19)) check_one_sided(s.F);
  // rank-deficient, repeated, zero: where signed_svd_from_eigen falls back
  Eigen::Vector3d a(1, 2, 3), b(-1, 0.5, 2);
  for (const Mat3d& F : {Mat3d(Mat3d::Zero()), with_singular_values(rng, 1.5, 0.7, 0.0), with_singular_values(rng, 1.5, 0.0, 0.0),
                         with_singular_values(rng, 1.5, 0.7, 1e-9), with_singular_values(rng, 2.0, 1.0, -1e-6), Mat3d(a * b.transpose()),
                         with_singular_values(rng, 1.2, 1.2, 0.8), with_singular_values(rng, 1.0, 1.0, -1.0), Mat3d(Mat3d::Identity()),
                         Mat3d(-Mat3d::Identity())}) {
    check_one_sided(F);
    // signed_svd_from_eigen with this fallback (what a device runs): the conventions hold there too
    check_decomposition(F, signed_svd_from_eigen(F, [](const Mat3d& G) { return signed_svd_one_sided(G); }));
  }
  CHECK(signed_svd_one_sided(Mat3d(-Mat3d::Identity())).sigma.isApprox(Eigen::Vector3d(1, 1, -1)));
  // a NaN or infinite entry gives NaN values (as Eigen's Jacobi SVD), never a made-up decomposition
  Mat3d bad = Mat3d::Identity();
  bad(1, 2) = std::nan("");
  CHECK(signed_svd_one_sided(bad).sigma.array().isNaN().all());
  bad(1, 2) = std::numeric_limits<double>::infinity();
  CHECK(signed_svd_one_sided(bad).sigma.array().isNaN().all());
}
