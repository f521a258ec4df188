#include <simsr/mesh/generators.hpp>
#include <simsr/physics/forces/bone_attachment.hpp>

#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;

TEST_CASE("hinge_rotation: axis points fixed, rotation by the angle, composition") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ang(-3.0, 3.0);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3<> p = test::random_points(1, -1, 1, rng).row(0).transpose();
    const Vec3<> dir = test::random_points(1, -1, 1, rng).row(0).transpose() * 3.0;  // not normalized
    const double a = ang(rng), b = ang(rng);
    const RigidTransform<> Ra = hinge_rotation(p, dir, a);
    const Vec3<> n = dir.normalized();
    // points on the axis stay put
    for (double s : {-2.0, 0.0, 0.7}) worst = std::max(worst, (Ra.apply(Vec3<>(p + s * n)) - (p + s * n)).norm());
    // R is a rotation
    CHECK((Ra.R * Ra.R.transpose() - Mat3<>::Identity()).norm() < 1e-14);
    CHECK(Ra.R.determinant() == doctest::Approx(1.0));
    // a point off the axis turns by the angle about it (right-handed), keeping its distance
    Vec3<> q = test::random_points(1, -1, 1, rng).row(0).transpose();
    const Vec3<> r = (q - p) - n * n.dot(q - p);
    const Vec3<> r2 = (Ra.apply(q) - p) - n * n.dot(Ra.apply(q) - p);
    CHECK(r2.norm() == doctest::Approx(r.norm()).epsilon(1e-12));
    CHECK(std::atan2(n.dot(r.cross(r2)), r.dot(r2)) == doctest::Approx(a).epsilon(1e-10));
    CHECK(n.dot(Ra.apply(q) - q) == doctest::Approx(0.0).epsilon(1e-12));
    // composition about the same axis adds angles; inverse undoes
    const RigidTransform<> ab = Ra * hinge_rotation(p, dir, b), direct = hinge_rotation(p, dir, a + b);
    worst = std::max(worst, (ab.apply(q) - direct.apply(q)).norm());
    worst = std::max(worst, (Ra.inverse().apply(Ra.apply(q)) - q).norm());
    // composition order: (A * B)(x) = A(B(x)) for different axes
    const RigidTransform<> B = hinge_rotation(Vec3<>(0.1, 0.2, 0.3), Vec3<>(0, 1, 0), b);
    worst = std::max(worst, ((Ra * B).apply(q) - Ra.apply(B.apply(q))).norm());
  }
  MESSAGE("hinge_rotation: worst error " << worst);
  CHECK(worst < 1e-12);
  // quarter turn about z through (1, 0, 0): (2, 0, 0) → (1, 1, 0)
  const RigidTransform<> quarter = hinge_rotation(Vec3<>(1, 0, 0), Vec3<>(0, 0, 2), M_PI / 2);
  CHECK((quarter.apply(Vec3<>(2, 0, 0)) - Vec3<>(1, 1, 0)).norm() < 1e-15);
  Points<> P(2, 3);
  P << 2, 0, 0, 1, 0, 5;
  const Points<> Q = quarter.apply(P);
  CHECK((Q.row(0) - Eigen::RowVector3d(1, 1, 0)).norm() < 1e-15);
  CHECK((Q.row(1) - Eigen::RowVector3d(1, 0, 5)).norm() < 1e-15);

  CHECK_THROWS_AS(hinge_rotation(Vec3<>::Zero(), Vec3<>::Zero(), 1.0), ArgumentError);
  CHECK_THROWS_AS(hinge_rotation(Vec3<>::Zero(), Vec3<>(0, 0, std::nan("")), 1.0), ArgumentError);
  CHECK_THROWS_AS(hinge_rotation(Vec3<>::Zero(), Vec3<>(0, 0, 1), std::nan("")), ArgumentError);
}

TEST_CASE("BoneAttachments: a static cranium and a hinged jaw give a sorted Dirichlet boundary") {
  const TetMesh<> m = box_tet_mesh<double>(4, 2, 2);
  BoneAttachments<> bones(m.V);
  // cantilever-style selection: the clamped end x = 0 is the "cranium", the top of the far end the "jaw"
  const IndexVector cranium = select_vertices(m.V, [](const Vec3<>& p) { return p.x() < 1e-9; });
  const IndexVector jaw = select_vertices(m.V, [](const Vec3<>& p) { return p.x() > 0.99 && p.z() > 0.99; });
  CHECK(cranium.size() == 9);
  CHECK(jaw.size() == 3);
  IndexVector jaw_shuffled(5);
  jaw_shuffled << jaw[2], jaw[0], jaw[1], jaw[0], jaw[2];  // any order, duplicates merged
  CHECK(bones.add_bone("cranium", cranium) == 0);
  CHECK(bones.add_bone("jaw", jaw_shuffled) == 1);
  CHECK(bones.vertices("jaw") == jaw);
  CHECK(bones.owner(jaw[1]) == 1);
  CHECK(bones.owner(1) == -1);

  DirichletBoundary<> bc = bones.boundary();
  CHECK(bc.size() == 12);
  for (Index b = 0; b < bc.size(); ++b) {
    if (b > 0) CHECK(bc.vertices[b - 1] < bc.vertices[b]);
    CHECK(bc.targets.row(b) == m.V.row(bc.vertices[b]));
  }

  const Vec3<> hinge(1.0, 0.0, 1.0), axis(0.0, 1.0, 0.0);
  const RigidTransform<> open = hinge_rotation(hinge, axis, 0.3);
  bones.set_transform("jaw", open);
  bc = bones.boundary();
  for (Index b = 0; b < bc.size(); ++b) {
    const Vec3<> rest = m.V.row(bc.vertices[b]).transpose();
    const Vec3<> expect = bones.owner(bc.vertices[b]) == 1 ? open.apply(rest) : rest;
    CHECK((bc.targets.row(b).transpose() - expect).norm() < 1e-15);
  }
  // the jaw vertices lie on the hinge axis (x = 1, z = 1): they stay put
  for (Index i = 0; i < jaw.size(); ++i) CHECK((open.apply(Vec3<>(m.V.row(jaw[i]).transpose())) - m.V.row(jaw[i]).transpose()).norm() < 1e-15);
}

TEST_CASE("BoneAttachments: bad input throws typed errors") {
  const TetMesh<> m = box_tet_mesh<double>(2, 1, 1);
  BoneAttachments<> bones(m.V);
  IndexVector a(2), b(2);
  a << 0, 3;
  b << 5, 3;
  bones.add_bone("cranium", a);
  try {
    bones.add_bone("jaw", b);
    FAIL("expected MeshError");
  } catch (const MeshError& e) {
    CHECK(e.element() == 3);
    CHECK(std::string(e.what()).find("cranium") != std::string::npos);
    CHECK(std::string(e.what()).find("jaw") != std::string::npos);
  }
  CHECK(bones.num_bones() == 1);
  CHECK(bones.owner(5) == -1);  // the failed bone left nothing behind
  CHECK_THROWS_AS(bones.add_bone("cranium", IndexVector::Constant(1, 1)), ArgumentError);
  CHECK_THROWS_AS(bones.add_bone("", IndexVector::Constant(1, 1)), ArgumentError);
  CHECK_THROWS_AS(bones.add_bone("x", IndexVector::Constant(1, VIndex(m.num_vertices()))), ArgumentError);
  CHECK_THROWS_AS(bones.set_transform("nose", RigidTransform<>{}), ArgumentError);
  CHECK_THROWS_AS(bones.set_transform(7, RigidTransform<>{}), ArgumentError);
  RigidTransform<> nan;
  nan.t[0] = std::nan("");
  CHECK_THROWS_AS(bones.set_transform(0, nan), ArgumentError);
  Points<> V = m.V;
  V(1, 1) = std::nan("");
  CHECK_THROWS_AS(BoneAttachments<>{V}, ArgumentError);
}
