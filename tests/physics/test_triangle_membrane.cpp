// TriangleMembrane (cloth stretching, ARAP per triangle): finite differences of the gradient and
// of the exact Hessian over random deformations (stretched, compressed, folded, nearly collapsed),
// the projected Hessian PSD, zero under rigid motion, the closed form under uniform scaling, the
// local-global matrix, and bad input; and one cloth step with the thin-shell scenes' terms.
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/vertex_areas.hpp>
#include <simsr/physics/forces/gravity.hpp>
#include <simsr/physics/forces/implicit_inertia.hpp>
#include <simsr/physics/forces/obstacle_contact.hpp>
#include <simsr/physics/forces/surface_bending.hpp>
#include <simsr/physics/forces/triangle_membrane.hpp>
#include <simsr/physics/local_global.hpp>
#include <simsr/physics/quasistatic.hpp>

#include <doctest/doctest.h>

#include <Eigen/Geometry>

#include <random>

#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;
using namespace simsr::test;

TEST_CASE("TriangleMembrane: gradient and exact Hessian match finite differences; projected Hessian PSD; seq == omp") {
  const TriMesh<> sheet = square_sheet(1.0, 3);
  const TriangleMembrane<> mem(sheet.V.rows(), sheet.V, sheet.F, 3.0);
  std::mt19937 rng(12);
  for (int trial = 0; trial < 8; ++trial) {
    Points<> x = sheet.V + random_points(sheet.V.rows(), -0.08, 0.08, rng);
    if (trial == 6) x = 0.5 * sheet.V + random_points(sheet.V.rows(), -0.01, 0.01, rng);  // compressed: indefinite
    if (trial == 7) x.col(2) = (x.col(0).array() * 7).sin() * 0.1;                           // folded into 3-D
    CHECK(rel_error(gradient(mem, x), fd_gradient(mem, x, 1e-6)) < 1e-7);
    CHECK(rel_error(assembled_hessian(mem, x, Definiteness::exact), fd_hessian(mem, x, 1e-6)) < 1e-6);
    CHECK(min_eigenvalue(assembled_hessian(mem, x, Definiteness::project)) > -1e-10);
    Points<> gs = Points<>::Zero(x.rows(), 3), go = gs;
    mem.add_gradient(exec::seq, x, gs);
    mem.add_gradient(exec::omp, x, go);
    CHECK(gs == go);
    CHECK(mem.energy(exec::seq, x) == mem.energy(exec::omp, x));
  }
  // compression makes the exact Hessian indefinite (buckling): the projection is not idle
  CHECK(min_eigenvalue(assembled_hessian(mem, 0.5 * sheet.V, Definiteness::exact)) < -1e-6);
}

TEST_CASE("TriangleMembrane: zero under rigid motion, k·A·2(s−1)² under uniform in-plane scaling by s, constant matrix") {
  const TriMesh<> disk = disk_surface(0.7, 3);
  const double k = 5.0;
  const TriangleMembrane<> mem(disk.V.rows(), disk.V, disk.F, k);
  const double area = mem.rest_areas().sum();
  CHECK(area == doctest::Approx(0.5 * 18 * 0.49 * std::sin(2 * M_PI / 18)).epsilon(1e-12));
  const Mat3<> R = Eigen::AngleAxisd(2.5, Vec3<>(1, -2, 0.5).normalized()).toRotationMatrix();
  const Points<> moved = (disk.V * R.transpose()).rowwise() + Vec3<>(1, 2, 3).transpose();
  CHECK(mem.energy(exec::seq, moved) < 1e-24);
  CHECK(gradient(mem, moved).cwiseAbs().maxCoeff() < 1e-12);
  for (const double s : {0.7, 1.3}) CHECK(mem.energy(exec::seq, s * disk.V) == doctest::Approx(k * area * 2 * (s - 1) * (s - 1)).epsilon(1e-12));
  // the local-global matrix is 2kA·GᵀG: symmetric PSD with the three translations in its null space
  BlockHessian<double> L(disk.V.rows());
  L.set_zero();
  mem.add_global_matrix(exec::seq, L);
  const Eigen::MatrixXd D = dense_hessian(L);
  CHECK((D - D.transpose()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(min_eigenvalue(D) > -1e-10);
  for (int a = 0; a < 3; ++a) {
    Eigen::VectorXd t = Eigen::VectorXd::Zero(3 * disk.V.rows());
    for (Index i = 0; i < disk.V.rows(); ++i) t[3 * i + a] = 1;
    CHECK((D * t).norm() < 1e-12);
  }
}

TEST_CASE("TriangleMembrane: bad input is named") {
  const TriMesh<> sheet = square_sheet(1.0, 2);
  Tris bad = sheet.F;
  bad(1, 2) = 40;
  CHECK_THROWS_AS(TriangleMembrane<>(sheet.V.rows(), sheet.V, bad, 1.0), MeshError);
  Points<> flat = sheet.V;
  flat.row(4) = flat.row(0);  // triangles at vertex 4 collapse
  CHECK_THROWS_AS(TriangleMembrane<>(flat.rows(), flat, sheet.F, 1.0), MeshError);
  CHECK_THROWS_AS(TriangleMembrane<>(sheet.V.rows(), sheet.V, sheet.F, -1.0), ArgumentError);
}


TEST_CASE("cloth step: a sheet pinned at two corners drops onto a pole; local-global and Newton agree, nothing sinks far into it") {
  // the thin-shell scenes' terms on a triangle surface (no tets: the solvers' patterns grow from
  // the terms' blocks): membrane, bending (flat rest: quadratic), gravity and inertia from the
  // lumped areal masses, penalty contact against a capsule, two pinned corners
  const TriMesh<> sheet = square_sheet(1.0, 6);
  const Index n = sheet.V.rows();
  const VecX<> masses = 0.2 * voronoi_areas(sheet.V, sheet.F);  // 0.2 kg/m²
  const TriangleMembrane<> stretch(n, sheet.V, sheet.F, 50.0);
  const SurfaceBending<> bend(n, sheet.V, sheet.F, 1e-4);
  const Gravity<> gravity(masses, Vec3<>(0, 0, -9.81));
  ImplicitInertia<> inertia(masses, sheet.V, {.h = 1.0 / 30, .alpha = 1, .beta = 0, .gamma = 1});
  IndexVector all(n);
  for (Index i = 0; i < n; ++i) all[i] = VIndex(i);
  const ObstacleContact pole(Capsule<>(Vec3<>(0.5, -0.5, -0.08), Vec3<>(0.5, 1.5, -0.08), 0.05), all, n, VecX<>(1e5 * voronoi_areas(sheet.V, sheet.F)));
  const DirichletBoundary<> pins{(IndexVector(2) << 0, VIndex(6)).finished(), Points<>(sheet.V({0, 6}, Eigen::all))};
  LocalGlobalSolver<> pd(n, Tets(0, 4), LocalGlobalOptions{.relative_tolerance = 1e-10, .max_iterations = 20000});
  QuasistaticSolver<> newton(n, Tets(0, 4), NewtonOptions{.relative_tolerance = 1e-10, .progress = {}});
  Points<> xl = sheet.V, xn = sheet.V;
  ImplicitInertia<> inertia_n = inertia;
  for (int step = 0; step < 4; ++step) {
    const auto rl = pd.solve(exec::omp, xl, pins, stretch, bend, gravity, inertia, pole);
    const auto rn = newton.solve(exec::omp, xn, pins, stretch, bend, gravity, inertia_n, pole);
    REQUIRE(rl.converged);
    REQUIRE(rn.converged);
    CHECK((xl - xn).cwiseAbs().maxCoeff() < 1e-6);
    inertia.advance(xl);
    inertia_n.advance(xn);
  }
  CHECK((xl - sheet.V).col(2).minCoeff() < -0.05);  // it fell
  double deepest = 0;
  for (Index i = 0; i < n; ++i) deepest = std::min(deepest, pole.obstacle().distance(Vec3<>(xl.row(i).transpose())));
  CHECK(deepest < 0);        // the pole is touched...
  CHECK(deepest > -0.01);    // ...and holds the sheet (the penalty's depth: under a centimetre)
}
