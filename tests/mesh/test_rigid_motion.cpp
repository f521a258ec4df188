#include <doctest/doctest.h>

#include <simsr/mesh/rigid_motion.hpp>

#include <cmath>
#include <random>

namespace mesh_test_rigid_motion {

using namespace simsr;

namespace {

Vec3<> random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Vec3<> v(n(rng), n(rng), n(rng));
  return v.normalized();
}

Points<> random_cloud(std::mt19937& rng, Index count, double spread) {
  std::normal_distribution<double> n(0.0, spread);
  Points<> X(count, 3);
  for (Index i = 0; i < X.size(); ++i) X.data()[i] = n(rng);
  return X;
}

/// Distance from q to the line through p with unit direction a.
double distance_to_line(const Vec3<>& q, const Vec3<>& p, const Vec3<>& a) { return ((q - p) - (q - p).dot(a) * a).norm(); }

}  // namespace

TEST_CASE("fit_rigid_motion recovers random motions exactly; seq and omp agree bitwise") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Points<> X = random_cloud(rng, 3 + Index(rng() % 200), 0.1 + 5.0 * std::abs(u(rng)));
    RigidMotion<> m;
    m.R = Eigen::AngleAxisd(u(rng), random_unit(rng)).toRotationMatrix();
    m.t = Vec3<>(u(rng), u(rng), u(rng)) * 10;
    const Points<> Y = apply_rigid_motion(exec::seq, m, X);
    CHECK(apply_rigid_motion(exec::omp, m, X) == Y);
    const auto fit = fit_rigid_motion(exec::seq, X, Y);
    CHECK((fit.motion.R - m.R).norm() < 1e-9);
    CHECK((fit.motion.t - m.t).norm() < 1e-8);
    CHECK(fit.max_residual < 1e-8);
    CHECK(fit.rms_residual <= fit.max_residual);
    const auto fit_omp = fit_rigid_motion(exec::omp, X, Y);
    CHECK(fit_omp.motion.R == fit.motion.R);
    CHECK(fit_omp.max_residual == fit.max_residual);
    CHECK(fit_omp.rms_residual == fit.rms_residual);
  }
}

TEST_CASE("fit_rigid_motion: residuals measure the noise; a mirror image still gives a rotation") {
  std::mt19937 rng(4);
  const Points<> X = random_cloud(rng, 500, 2.0);
  RigidMotion<> m;
  m.R = Eigen::AngleAxisd(0.7, Vec3<>(0, 1, 0)).toRotationMatrix();
  m.t = Vec3<>(1, 2, 3);
  Points<> Y = apply_rigid_motion(exec::seq, m, X);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (Index i = 0; i < Y.size(); ++i) Y.data()[i] += noise(rng);
  const auto fit = fit_rigid_motion(exec::seq, X, Y);
  // 3-D Gaussian noise of σ = 0.01 per coordinate: rms distance ≈ σ√3 (less what the fit absorbs)
  CHECK(fit.rms_residual == doctest::Approx(0.01 * std::sqrt(3.0)).epsilon(0.1));
  CHECK(fit.max_residual > fit.rms_residual);
  CHECK((fit.motion.R - m.R).norm() < 5e-3);

  Points<> mirrored = X;
  mirrored.col(0) *= -1;
  const auto f2 = fit_rigid_motion(exec::seq, X, mirrored);
  CHECK(f2.motion.R.determinant() == doctest::Approx(1.0));
  CHECK(f2.max_residual > 0.1);  // no rotation maps a cloud onto its mirror image
}

TEST_CASE("hinge_of: axis, angle and a point on the axis of random hinge rotations; hinge_rotation inverts it") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    Hinge<> truth;
    truth.axis = random_unit(rng);
    truth.point = Vec3<>(u(rng), u(rng), u(rng)) * 20;
    const double angle = (0.01 + 3.0 * std::abs(u(rng))) * (u(rng) < 0 ? -1 : 1);
    const RigidMotion<> m = hinge_rotation(truth, angle);
    const Vec3<> reference(u(rng), u(rng), u(rng));
    const Hinge<> h = hinge_of(m, reference);
    // (axis, angle) and (−axis, −angle) are one rotation
    const double sign = h.axis.dot(truth.axis) > 0 ? 1 : -1;
    CHECK((sign * h.axis - truth.axis).norm() < 1e-9);
    CHECK(sign * h.angle == doctest::Approx(angle).epsilon(1e-9));
    CHECK(distance_to_line(h.point, truth.point, truth.axis) < 1e-8);
    CHECK(std::abs((reference - h.point).dot(h.axis)) < 1e-8);  // the axis point nearest the reference
    const RigidMotion<> back = hinge_rotation(h, h.angle);
    CHECK((back.R - m.R).norm() < 1e-9);
    CHECK((back.t - m.t).norm() < 1e-8);
  }
}

TEST_CASE("rigid fits refuse what they cannot answer, naming it") {
  Points<> X(4, 3), Y(3, 3);
  X.setRandom();
  Y.setRandom();
  CHECK_THROWS_AS(fit_rigid_motion(exec::seq, X, Y), ShapeError);
  const Points<> two = X.topRows(2);
  CHECK_THROWS_WITH_AS(fit_rigid_motion(exec::seq, two, two), doctest::Contains("at least 3 points"), ArgumentError);
  Points<> line(5, 3);
  for (Index i = 0; i < 5; ++i) line.row(i) = Eigen::RowVector3d(1, 2, 3) * double(i);
  CHECK_THROWS_WITH_AS(fit_rigid_motion(exec::seq, line, line), doctest::Contains("one line"), ArgumentError);
  Points<> bad = X;
  bad(2, 1) = std::nan("");
  CHECK_THROWS_WITH_AS(fit_rigid_motion(exec::seq, bad, X), doctest::Contains("non-finite"), ArgumentError);

  RigidMotion<> still;
  still.t = Vec3<>(1, 0, 0);
  CHECK_THROWS_WITH_AS(hinge_of(still, Vec3<>::Zero()), doctest::Contains("does not rotate"), ArgumentError);
  RigidMotion<> screw = hinge_rotation(Hinge<>{Vec3<>::Zero(), Vec3<>::UnitZ(), 0.0}, 0.5);
  screw.t += Vec3<>(0, 0, 0.5);  // half a unit along the axis
  CHECK_THROWS_WITH_AS(hinge_of(screw, Vec3<>::Zero()), doctest::Contains("a screw, not a hinge"), ArgumentError);
}

}  // namespace mesh_test_rigid_motion
