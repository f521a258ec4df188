// VertexTargets (SoftDECA's E_tar and E_dist2): finite differences of energy and gradient at
// random configurations inside and outside the spheres, the projection, and bad input.
#include <simsr/physics/forces/vertex_targets.hpp>

#include <doctest/doctest.h>

#include <random>

#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;
using namespace simsr::test;

namespace test_vertex_targets {

VertexTargets<> random_term(std::mt19937& rng, Index n, Index k, double dmax) {
  std::uniform_int_distribution<int> pick(0, int(n) - 1);
  std::uniform_real_distribution<double> d(0, dmax), w(0.1, 3);
  IndexVector v(k);
  VecX<> dist(k), weight(k);
  for (Index i = 0; i < k; ++i) {
    v[i] = pick(rng);  // repeats allowed: a vertex may have several targets
    dist[i] = d(rng);
    weight[i] = w(rng);
  }
  return VertexTargets<>(n, v, random_points(k, -1, 1, rng), dist, weight);
}

}  // namespace test_vertex_targets

TEST_CASE("VertexTargets: gradient and Hessian match finite differences (E_dist2 and E_tar), projected Hessian PSD") {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 20; ++trial) {
    const double dmax = trial % 2 ? 0.0 : 0.8;  // odd trials: E_tar (every distance 0)
    const auto term = test_vertex_targets::random_term(rng, 12, 9, dmax);
    const Points<> x = random_points(12, -1, 1, rng);
    CHECK(rel_error(gradient(term, x), fd_gradient(term, x, 1e-6)) < 1e-7);
    CHECK(rel_error(assembled_hessian(term, x, Definiteness::exact), fd_hessian(term, x, 1e-6)) < 1e-6);
    CHECK(min_eigenvalue(assembled_hessian(term, x, Definiteness::project)) > -1e-12);
    CHECK(term.energy(exec::omp, x) == doctest::Approx(term.energy(exec::seq, x)).epsilon(1e-14));
  }
}

TEST_CASE("VertexTargets: E = sum w (|x - s| - d)^2; project() is the nearest point of the sphere") {
  std::mt19937 rng(2);
  const auto term = test_vertex_targets::random_term(rng, 6, 6, 0.5);
  const Points<> x = random_points(6, -1, 1, rng);
  double e = 0;
  for (Index k = 0; k < term.size(); ++k) {
    const Vec3<> r = x.row(term.vertices()[k]) - term.targets().row(k);
    e += term.weights()[k] * std::pow(r.norm() - term.distances()[k], 2);
    const Vec3<> p = term.project(x, k);
    CHECK((p - term.targets().row(k).transpose()).norm() == doctest::Approx(term.distances()[k]).epsilon(1e-12));
    // the energy is w ‖x − p‖², and no point of the sphere is nearer
    CHECK(std::pow(r.norm() - term.distances()[k], 2) == doctest::Approx((x.row(term.vertices()[k]).transpose() - p).squaredNorm()).epsilon(1e-10));
    for (int s = 0; s < 200; ++s) {
      const Vec3<> q = term.targets().row(k).transpose() + term.distances()[k] * random_points(1, -1, 1, rng).row(0).transpose().normalized();
      CHECK((x.row(term.vertices()[k]).transpose() - q).norm() >= (x.row(term.vertices()[k]).transpose() - p).norm() - 1e-12);
    }
  }
  CHECK(term.energy(exec::seq, x) == doctest::Approx(e).epsilon(1e-12));
  // E_tar: attraction() is the d = 0 case, ‖x − s‖² w
  const auto tar = VertexTargets<>::attraction(6, term.vertices(), term.targets(), term.weights());
  double et = 0;
  for (Index k = 0; k < tar.size(); ++k) et += tar.weights()[k] * (x.row(tar.vertices()[k]) - tar.targets().row(k)).squaredNorm();
  CHECK(tar.energy(exec::seq, x) == doctest::Approx(et).epsilon(1e-12));
}

TEST_CASE("VertexTargets: bad input is named") {
  const IndexVector v = (IndexVector(2) << 0, 5).finished();
  const Points<> s = Points<>::Zero(2, 3);
  CHECK_THROWS_WITH_AS(VertexTargets<>(5, v, s, VecX<>::Zero(2), VecX<>::Ones(2)), doctest::Contains("not a vertex"), ArgumentError);
  const IndexVector ok = (IndexVector(2) << 0, 4).finished();
  CHECK_THROWS_AS(VertexTargets<>(5, ok, Points<>::Zero(3, 3), VecX<>::Zero(2), VecX<>::Ones(2)), ShapeError);
  CHECK_THROWS_WITH_AS(VertexTargets<>(5, ok, s, (VecX<>(2) << 0, -1).finished(), VecX<>::Ones(2)), doctest::Contains("distances[1]"), ArgumentError);
  Points<> bad = s;
  bad(1, 2) = std::nan("");
  CHECK_THROWS_WITH_AS(VertexTargets<>(5, ok, bad, VecX<>::Zero(2), VecX<>::Ones(2)), doctest::Contains("row 1"), ArgumentError);
  CHECK_THROWS_AS(VertexTargets<>(5, ok, s, VecX<>::Zero(2), (VecX<>(2) << 1, std::nan("")).finished()), ArgumentError);
  const VertexTargets<> term(5, ok, s, VecX<>::Zero(2), VecX<>::Ones(2));
  CHECK_THROWS_AS(term.energy(exec::seq, Points<>::Zero(4, 3)), ShapeError);
}
