// RoundedCylinder and CapsuleUnion (the thin-shell scenes' table and body-like obstacle), and
// VertexForces (wind as a per-step potential).
#include <simsr/physics/forces/obstacle_shapes.hpp>
#include <simsr/physics/forces/vertex_forces.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "forces_checks.hpp"

namespace physics_test_obstacle_shapes {

using namespace simsr;
using namespace simsr::physics;

/// ∇d and ∇²d of `o` at x by central differences of d and of ∇d.
template <class O>
std::pair<Vec3<>, Mat3<>> fd_derivatives(const O& o, const Vec3<>& x, double h = 1e-6) {
  Vec3<> g;
  Mat3<> H;
  for (int c = 0; c < 3; ++c) {
    Vec3<> e = Vec3<>::Zero();
    e[c] = h;
    g[c] = (o.distance(x + e) - o.distance(x - e)) / (2 * h);
    H.col(c) = (o.distance_gradient(x + e) - o.distance_gradient(x - e)) / (2 * h);
  }
  return {g, H};
}

TEST_CASE("RoundedCylinder: distance against a brute-force closest point of the solid, gradient and Hessian by finite differences in every region") {
  std::mt19937 rng(91);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  const Vec3<> c(0.1, -0.2, 0.3), axis = Vec3<>(0.3, -0.4, 1.0).normalized();
  const double a = 0.5, hh = 0.25, r = 0.05;
  const RoundedCylinder<> cyl(c, Vec3<>(0.3, -0.4, 1.0) * 2.0, a, hh, r);
  CHECK((cyl.axis() - axis).norm() < 1e-15);
  // an orthonormal frame of the axis for the brute force
  const Vec3<> e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  int cap = 0, side = 0, rim = 0;
  for (int k = 0; k < 400; ++k) {
    const Vec3<> x = c + Vec3<>(u(rng), u(rng), u(rng));
    const Vec3<> v = x - c;
    const double z = v.dot(axis), s = (v - z * axis).norm();
    if (s <= a && std::abs(z) <= hh) continue;  // inside: checked below
    // the solid's closest point, brute force over a polar grid of the solid's surface
    double best = 1e300;
    for (int i = 0; i <= 60; ++i)
      for (int j = 0; j < 240; ++j) {
        const double phi = 2 * M_PI * j / 240.0;
        const Vec3<> radial = std::cos(phi) * e1 + std::sin(phi) * e2;
        best = std::min(best, (x - (c + a * i / 60.0 * radial + hh * axis)).norm());        // top cap
        best = std::min(best, (x - (c + a * i / 60.0 * radial - hh * axis)).norm());        // bottom cap
        best = std::min(best, (x - (c + a * radial + hh * (2.0 * i / 60.0 - 1) * axis)).norm());  // side
      }
    // the sampled surface is an upper bound within its spacing (~1 cm at the rim)
    CHECK(cyl.distance(x) <= best - r + 1e-12);
    CHECK(cyl.distance(x) >= best - r - 2e-3);
    // the solid is a disk × an interval in orthogonal coordinates: its closest point clamps each
    const Vec3<> radial = v - z * axis;
    const Vec3<> q = c + std::clamp(z, -hh, hh) * axis + (s > a ? a / s : 1.0) * radial;
    CHECK(cyl.distance(x) == doctest::Approx((x - q).norm() - r).epsilon(1e-12));
    // away from the region boundaries (where the Hessian jumps), the derivatives
    const double ds = s - a, dz = std::abs(z) - hh;
    if (std::abs(ds) < 1e-3 || std::abs(dz) < 1e-3) continue;
    const auto [g, H] = fd_derivatives(cyl, x);
    CHECK((cyl.distance_gradient(x) - g).norm() < 1e-7);
    CHECK((cyl.distance_hessian(x) - H).cwiseAbs().maxCoeff() < 1e-5 * (1 + H.cwiseAbs().maxCoeff()));
    (ds < 0 ? cap : (dz < 0 ? side : rim))++;
  }
  CHECK(cap > 20);
  CHECK(side > 20);
  CHECK(rim > 20);
  // inside: minus the nearer face's depth, its normal
  CHECK(cyl.distance(c) == doctest::Approx(-hh - r));
  CHECK((cyl.distance_gradient(c + 0.01 * axis) - axis).norm() < 1e-12);
  CHECK(cyl.distance(c + 0.45 * e1) == doctest::Approx(-0.05 - r));
  CHECK((cyl.distance_gradient(c + 0.45 * e1) - e1).norm() < 1e-12);
  // on the axis above the cap: a fixed radial direction, a finite Hessian
  CHECK(cyl.distance_hessian(c + axis).allFinite());
  CHECK_THROWS_AS(RoundedCylinder<>(c, Vec3<>::Zero(), a, hh, r), ArgumentError);
  CHECK_THROWS_AS(RoundedCylinder<>(c, axis, -1.0, hh, r), ArgumentError);
  CHECK_THROWS_AS(RoundedCylinder<>(c, axis, a, hh, 0.0), ArgumentError);
  CHECK_THROWS_AS(RoundedCylinder<>(Vec3<>(NAN, 0, 0), axis, a, hh, r), ArgumentError);
}

TEST_CASE("CapsuleUnion: the closest capsule's distance, gradient and Hessian; each capsule moves; no capsule is an error") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  CapsuleUnion<> body({Capsule<>(Vec3<>(0, 0, 0), Vec3<>(0, 0, 0.6), 0.15),       // torso
                       Capsule<>(Vec3<>(0, 0, 0.55), Vec3<>(0.5, 0, 0.4), 0.05),  // arm
                       Capsule<>(Vec3<>(0, 0, 0.8), Vec3<>(0, 0, 0.8), 0.1)});    // head
  CHECK(body.size() == 3);
  for (int k = 0; k < 200; ++k) {
    const Vec3<> x(u(rng), u(rng), 0.5 + u(rng));
    double best = 1e300;
    Index which = -1;
    for (Index j = 0; j < 3; ++j)
      if (body.capsule(j).distance(x) < best) best = body.capsule(j).distance(x), which = j;
    CHECK(body.distance(x) == best);
    CHECK(body.closest(x) == which);
    CHECK(body.distance_gradient(x) == body.capsule(which).distance_gradient(x));
    CHECK(body.distance_hessian(x) == body.capsule(which).distance_hessian(x));
  }
  body.capsule(2).set_ends(Vec3<>(0, 0, 2), Vec3<>(0, 0, 2));
  CHECK(body.distance(Vec3<>(0, 0, 2)) == doctest::Approx(-0.1));
  CHECK_THROWS_AS(CapsuleUnion<>(std::vector<Capsule<>>{}), ArgumentError);
}

TEST_CASE("VertexForces: energy −Σ f·x, gradient −f by finite differences, no Hessian; bad forces are named") {
  std::mt19937 rng(8);
  VertexForces<> f(6);
  Points<> forces = test::random_points(6, -1, 1, rng), x = test::random_points(6, -1, 1, rng);
  f.set_forces(forces);
  CHECK(f.energy(exec::seq, x) == doctest::Approx(-(forces.array() * x.array()).sum()));
  CHECK(test::rel_error(test::gradient(f, x), test::fd_gradient(f, x, 1e-6)) < 1e-8);
  CHECK(test::assembled_hessian(f, x, Definiteness::exact).cwiseAbs().maxCoeff() == 0);
  CHECK_THROWS_AS(f.set_forces(Points<>::Zero(5, 3)), ShapeError);
  forces(2, 1) = NAN;
  CHECK_THROWS_AS(f.set_forces(forces), ArgumentError);
}

}  // namespace physics_test_obstacle_shapes
