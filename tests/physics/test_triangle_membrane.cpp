// TriangleMembrane (cloth stretching, ARAP per triangle): finite differences of the gradient and
// of the exact Hessian over random deformations (stretched, compressed, folded, nearly collapsed),
// the projected Hessian PSD, zero under rigid motion, the closed form under uniform scaling, the
// local-global matrix, and bad input.
#include <simsr/mesh/generators.hpp>
#include <simsr/physics/forces/triangle_membrane.hpp>

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
