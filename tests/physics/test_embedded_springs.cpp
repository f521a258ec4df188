#include <simsr/mesh/generators.hpp>
#include <simsr/physics/forces/embedded_springs.hpp>

#include <doctest/doctest.h>

#include <vector>

#include <cmath>
#include <random>

#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;

namespace {

TetMesh<> unit_box() { return box_tet_mesh<double>(2, 2, 2); }

EmbeddedSprings<> random_springs(const TetMesh<>& m, std::mt19937& rng, Index q) {
  const Points<> P = test::random_points(q, 0.05, 0.95, rng);
  const Embedding<> e = embed(exec::seq, m, P);
  std::uniform_real_distribution<double> k(0.0, 100.0);
  VecX<> K(q);
  for (Index s = 0; s < q; ++s) K[s] = k(rng);
  return EmbeddedSprings<>(e, m.T, m.num_vertices(), K, test::random_points(q, -0.2, 1.2, rng));
}

}  // namespace

TEST_CASE("EmbeddedSprings: gradient and Hessian match finite differences; Hessian is PSD") {
  std::mt19937 rng(11);
  const TetMesh<> m = unit_box();
  double worst_g = 0, worst_h = 0, min_eig = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const EmbeddedSprings<> springs = random_springs(m, rng, 1 + trial % 7);
    const Points<> x = m.V + test::random_points(m.num_vertices(), -0.2, 0.2, rng);
    worst_g = std::max(worst_g, test::rel_error(test::gradient(springs, x), test::fd_gradient(springs, x, 1e-5)));
    const Eigen::MatrixXd H = test::assembled_hessian(springs, x);
    worst_h = std::max(worst_h, test::rel_error(H, test::fd_hessian(springs, x, 1e-5)));
    min_eig = std::min(min_eig, test::min_eigenvalue(H) / std::max(1.0, H.cwiseAbs().maxCoeff()));
  }
  MESSAGE("springs: worst gradient error " << worst_g << ", Hessian error " << worst_h << ", min eigenvalue " << min_eig);
  CHECK(worst_g < 1e-8);
  CHECK(worst_h < 1e-8);
  CHECK(min_eig > -1e-12);
}

TEST_CASE("EmbeddedSprings: force magnitude is k times the stretch") {
  const TetMesh<> m = unit_box();
  SUBCASE("vertex spring") {
    EmbeddedSprings<> s = vertex_springs(m.V, IndexVector::Constant(1, 13), 50.0);
    CHECK(s.energy(exec::seq, m.V) == 0.0);
    Points<> y = m.V.row(13);
    y(0, 1) += 0.03;
    s.set_targets(y);
    const Points<> g = test::gradient(s, m.V);
    CHECK(g.row(13).norm() == doctest::Approx(50.0 * 0.03).epsilon(1e-12));
    CHECK(g(13, 1) < 0);  // ∂E/∂x points away from the target: the force pulls towards it
    CHECK(g.norm() == doctest::Approx(g.row(13).norm()));
    CHECK(s.energy(exec::seq, m.V) == doctest::Approx(50.0 / 2 * 0.03 * 0.03));
  }
  SUBCASE("embedded point spring") {
    Points<> p(1, 3);
    p << 0.31, 0.47, 0.62;
    EmbeddedSprings<> s = point_springs(exec::seq, m, p, 20.0);
    CHECK(s.energy(exec::seq, m.V) == doctest::Approx(0.0).epsilon(1e-24));
    CHECK((s.points(m.V) - p).norm() < 1e-14);
    const Vec3<> u(0.01, -0.02, 0.005);
    Points<> x = m.V;
    x.rowwise() += u.transpose();
    const Points<> g = test::gradient(s, x);
    const Vec3<> total = g.colwise().sum().transpose();  // Σ_i w_i k r = k r (weights sum to 1)
    CHECK((total - 20.0 * u).norm() < 1e-12);
    CHECK(total.norm() == doctest::Approx(20.0 * u.norm()));
  }
}

TEST_CASE("track_springs: total stiffness is stiffness per area times surface area, alike on coarse and fine meshes") {
  const TetMesh<> box = box_tet_mesh<double>(4, 4, 4, Vec3<>::Constant(-1.3), Vec3<>::Constant(1.3));
  const double kappa = 1e3;
  const Vec3<> u(0.01, 0.02, -0.03);
  Points<> x = box.V;
  x.rowwise() += u.transpose();
  double total[2];
  const Index levels[2] = {2, 4};
  for (int i = 0; i < 2; ++i) {
    const TriMesh<> sphere = icosphere<double>(levels[i], 1.0);
    const Embedding<> e = embed(exec::seq, box, sphere.V);
    const EmbeddedSprings<> s = track_springs(exec::seq, e, box, sphere, kappa);
    CHECK(s.energy(exec::seq, box.V) < 1e-20);
    const double area = voronoi_areas(sphere.V, sphere.F).sum();
    total[i] = 2 * s.energy(exec::seq, x) / u.squaredNorm();  // uniform translation: every spring stretched by u
    CHECK(total[i] == doctest::Approx(kappa * area).epsilon(1e-12));
    CHECK(s.stiffness().sum() == doctest::Approx(kappa * area).epsilon(1e-12));
    const EmbeddedSprings<> b = track_springs(exec::seq, e, box, sphere, kappa, MassType::barycentric);
    CHECK(b.stiffness().sum() == doctest::Approx(kappa * area).epsilon(1e-12));
  }
  MESSAGE("track springs: total stiffness coarse " << total[0] << ", fine " << total[1] << ", κ·4π " << kappa * 4 * M_PI);
  CHECK(std::abs(total[0] - total[1]) / total[1] < 0.025);  // the level-2 polyhedron has 1.9% less area than the sphere
  CHECK(std::abs(total[1] - kappa * 4 * M_PI) / (kappa * 4 * M_PI) < 0.005);
}

TEST_CASE("EmbeddedSprings: bad input throws typed errors") {
  const TetMesh<> m = unit_box();
  Points<> p(2, 3);
  p << 0.2, 0.2, 0.2, 0.7, 0.6, 0.5;
  const Embedding<> e = embed(exec::seq, m, p);
  const VecX<> k = VecX<>::Constant(2, 1.0);
  CHECK_NOTHROW(EmbeddedSprings<>(e, m.T, m.num_vertices(), k, p));
  CHECK_THROWS_AS(EmbeddedSprings<>(e, m.T, m.num_vertices(), VecX<>::Constant(3, 1.0), p), ShapeError);
  CHECK_THROWS_AS(EmbeddedSprings<>(e, m.T, m.num_vertices(), VecX<>::Constant(2, -1.0), p), ArgumentError);
  VecX<> knan = k;
  knan[1] = std::nan("");
  CHECK_THROWS_AS(EmbeddedSprings<>(e, m.T, m.num_vertices(), knan, p), ArgumentError);
  CHECK_THROWS_AS(EmbeddedSprings<>(e, m.T, m.num_vertices(), k, Points<>(p.topRows(1))), ShapeError);
  Points<> pnan = p;
  pnan(1, 2) = std::nan("");
  CHECK_THROWS_AS(EmbeddedSprings<>(e, m.T, m.num_vertices(), k, pnan), ArgumentError);
  Embedding<> bad = e;
  bad.tet[1] = VIndex(m.num_tets());
  CHECK_THROWS_AS(EmbeddedSprings<>(bad, m.T, m.num_vertices(), k, p), ArgumentError);
  Tets T = m.T;
  T(e.tet[0], 2) = VIndex(m.num_vertices());
  CHECK_THROWS_AS(EmbeddedSprings<>(e, T, m.num_vertices(), k, p), MeshError);
  Embedding<> wnan = e;
  wnan.weights(0, 0) = std::nan("");
  CHECK_THROWS_AS(EmbeddedSprings<>(wnan, m.T, m.num_vertices(), k, p), ArgumentError);

  // springs on some rows of an embedding: the same anchors, weights and points as those rows
  {
    const EmbeddedSprings<> all(e, m.T, m.num_vertices(), k, p), second(e, m.T, m.num_vertices(), std::vector<Index>{1}, VecX<>::Ones(1), p.bottomRows(1));
    CHECK(second.num_springs() == 1);
    CHECK(second.anchors().row(0) == all.anchors().row(1));
    CHECK(second.weights().row(0) == all.weights().row(1));
    CHECK(second.points(m.V).row(0) == all.points(m.V).row(1));
    CHECK_THROWS_WITH_AS(EmbeddedSprings<>(e, m.T, m.num_vertices(), std::vector<Index>{2}, VecX<>::Ones(1), p.topRows(1)),
                         doctest::Contains("point 2 outside"), ArgumentError);
  }

  EmbeddedSprings<> s(e, m.T, m.num_vertices(), k, p);
  CHECK_THROWS_AS(s.set_targets(Points<>(3, 3)), ShapeError);
  CHECK_THROWS_AS(s.set_targets(pnan), ArgumentError);
  CHECK_THROWS_AS(s.energy(exec::seq, Points<>(m.V.topRows(5))), ShapeError);
  Points<> g = Points<>::Zero(5, 3);
  CHECK_THROWS_AS(s.add_gradient(exec::seq, m.V, g), ShapeError);
  CHECK_THROWS_AS(vertex_springs(m.V, IndexVector::Constant(1, -1), 1.0), ArgumentError);
  CHECK_THROWS_AS(vertex_springs(m.V, IndexVector::Constant(1, VIndex(m.num_vertices())), 1.0), ArgumentError);
  CHECK_THROWS_AS(vertex_springs(m.V, IndexVector::Constant(1, 0), -2.0), ArgumentError);
  CHECK_THROWS_AS(point_springs(exec::seq, m, p, std::nan("")), ArgumentError);
  CHECK_THROWS_AS(track_springs(exec::seq, e, m, VecX<>::Ones(3), 1.0), ShapeError);
  CHECK_THROWS_AS(track_springs(exec::seq, e, m, VecX<>::Ones(2), -1.0), ArgumentError);
}
