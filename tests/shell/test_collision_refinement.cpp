// Collision refinement (issue #14 item 4): a wrinkled cloth pushed into a sphere and a pole comes
// out with no vertex inside in at most 3 solves, keeping its wrinkles (its Laplacian) better than
// projecting the inside vertices out does; an untouched cloth is left bitwise alone.
#include <doctest/doctest.h>

#include <simsr/mesh/cotangent_laplacian.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/shell/collision_refinement.hpp>

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
