// SurfaceBending (SoftDECA's E_curv): finite differences on a perturbed sphere whose vertices
// sit inside a larger mesh's numbering, invariance under rigid motion, the closed form under
// uniform scaling, the rest curvature of a sphere, and bad input.
#include <simsr/mesh/generators.hpp>
#include <simsr/physics/forces/surface_bending.hpp>

#include <doctest/doctest.h>

#include <Eigen/Geometry>

#include <random>

#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;
using namespace simsr::test;

namespace test_surface_bending {

/// An icosphere's vertices placed at odd indices of a mesh with 2·#V + 3 vertices (the others are
/// not on the surface), its triangles renumbered accordingly.
struct Embedded {
  Points<> rest;
  Tris F;
  Index n;
};

Embedded sphere_in_mesh(Index level, double radius) {
  const auto s = icosphere<double>(level, radius);
  Embedded e;
  e.n = 2 * s.V.rows() + 3;
  e.rest = Points<>::Zero(e.n, 3);
  for (Index i = 0; i < s.V.rows(); ++i) e.rest.row(2 * i + 1) = s.V.row(i);
  e.F = s.F;
  for (Index f = 0; f < e.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) e.F(f, c) = VIndex(2 * s.F(f, c) + 1);
  return e;
}

}  // namespace test_surface_bending

TEST_CASE("SurfaceBending: gradient and Hessian match finite differences; projected Hessian PSD; seq == omp") {
  const auto m = test_surface_bending::sphere_in_mesh(1, 1.0);
  const SurfaceBending<> bend(m.n, m.rest, m.F, 0.7);
  std::mt19937 rng(9);
  for (int trial = 0; trial < 6; ++trial) {
    Points<> x = m.rest + random_points(m.n, -0.15, 0.15, rng);
    if (trial == 5) x = 0.6 * m.rest;  // compressed: every ‖Δx‖ < ‖Δ_b x‖, the tangential part negative
    CHECK(rel_error(gradient(bend, x), fd_gradient(bend, x, 1e-6)) < 1e-6);
    CHECK(rel_error(assembled_hessian(bend, x, Definiteness::exact), fd_hessian(bend, x, 1e-6)) < 1e-5);
    CHECK(min_eigenvalue(assembled_hessian(bend, x, Definiteness::project)) > -1e-10);
    Points<> gs = Points<>::Zero(m.n, 3), go = gs;
    bend.add_gradient(exec::seq, x, gs);
    bend.add_gradient(exec::omp, x, go);
    CHECK(gs == go);
    // vertices off the surface feel nothing
    for (Index v = 0; v < m.n; v += 2) CHECK(gs.row(v).norm() == 0);
  }
}

TEST_CASE("SurfaceBending: zero at rest and under rigid motion; (s-1)^2 k sum A b^2 under uniform scaling; a sphere's |Δx| ≈ 2/r") {
  const double r = 0.3;
  const auto m = test_surface_bending::sphere_in_mesh(3, r);
  const SurfaceBending<> bend(m.n, m.rest, m.F, 2.0);
  CHECK(bend.energy(exec::seq, m.rest) == doctest::Approx(0).epsilon(1e-14));
  const Mat3<> R = Eigen::AngleAxisd(0.7, Vec3<>(1, 2, 3).normalized()).toRotationMatrix();
  Points<> moved = (m.rest * R.transpose()).rowwise() + Vec3<>(0.3, -1, 2).transpose();
  CHECK(bend.energy(exec::seq, moved) < 1e-12 * bend.energy(exec::seq, 1.1 * m.rest));
  double sum = 0;
  for (Index i = 0; i < Index(bend.vertices().size()); ++i) sum += bend.areas()[i] * bend.rest_curvature()[i] * bend.rest_curvature()[i];
  for (double s : {0.8, 1.25}) CHECK(bend.energy(exec::seq, s * m.rest) == doctest::Approx(2.0 * (s - 1) * (s - 1) * sum).epsilon(1e-10));
  // the mean-curvature normal of a sphere: ‖Δx‖ = 2H = 2/r (the discretization's error a few %)
  CHECK(bend.rest_curvature().mean() == doctest::Approx(2 / r).epsilon(0.03));
  CHECK(bend.areas().sum() == doctest::Approx(4 * M_PI * r * r).epsilon(0.02));
}

TEST_CASE("SurfaceBending: bad input is named") {
  const auto m = test_surface_bending::sphere_in_mesh(0, 1.0);
  Tris bad = m.F;
  bad(3, 1) = VIndex(m.n);
  CHECK_THROWS_WITH_AS(SurfaceBending<>(m.n, m.rest, bad, 1.0), doctest::Contains("triangle 3"), MeshError);
  CHECK_THROWS_AS(SurfaceBending<>(m.n, m.rest, m.F, -1.0), ArgumentError);
  Points<> flat = m.rest;
  flat.col(2).setZero();
  flat.col(1).setZero();  // every triangle degenerate
  CHECK_THROWS_WITH_AS(SurfaceBending<>(m.n, flat, m.F, 1.0), doctest::Contains("zero Voronoi area"), MeshError);
  Points<> nan = m.rest;
  nan(1, 0) = std::nan("");
  CHECK_THROWS_AS(SurfaceBending<>(m.n, nan, m.F, 1.0), ArgumentError);
}
