#include <simsr/physics/forces/embedded_obstacle_contact.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>

#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;

namespace {

using Contact = EmbeddedObstacleContact<Plane<>>;

/// Q points, each in 4 distinct random vertices of n with random positive barycentric weights.
std::pair<Contact::Anchors, Contact::Weights> random_embedded_points(Index q, Index n, std::mt19937& rng) {
  Contact::Anchors a(q, 4);
  Contact::Weights w(q, 4);
  std::vector<VIndex> ids(static_cast<std::size_t>(n));
  std::iota(ids.begin(), ids.end(), VIndex(0));
  std::uniform_real_distribution<double> u(0.05, 1.0);
  for (Index p = 0; p < q; ++p) {
    std::shuffle(ids.begin(), ids.end(), rng);
    double sum = 0;
    for (int i = 0; i < 4; ++i) {
      a(p, i) = ids[std::size_t(i)];
      w(p, i) = u(rng);
      sum += w(p, i);
    }
    w.row(p) /= sum;
  }
  return {a, w};
}

}  // namespace

TEST_CASE("EmbeddedObstacleContact: gradient and Hessian against finite differences (plane exact, sphere projected PSD)") {
  std::mt19937 rng(77);
  double worst_g = 0, worst_h_plane = 0, min_eig = 0;
  Index active = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const Index n = 14, q = 9;
    const Points<> x = test::random_points(n, -1, 1, rng);
    const auto [a, w] = random_embedded_points(q, n, rng);
    VecX<> k(q);
    for (Index p = 0; p < q; ++p) k[p] = std::uniform_real_distribution<double>(1, 100)(rng);
    const Vec3<> c = test::random_points(1, -0.3, 0.3, rng).row(0).transpose();
    const Vec3<> dir = test::random_points(1, -1, 1, rng).row(0).transpose();
    const EmbeddedObstacleContact plane(Plane<>(c, dir), a, w, n, k);
    const EmbeddedObstacleContact sphere(Sphere<>(c, 0.5), a, w, n, k);
    active += sphere.num_active(x) + plane.num_active(x);
    worst_g = std::max({worst_g, test::rel_error(test::gradient(plane, x), test::fd_gradient(plane, x, 1e-6)),
                        test::rel_error(test::gradient(sphere, x), test::fd_gradient(sphere, x, 1e-6))});
    const Eigen::MatrixXd Hp = test::assembled_hessian(plane, x), Hs = test::assembled_hessian(sphere, x);
    worst_h_plane = std::max(worst_h_plane, test::rel_error(Hp, test::fd_hessian(plane, x, 1e-6)));
    for (const Eigen::MatrixXd* H : {&Hp, &Hs}) min_eig = std::min(min_eig, test::min_eigenvalue(*H) / std::max(1.0, H->cwiseAbs().maxCoeff()));
  }
  MESSAGE("embedded obstacle contact: gradient " << worst_g << ", Hessian plane " << worst_h_plane << ", min eigenvalue " << min_eig << ", active " << active);
  CHECK(active > 40);
  CHECK(worst_g < 1e-7);
  CHECK(worst_h_plane < 1e-6);
  CHECK(min_eig > -1e-12);
}

TEST_CASE("EmbeddedObstacleContact: a point at one vertex is ObstacleContact on that vertex, exactly (with and without an onset)") {
  std::mt19937 rng(3);
  const Index n = 10;
  for (int trial = 0; trial < 40; ++trial) {
    const double onset = trial < 20 ? 0.0 : 0.3;
    const Points<> x = test::random_points(n, -1, 1, rng);
    IndexVector v(4);
    v << 0, 3, 5, 8;
    Contact::Anchors a(4, 4);
    Contact::Weights w = Contact::Weights::Zero(4, 4);
    for (Index p = 0; p < 4; ++p) {
      a.row(p) << v[p], (v[p] + 1) % n, (v[p] + 2) % n, (v[p] + 3) % n;
      w(p, 0) = 1;
    }
    const VecX<> k = VecX<>::LinSpaced(4, 5, 50);
    const Sphere<> s(test::random_points(1, -0.5, 0.5, rng).row(0).transpose(), 0.8);
    EmbeddedObstacleContact emb(s, a, w, n, k);
    ObstacleContact direct(s, v, n, k);
    emb.set_onset(onset);
    direct.set_onset(onset);
    CHECK(emb.onset() == onset);
    CHECK(emb.energy(exec::seq, x) == direct.energy(exec::seq, x));
    CHECK(test::gradient(emb, x) == test::gradient(direct, x));
    CHECK(test::assembled_hessian(emb, x) == test::assembled_hessian(direct, x));
  }
}

TEST_CASE("EmbeddedObstacleContact: from an embedding; bad input named") {
  // one tet, points embedded by hand: rows picked from the embedding
  Tets T(1, 4);
  T << 0, 1, 2, 3;
  Embedding<> e;
  e.tet = IndexVector::Zero(3);
  e.weights.resize(3, 4);
  e.weights << 1, 0, 0, 0, 0.25, 0.25, 0.25, 0.25, 0, 0, 0.5, 0.5;
  e.inside = Eigen::Array<bool, Eigen::Dynamic, 1>::Constant(3, true);
  e.distance = VecX<>::Zero(3);
  Points<> x(4, 3);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  const Plane<> floor(Vec3<>(0, 0, 0.3), Vec3<>(0, 0, 1));  // free above z = 0.3
  const Contact c(floor, e, T, 4, {1, 2}, VecX<>::Constant(2, 10.0));
  CHECK(c.num_points() == 2);
  const Points<> p = c.points(x);
  CHECK(p(0, 2) == doctest::Approx(0.25));
  CHECK(p(1, 2) == doctest::Approx(0.5));
  CHECK(c.num_active(x) == 1);                                          // the centroid, 0.05 below
  CHECK(c.energy(exec::seq, x) == doctest::Approx(5.0 * 0.05 * 0.05));  // k/2 d²

  // the whole embedding: rows 0, 1, 2 in order
  const Contact whole(floor, e, T, 4, VecX<>::Constant(3, 10.0)), rows(floor, e, T, 4, {0, 1, 2}, VecX<>::Constant(3, 10.0));
  CHECK(whole.points(x) == rows.points(x));
  CHECK(whole.energy(exec::seq, x) == rows.energy(exec::seq, x));

  CHECK_THROWS_AS(Contact(floor, e, T, 4, {3}, VecX<>::Ones(1)), ArgumentError);
  CHECK_THROWS_AS(Contact(floor, e, T, 4, {0}, VecX<>::Constant(1, -1.0)), ArgumentError);
  Contact::Anchors a(1, 4);
  a << 0, 1, 2, 9;
  CHECK_THROWS_AS(Contact(floor, a, Contact::Weights::Constant(1, 4, 0.25), 4, VecX<>::Ones(1)), ArgumentError);
  a << 0, 1, 2, 3;
  Contact::Weights bad = Contact::Weights::Constant(1, 4, 0.25);
  bad(0, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(Contact(floor, a, bad, 4, VecX<>::Ones(1)), ArgumentError);
  CHECK_THROWS(Contact(floor, a, Contact::Weights::Constant(1, 4, 0.25), 4, VecX<>::Ones(2)));
}
