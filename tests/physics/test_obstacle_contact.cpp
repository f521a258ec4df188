#include <simsr/physics/forces/obstacle_contact.hpp>

#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;

namespace {

/// A user-defined obstacle: the inside of a spherical bowl (free inside, d = r − ‖x − c‖). Its
/// exact penalty Hessian is PSD where d < 0, so ObstacleContact must return it unchanged.
struct Bowl {
  using scalar_type = double;
  Vec3<> c;
  double r;
  double distance(const Vec3<>& x) const { return r - (x - c).norm(); }
  Vec3<> distance_gradient(const Vec3<>& x) const { return -(x - c).normalized(); }
  Mat3<> distance_hessian(const Vec3<>& x) const {
    const double l = (x - c).norm();
    const Vec3<> n = (x - c) / l;
    return -(Mat3<>::Identity() - n * n.transpose()) / l;
  }
};
static_assert(Obstacle<Bowl>);

IndexVector every_other(Index n) {
  IndexVector v((n + 1) / 2);
  for (Index i = 0; i < v.size(); ++i) v[i] = VIndex(2 * i);
  return v;
}

VecX<> random_stiffness(Index n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(1.0, 100.0);
  VecX<> k(n);
  for (Index i = 0; i < n; ++i) k[i] = u(rng);
  return k;
}

}  // namespace

TEST_CASE("ObstacleContact: plane and bowl Hessians are exact, sphere drops its negative tangential part") {
  std::mt19937 rng(21);
  double worst_g = 0, worst_h_plane = 0, worst_h_sphere = 0, worst_h_bowl = 0, min_eig = 0;
  Index active = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const Index n = 12;
    const Points<> x = test::random_points(n, -1, 1, rng);
    const IndexVector v = every_other(n);
    const VecX<> k = random_stiffness(v.size(), rng);
    const Vec3<> p = test::random_points(1, -0.3, 0.3, rng).row(0).transpose();
    const Vec3<> dir = test::random_points(1, -1, 1, rng).row(0).transpose();

    const ObstacleContact plane(Plane<>(p, dir), v, n, k);
    const ObstacleContact sphere(Sphere<>(p, 0.9), v, n, k);
    const ObstacleContact bowl(Bowl{p, 0.8}, v, n, k);
    active += Index(sphere.active(x).size());

    worst_g = std::max({worst_g, test::rel_error(test::gradient(plane, x), test::fd_gradient(plane, x, 1e-6)),
                        test::rel_error(test::gradient(sphere, x), test::fd_gradient(sphere, x, 1e-6)),
                        test::rel_error(test::gradient(bowl, x), test::fd_gradient(bowl, x, 1e-6))});

    const Eigen::MatrixXd Hp = test::assembled_hessian(plane, x), Hs = test::assembled_hessian(sphere, x), Hb = test::assembled_hessian(bowl, x);
    worst_h_plane = std::max(worst_h_plane, test::rel_error(Hp, test::fd_hessian(plane, x, 1e-6)));
    worst_h_bowl = std::max(worst_h_bowl, test::rel_error(Hb, test::fd_hessian(bowl, x, 1e-6)));
    // sphere: exact Hessian minus the dropped k d/‖x − c‖ (I − n nᵀ) of each penetrating vertex
    Eigen::MatrixXd expect = test::fd_hessian(sphere, x, 1e-6);
    for (Index i = 0; i < v.size(); ++i) {
      const Vec3<> xi = x.row(v[i]).transpose();
      const double d = sphere.obstacle().distance(xi);
      if (d < 0) expect.block<3, 3>(3 * v[i], 3 * v[i]) -= k[i] * d * sphere.obstacle().distance_hessian(xi);
    }
    worst_h_sphere = std::max(worst_h_sphere, test::rel_error(Hs, expect));
    for (const Eigen::MatrixXd* H : {&Hp, &Hs, &Hb}) min_eig = std::min(min_eig, test::min_eigenvalue(*H) / std::max(1.0, H->cwiseAbs().maxCoeff()));
  }
  MESSAGE("obstacle contact: gradient " << worst_g << ", Hessian plane " << worst_h_plane << ", sphere (projected) " << worst_h_sphere
                                        << ", bowl " << worst_h_bowl << ", min eigenvalue " << min_eig << ", active sphere contacts " << active);
  CHECK(active > 20);
  CHECK(worst_g < 1e-7);
  CHECK(worst_h_plane < 1e-6);
  CHECK(worst_h_sphere < 1e-6);
  CHECK(worst_h_bowl < 1e-6);
  CHECK(min_eig > -1e-12);
}

TEST_CASE("ObstacleContact: analytic plane and moving sphere") {
  Points<> x(2, 3);
  x << 0.3, 0.2, -0.01, 0.0, 0.0, 0.5;
  IndexVector v(2);
  v << 0, 1;
  ObstacleContact plane(Plane<>(Vec3<>::Zero(), Vec3<>(0, 0, 3)), v, 2, 100.0);
  CHECK(plane.energy(exec::seq, x) == doctest::Approx(50.0 * 1e-4));
  const Points<> g = test::gradient(plane, x);
  CHECK((g.row(0) - Eigen::RowVector3d(0, 0, -1.0)).norm() < 1e-12);  // force +1 N along the normal
  CHECK(g.row(1).norm() == 0.0);

  ObstacleContact sphere(Sphere<>(Vec3<>(0, 0, 1.0), 0.4), v, 2, 10.0);
  CHECK(sphere.energy(exec::seq, x) == 0.0);
  CHECK(sphere.active(x).empty());
  sphere.obstacle().set_centre(Vec3<>(0, 0, 0.8));  // pushed in: vertex 1 is 0.3 from the centre
  REQUIRE(sphere.active(x).size() == 1);
  CHECK(sphere.energy(exec::seq, x) == doctest::Approx(5.0 * 0.1 * 0.1));
  CHECK((test::gradient(sphere, x).row(1) - Eigen::RowVector3d(0, 0, 10.0 * 0.1)).norm() < 1e-12);  // pushed towards −z
  // the centre itself: finite energy, gradient along +z by convention
  sphere.obstacle().set_centre(Vec3<>(0, 0, 0.5));
  CHECK(sphere.energy(exec::seq, x) == doctest::Approx(5.0 * 0.16));
  CHECK(test::gradient(sphere, x).allFinite());
}

TEST_CASE("ObstacleContact: bad input throws typed errors") {
  IndexVector v(2);
  v << 0, 3;
  CHECK_THROWS_AS(Plane<>(Vec3<>::Zero(), Vec3<>::Zero()), ArgumentError);
  CHECK_THROWS_AS(Plane<>(Vec3<>(0, std::nan(""), 0), Vec3<>::UnitZ()), ArgumentError);
  CHECK_THROWS_AS(Sphere<>(Vec3<>::Zero(), -1.0), ArgumentError);
  CHECK_THROWS_AS(Sphere<>(Vec3<>::Zero(), 0.0), ArgumentError);
  CHECK_THROWS_AS(Sphere<>(Vec3<>::Constant(std::nan("")), 1.0), ArgumentError);
  const Sphere<> s(Vec3<>::Zero(), 1.0);
  CHECK_THROWS_AS(ObstacleContact(s, v, 3, 1.0), ArgumentError);   // vertex 3 of 3
  CHECK_THROWS_AS(ObstacleContact(s, v, 4, -1.0), ArgumentError);  // negative stiffness
  CHECK_THROWS_AS(ObstacleContact(s, v, 4, VecX<>::Ones(3)), ShapeError);
  CHECK_THROWS_AS(ObstacleContact(s, v, 4, VecX<>::Constant(2, std::nan(""))), ArgumentError);
  ObstacleContact c(s, v, 4, 1.0);
  CHECK_THROWS_AS(c.energy(exec::seq, Points<>::Zero(3, 3)), ShapeError);
  CHECK_THROWS_AS(c.obstacle().set_centre(Vec3<>::Constant(INFINITY)), ArgumentError);
}

TEST_CASE("Capsule: distance against a brute-force closest point, gradient and Hessian by finite differences, beside and beyond the ends") {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const Vec3<> a(0.1, -0.2, 0.3), b(0.4, 0.9, -0.5);
  const Capsule<> cap(a, b, 0.25);
  const double h = 1e-6;
  int beside = 0, beyond = 0;
  for (int k = 0; k < 300; ++k) {
    const Vec3<> x(u(rng), u(rng), u(rng));
    double best = 1e300;  // the segment sampled densely: an independent closest distance
    for (int s = 0; s <= 20000; ++s) best = std::min(best, (x - (a + (b - a) * (s / 20000.0))).norm());
    CHECK(cap.distance(x) == doctest::Approx(best - 0.25).epsilon(1e-7));
    const double t = (x - a).dot(b - a) / (b - a).squaredNorm();
    ((t > 0 && t < 1) ? beside : beyond)++;
    Vec3<> g;
    Mat3<> H;
    for (int c = 0; c < 3; ++c) {
      Vec3<> e = Vec3<>::Zero();
      e[c] = h;
      g[c] = (cap.distance(x + e) - cap.distance(x - e)) / (2 * h);
      H.col(c) = (cap.distance_gradient(x + e) - cap.distance_gradient(x - e)) / (2 * h);
    }
    CHECK((cap.distance_gradient(x) - g).norm() < 1e-7);
    CHECK((cap.distance_hessian(x) - H).cwiseAbs().maxCoeff() < 1e-5 * (1 + H.cwiseAbs().maxCoeff()));
  }
  CHECK(beside > 50);
  CHECK(beyond > 50);
  CHECK(cap.distance(a) == doctest::Approx(-0.25));  // on the axis: inside by the radius
  CHECK(std::abs(cap.distance_gradient(0.5 * (a + b)).dot(b - a)) < 1e-12);
  CHECK_THROWS_AS(Capsule<>(a, b, 0.0), ArgumentError);
}

TEST_CASE("ObstacleContact: the local-global stand-in is k_i I on every contact vertex, touching or not") {
  const Index n = 5;
  const IndexVector v = every_other(n);
  const ObstacleContact contact(Capsule<>(Vec3<>(0, 0, 0), Vec3<>(1, 0, 0), 0.1), v, n, 7.0);
  BlockHessian<double> L(n);
  L.set_zero();
  contact.add_global_matrix(exec::seq, L);
  const Eigen::MatrixXd D = test::dense_hessian(L);
  for (Index i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) CHECK(D(3 * i + c, 3 * i + c) == (i % 2 == 0 ? 7.0 : 0.0));
  CHECK((D - Eigen::MatrixXd(D.diagonal().asDiagonal())).norm() == 0.0);
}

TEST_CASE("ObstacleContact onset: the profile is C² at 0 and −δ, and gradient and Hessian match finite differences of the energy") {
  // the profile itself: values, slopes and curvatures meet where the pieces do, slope and
  // curvature are the derivatives of the value (central differences), δ = 0 is k/2 d²
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uk(1, 1e3), ud(1e-4, 1e-2);
  double worst_join = 0, worst_fd = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const double k = uk(rng), delta = ud(rng);
    const auto at = [&](double d) { return physics::detail::penalty_profile(d, k, delta); };
    const double e = 1e-9 * delta;
    for (const double join : {0.0, -delta}) {
      const auto a = at(join - e), b = at(join + e);
      worst_join = std::max({worst_join, std::abs(a.value - b.value) / (k * delta * delta), std::abs(a.slope - b.slope) / (k * delta),
                             std::abs(a.curvature - b.curvature) / k});
    }
    for (const double d : {-0.3 * delta, -0.9 * delta, -1.7 * delta, -6 * delta}) {
      const double h = 1e-6 * delta;
      const auto p = at(d), up = at(d + h), down = at(d - h);
      worst_fd = std::max({worst_fd, std::abs((up.value - down.value) / (2 * h) - p.slope) / (k * delta),
                           std::abs((up.slope - down.slope) / (2 * h) - p.curvature) / k});
    }
    CHECK(at(1e-3).value == 0.0);
    CHECK(at(-delta).curvature == k);
    CHECK(physics::detail::penalty_profile(-0.2, k, 0.0).value == doctest::Approx(k / 2 * 0.04));
  }
  MESSAGE("penalty onset: worst jump at the joins " << worst_join << ", worst finite-difference error " << worst_fd);
  CHECK(worst_join < 1e-7);
  CHECK(worst_fd < 1e-6);

  // the term: gradient by differences of the energy, Hessian by differences of the gradient
  // against a plane (exact) and the bowl (PSD where inside), points spread across the ramp
  double worst_g = 0, worst_h = 0;
  Index in_ramp = 0, past_ramp = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const Index n = 12;
    const Points<> x = test::random_points(n, -0.05, 0.05, rng);
    const IndexVector v = every_other(n);
    const VecX<> k = random_stiffness(v.size(), rng);
    const Vec3<> dir = test::random_points(1, -1, 1, rng).row(0).transpose();
    ObstacleContact plane(Plane<>(Vec3<>::Zero(), dir), v, n, k);
    ObstacleContact bowl(Bowl{Vec3<>(0.03, 0, 0), 0.06}, v, n, k);
    plane.set_onset(0.03);
    bowl.set_onset(0.03);
    for (Index i = 0; i < v.size(); ++i) {
      const double d = plane.obstacle().distance(x.row(v[i]).transpose());
      in_ramp += d < 0 && d > -0.03;
      past_ramp += d <= -0.03;
    }
    worst_g = std::max(worst_g, test::rel_error(test::gradient(plane, x), test::fd_gradient(plane, x, 1e-7)));
    worst_h = std::max(worst_h, test::rel_error(test::assembled_hessian(plane, x), test::fd_hessian(plane, x, 1e-7)));
    worst_g = std::max(worst_g, test::rel_error(test::gradient(bowl, x), test::fd_gradient(bowl, x, 1e-7)));
    worst_h = std::max(worst_h, test::rel_error(test::assembled_hessian(bowl, x), test::fd_hessian(bowl, x, 1e-7)));
  }
  MESSAGE("contact with onset 0.03 m: gradient " << worst_g << ", Hessian " << worst_h << "; points in the ramp " << in_ramp << ", past it " << past_ramp);
  CHECK(in_ramp > 20);
  CHECK(past_ramp > 5);
  CHECK(worst_g < 1e-6);
  CHECK(worst_h < 1e-5);

  ObstacleContact c(Sphere<>(Vec3<>::Zero(), 1.0), every_other(4), 4, 1.0);
  CHECK(c.onset() == 0.0);
  CHECK_THROWS_AS(c.set_onset(-1e-3), ArgumentError);
  CHECK_THROWS_AS(c.set_onset(std::nan("")), ArgumentError);
}
