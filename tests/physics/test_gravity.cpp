#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/volume.hpp>
#include <simsr/physics/forces/gravity.hpp>

#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;

TEST_CASE("Gravity: total force is density × g × mesh volume") {
  const Vec3<> g(0.0, -9.81, 0.0);
  const double rho = 1060.0;
  SUBCASE("box") {
    const TetMesh<> m = box_tet_mesh<double>(3, 2, 4, Vec3<>(0, 0, 0), Vec3<>(0.3, 0.2, 0.5));
    const Gravity<> grav(m, rho, g);
    const Vec3<> total = grav.forces().colwise().sum().transpose();
    CHECK((total - rho * 0.3 * 0.2 * 0.5 * g).norm() < 1e-12);
    CHECK(grav.total_mass() == doctest::Approx(rho * 0.03).epsilon(1e-14));
    // interior vertices of a uniform grid weigh the same; the gradient is −m g everywhere
    const Points<> G = test::gradient(grav, m.V);
    CHECK((G + grav.forces()).norm() == 0.0);
  }
  SUBCASE("sphere shell") {
    const TetMesh<> m = sphere_shell_tet_mesh<double>(0.5, 1.0, 2, 3);
    const Gravity<> grav(m, rho, g);
    const double volume = total_volume(exec::seq, m.V, m.T);
    const Vec3<> total = grav.forces().colwise().sum().transpose();
    CHECK((total - rho * volume * g).norm() < 1e-12 * rho * volume * g.norm());
    MESSAGE("gravity: shell total-force error " << (total - rho * volume * g).norm());
  }
}

TEST_CASE("Gravity: energy is −Σ m g·x, gradient matches finite differences, Hessian adds nothing") {
  std::mt19937 rng(5);
  const TetMesh<> m = box_tet_mesh<double>(2, 2, 2);
  double worst = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const Vec3<> g = test::random_points(1, -10, 10, rng).row(0).transpose();
    const Gravity<> grav(m, 1000.0, g);
    const Points<> x = m.V + test::random_points(m.num_vertices(), -0.3, 0.3, rng);
    worst = std::max(worst, test::rel_error(test::gradient(grav, x), test::fd_gradient(grav, x, 1e-4)));
    CHECK(test::assembled_hessian(grav, x).cwiseAbs().maxCoeff() == 0.0);
    if (trial == 0) CHECK(test::fd_hessian(grav, x, 1e-4).cwiseAbs().maxCoeff() < 1e-8);
    // lifting everything by h along −g changes the energy by M |g| h
    Points<> y = x;
    y.rowwise() -= 0.1 * g.normalized().transpose();
    CHECK(grav.energy(exec::seq, y) - grav.energy(exec::seq, x) == doctest::Approx(grav.total_mass() * g.norm() * 0.1).epsilon(1e-10));
  }
  MESSAGE("gravity: worst gradient error " << worst);
  CHECK(worst < 1e-9);
}

TEST_CASE("Gravity: bad input throws typed errors") {
  const TetMesh<> m = box_tet_mesh<double>(1, 1, 1);
  const Vec3<> g(0, 0, -9.81);
  CHECK_THROWS_AS(Gravity<>(m, -1.0, g), ArgumentError);
  CHECK_THROWS_AS(Gravity<>(m, std::nan(""), g), ArgumentError);
  CHECK_THROWS_AS(Gravity<>(m, 1.0, Vec3<>(0, std::nan(""), 0)), ArgumentError);
  TetMesh<> bad = m;
  bad.T(2, 1) = VIndex(m.num_vertices());
  CHECK_THROWS_AS(Gravity<>(bad, 1.0, g), MeshError);
  CHECK_THROWS_AS(Gravity<>(VecX<>::Constant(3, -1.0), g), ArgumentError);
  const Gravity<> grav(m, 1.0, g);
  CHECK_THROWS_AS(grav.energy(exec::seq, Points<>(m.V.topRows(2))), ShapeError);
  Points<> G = Points<>::Zero(m.num_vertices() + 1, 3);
  CHECK_THROWS_AS(grav.add_gradient(exec::seq, m.V, G), ShapeError);
}
