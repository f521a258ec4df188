// Collision refinement (issue #14 item 4): a wrinkled cloth pushed into a sphere and a pole comes
// out with no vertex inside in at most 3 solves, keeping its wrinkles (its Laplacian) better than
// projecting the inside vertices out does; an untouched cloth is left bitwise alone.
#include <doctest/doctest.h>

#include <simsr/mesh/cotangent_laplacian.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/vertex_areas.hpp>
#include <simsr/shell/collision_refinement.hpp>
#if defined(SIMSR_HAVE_CHOLMOD)
#include <simsr/physics/linear_solvers/cholmod_cholesky.hpp>
#endif

#include "../support/require.hpp"

#include <cmath>
#include <string>

namespace shell_test_collision_refinement {

using namespace simsr;
using namespace simsr::shell;

/// A 1 m sheet in z = 0 with wrinkles of 1 cm along x.
TriMesh<> wrinkled_sheet(Points<>& x) {
  TriMesh<> rest = square_sheet(1.0, 32);
  rest.V.rowwise() -= Vec3<>(0.5, 0.5, 0).transpose();
  x = rest.V;
  for (Index i = 0; i < x.rows(); ++i) x(i, 2) = 0.01 * std::sin(40 * x(i, 0));
  return rest;
}

template <class O>
void check_refinement(const O& obstacle, const char* what) {
  INFO(std::string(what));
  Points<> x0;
  const TriMesh<> rest = wrinkled_sheet(x0);
  CollisionRefinement refine(rest);
  Points<> x = x0;
  const auto report = refine.refine(exec::seq, obstacle, x);
  CHECK(report.inside_before > 5);
  CHECK(report.deepest_before < -0.03);
  CHECK(report.solves >= 1);
  CHECK(report.solves <= 3);
  CHECK(report.deepest_after >= 0);  // nothing inside
  for (Index i = 0; i < x.rows(); ++i) CHECK(obstacle.distance(Vec3<>(x.row(i).transpose())) >= 0);
  // the naive alternative: only the inside vertices, moved to their closest surface point
  Points<> naive = x0;
  for (Index i = 0; i < x0.rows(); ++i) {
    const Vec3<> p = x0.row(i).transpose();
    const double d = obstacle.distance(p);
    if (d < 0) naive.row(i) = (p - d * obstacle.distance_gradient(p)).transpose();
  }
  // the wrinkles of the vertices left outside: their Laplacian changes little (the cloth around a
  // pushed-out patch follows it smoothly), where projecting leaves a kink at the patch's rim
  const auto L = cotangent_laplacian(exec::seq, rest.V, rest.F);
  const Points<> dk = L * (x - x0), dp = L * (naive - x0);
  double kept = 0, projected = 0;
  for (Index i = 0; i < x0.rows(); ++i)
    if (obstacle.distance(Vec3<>(x0.row(i).transpose())) >= 0) kept += dk.row(i).squaredNorm(), projected += dp.row(i).squaredNorm();
  kept = std::sqrt(kept), projected = std::sqrt(projected);
  MESSAGE(std::string(what) << ": " << report.inside_before << " inside (deepest " << report.deepest_before * 1e3 << " mm), " << report.solves
                << " solves, " << report.projected << " projected; the outside vertices' Laplacian change " << kept << " against the projection's " << projected);
  CHECK(kept < 0.8 * projected);
  // far from the obstacle the cloth is as it was
  double far_motion = 0;
  for (Index i = 0; i < x.rows(); ++i)
    if (obstacle.distance(Vec3<>(x0.row(i).transpose())) > 0.3) far_motion = std::max(far_motion, (x.row(i) - x0.row(i)).norm());
  CHECK(far_motion < 0.01);
  CHECK(far_motion > 0);  // ...and yet it moved (the cloth followed)
}

TEST_CASE("CollisionRefinement: a wrinkled sheet through a sphere and a pole: none inside after <= 3 solves, the wrinkles kept better than by projection") {
  check_refinement(physics::Sphere<>(Vec3<>(0.05, -0.02, -0.1), 0.15), "sphere");
  check_refinement(physics::Capsule<>(Vec3<>(-0.6, 0.1, -0.04), Vec3<>(0.6, -0.1, -0.04), 0.08), "pole");
}

TEST_CASE("CollisionRefinement: one solve is the minimizer of the file comment's energy; a kept factorization gives what a fresh one does") {
  Points<> x0;
  const TriMesh<> rest = wrinkled_sheet(x0);
  const physics::Sphere<> sphere(Vec3<>(0.05, -0.02, -0.1), 0.15);
  const physics::Capsule<> pole(Vec3<>(-0.6, 0.1, -0.04), Vec3<>(0.6, -0.1, -0.04), 0.08);
  // max_iterations 1: the constrained set is the vertices inside x0, their targets known here;
  // the normal equations (LᵀM⁻¹L + M/ℓ⁴ + W) x = (LᵀM⁻¹L + M/ℓ⁴) x0 + W p built independently
  const CollisionRefinementOptions o{.max_iterations = 1};
  CollisionRefinement one(rest, o);
  Points<> x = x0;
  const auto report = one.refine(exec::seq, sphere, x);
  REQUIRE(report.solves == 1);
  const Eigen::SparseMatrix<double> L = cotangent_laplacian(exec::seq, rest.V, rest.F);
  const VecX<> area = voronoi_areas(rest.V, rest.F);
  Eigen::SparseMatrix<double> A = L.transpose() * area.cwiseInverse().asDiagonal() * L;
  for (Index i = 0; i < A.rows(); ++i) A.coeffRef(i, i) += area[i] / std::pow(o.falloff, 4);
  Points<> rhs = A * x0;
  Eigen::SparseMatrix<double> K = A;
  Index inside = 0;
  for (Index i = 0; i < x0.rows(); ++i) {
    const Vec3<> p = x0.row(i).transpose();
    const double d = sphere.distance(p);
    if (d >= 0) continue;
    ++inside;
    const double w = o.weight * A.coeff(i, i);
    K.coeffRef(i, i) += w;
    rhs.row(i) += w * (p + (o.clearance - d) * sphere.distance_gradient(p)).transpose();
  }
  REQUIRE(inside == report.inside_before);
  // nothing was left inside for the projection to move: x is the solve's, and solves them
  REQUIRE(report.projected == 0);
  const Points<> r = K * x - rhs;
  CHECK(r.rowwise().norm().maxCoeff() < 1e-9 * rhs.rowwise().norm().maxCoeff());
  // one object refining frame after frame (sphere, pole, sphere) gives bitwise what fresh objects do
  CollisionRefinement kept(rest);
  for (int k = 0; k < 3; ++k) {
    Points<> a = x0, b = x0;
    CollisionRefinement fresh(rest);
    if (k == 1) {
      kept.refine(exec::seq, pole, a);
      fresh.refine(exec::seq, pole, b);
    } else {
      kept.refine(exec::seq, sphere, a);
      fresh.refine(exec::seq, sphere, b);
    }
    CHECK(a == b);
  }
}

TEST_CASE("CollisionRefinement's linear solver is a type: CHOLMOD refines as Eigen's LDLT does") {
#if defined(SIMSR_HAVE_CHOLMOD)
  Points<> x0;
  const TriMesh<> rest = wrinkled_sheet(x0);
  CollisionRefinement<physics::SparseCholesky<>> simplicial(rest);
  CollisionRefinement<physics::CholmodCholesky<>> cholmod(rest);
  const physics::Sphere<> sphere(Vec3<>(0.05, -0.02, -0.1), 0.15);
  const physics::Capsule<> pole(Vec3<>(-0.6, 0.1, -0.04), Vec3<>(0.6, -0.1, -0.04), 0.08);
  for (int k = 0; k < 3; ++k) {  // sphere, pole, sphere: each object keeps its analysis between frames
    Points<> a = x0, b = x0;
    const auto ra = k == 1 ? simplicial.refine(exec::seq, pole, a) : simplicial.refine(exec::seq, sphere, a);
    const auto rb = k == 1 ? cholmod.refine(exec::omp, pole, b) : cholmod.refine(exec::omp, sphere, b);
    CHECK(ra.solves == rb.solves);
    CHECK(ra.constrained == rb.constrained);
    CHECK(ra.projected == rb.projected);
    const double motion = (a - x0).cwiseAbs().maxCoeff();
    CHECK(motion > 0.01);
    CHECK((a - b).cwiseAbs().maxCoeff() <= 1e-9 * motion);  // the two factorizations' round-off
  }
#else
  SIMSR_MISSING("CHOLMOD: configure with -DSIMSR_WITH_CHOLMOD=ON (apt-get install libsuitesparse-dev) to test CollisionRefinement with physics::CholmodCholesky");
#endif
}

TEST_CASE("CollisionRefinement: nothing inside leaves the cloth bitwise alone; bad input is named") {
  Points<> x0;
  const TriMesh<> rest = wrinkled_sheet(x0);
  CollisionRefinement refine(rest);
  Points<> x = x0;
  const auto report = refine.refine(exec::seq, physics::Sphere<>(Vec3<>(0, 0, -0.5), 0.2), x);
  CHECK(report.solves == 0);
  CHECK(report.inside_before == 0);
  CHECK(x == x0);
  Points<> short_x = x0.topRows(10);
  CHECK_THROWS_AS(refine.refine(exec::seq, physics::Sphere<>(Vec3<>(0, 0, 0), 0.1), short_x), ShapeError);
  x(3, 1) = NAN;
  CHECK_THROWS_AS(refine.refine(exec::seq, physics::Sphere<>(Vec3<>(0, 0, 0), 0.1), x), ArgumentError);
  CHECK_THROWS_AS(CollisionRefinement(rest, {.clearance = -1}), ArgumentError);
  CHECK_THROWS_AS(CollisionRefinement(rest, {.max_iterations = 0}), ArgumentError);
  CHECK_THROWS_AS(CollisionRefinement(rest, {.falloff = 0}), ArgumentError);
  TriMesh<> bad = rest;
  bad.F(0, 0) = 99999;
  CHECK_THROWS_AS(CollisionRefinement{bad}, MeshError);
}

}  // namespace shell_test_collision_refinement
