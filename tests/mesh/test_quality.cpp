#include <doctest/doctest.h>

#include <simsr/mesh/quality.hpp>

#include "fixtures.hpp"

namespace mesh_test_quality {

using namespace simsr;
using namespace simsr::test;

namespace {
/// Regular tet with unit edges, positively oriented.
Points<> regular_tet() {
  Points<> V(4, 3);
  V << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
  V /= std::sqrt(8.0);
  if (det_volume6(V, {0, 1, 2, 3}) < 0) V.row(2).swap(V.row(3));
  return V;
}
}  // namespace

TEST_CASE("element_quality of tets: 1 when regular under any similarity, → 0 when flattened, negative when inverted") {
  std::mt19937 rng(50);
  std::normal_distribution<double> n;
  Tets T(2, 4);
  T << 0, 1, 2, 3, 1, 0, 2, 3;
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3<> R = random_rotation(rng);
    const double s = std::exp(n(rng));
    const Points<> V = ((regular_tet() * R.transpose()) * s).rowwise() + Eigen::RowVector3d(n(rng), n(rng), n(rng));
    const VecX<> q = element_quality(exec::seq, V, T);
    CHECK(q[0] == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(q[1] == doctest::Approx(-1.0).epsilon(1e-12));
  }
  // Flatten: move the apex toward the base plane.
  Points<> V = regular_tet();
  const Vec3<> base = (V.row(0) + V.row(1) + V.row(2)).transpose() / 3;
  double prev = 1.0 + 1e-12;
  for (double t : {1.0, 0.5, 0.1, 1e-2, 1e-4, 1e-8}) {
    Points<> W = V;
    W.row(3) = (base + t * (V.row(3).transpose() - base)).transpose();
    const double q = element_quality(exec::seq, W, T)[0];
    CHECK(q < prev);
    CHECK(q > 0);
    prev = q;
  }
  CHECK(prev < 1e-4);
}

TEST_CASE("element_quality: random tets and triangles lie in (0, 1], similarity-invariant; seq == omp") {
  std::mt19937 rng(51);
  std::normal_distribution<double> n;
  Points<> V(4000, 3);
  for (Index i = 0; i < V.size(); ++i) V.data()[i] = n(rng);
  Tets T(1000, 4);
  Tris F(1000, 3);
  for (Index t = 0; t < 1000; ++t) {
    T.row(t) << 4 * t, 4 * t + 1, 4 * t + 2, 4 * t + 3;
    if (det_volume6(V, {T(t, 0), T(t, 1), T(t, 2), T(t, 3)}) < 0) std::swap(T(t, 2), T(t, 3));
    F.row(t) << 4 * t, 4 * t + 1, 4 * t + 2;
  }
  const VecX<> qt = element_quality(exec::seq, V, T), qf = element_quality(exec::seq, V, F);
  CHECK(qt.minCoeff() > 0);
  CHECK(qt.maxCoeff() <= 1 + 1e-12);
  CHECK(qf.minCoeff() >= 0);
  CHECK(qf.maxCoeff() <= 1 + 1e-12);
  const Mat3<> R = random_rotation(rng);
  const Points<> W = (V * R.transpose() * 3.7).rowwise() + Eigen::RowVector3d(1, 2, 3);
  CHECK((element_quality(exec::seq, W, T) - qt).cwiseAbs().maxCoeff() < 1e-9);
  CHECK((element_quality(exec::seq, W, F) - qf).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(element_quality(exec::omp, V, T) == qt);
  CHECK(element_quality(exec::omp, V, F) == qf);
  CHECK_THROWS_AS(element_quality(exec::seq, V, Edges(1, 2)), ShapeError);
}

TEST_CASE("element_quality of triangles: equilateral 1, collinear 0, right isosceles √3/2") {
  Points<> V(6, 3);
  V << 0, 0, 0, 1, 0, 0, 0.5, std::sqrt(3.0) / 2, 0, 0, 1, 0, 2, 0, 0, 7, 7, 7;
  Tris F(3, 3);
  F << 0, 1, 2, 0, 1, 3, 0, 1, 4;
  const VecX<> q = element_quality(exec::seq, V, F);
  CHECK(q[0] == doctest::Approx(1.0));
  CHECK(q[1] == doctest::Approx(std::sqrt(3.0) / 2));  // 4√3·½ / (1 + 1 + 2)
  CHECK(q[2] == doctest::Approx(0.0));
}

}  // namespace mesh_test_quality
