#include <doctest/doctest.h>

#include <simsr/mesh/volume.hpp>

#include "fixtures.hpp"

namespace mesh_test_volume {

using namespace simsr;
using namespace simsr::test;

TEST_CASE("signed_volumes: box tets have the analytic volumes and sum to the box") {
  std::mt19937 rng(10);
  for (int trial = 0; trial < 12; ++trial) {
    const int nx = 1 + int(rng() % 6), ny = 1 + int(rng() % 6), nz = 1 + int(rng() % 6);
    const double h = 0.05 + 0.01 * double(rng() % 50);
    const TetMesh<> six = box_tets(nx, ny, nz, h, Vec3<>(1, -2, 3), false);
    const VecX<> v6 = signed_volumes(exec::seq, six.V, six.T);
    for (Index t = 0; t < v6.size(); ++t) CHECK(v6[t] == doctest::Approx(h * h * h / 6).epsilon(1e-9));
    CHECK(total_volume(exec::seq, six.V, six.T) == doctest::Approx(nx * ny * nz * h * h * h).epsilon(1e-12));
    const TetMesh<> five = box_tets(nx, ny, nz, h, Vec3<>(1, -2, 3), true);
    const VecX<> v5 = signed_volumes(exec::seq, five.V, five.T);
    for (Index t = 0; t < v5.size(); ++t)  // 4 corner tets of h³/6, a central one of h³/3
      CHECK(v5[t] == doctest::Approx(t % 5 == 0 ? h * h * h / 3 : h * h * h / 6).epsilon(1e-9));
    CHECK(total_volume(exec::seq, five.V, five.T) == doctest::Approx(nx * ny * nz * h * h * h).epsilon(1e-12));
  }
}

TEST_CASE("signed_volumes: determinant truth, odd permutations negate, affine maps scale by det") {
  std::mt19937 rng(11);
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 200; ++trial) {
    Points<> V(4, 3);
    for (Index i = 0; i < V.size(); ++i) V.data()[i] = n(rng);
    Tets T(3, 4);
    T << 0, 1, 2, 3, 1, 0, 2, 3, 2, 3, 0, 1;  // identity, one swap, an even permutation
    const VecX<> vol = signed_volumes(exec::seq, V, T);
    const double truth = det_volume6(V, {0, 1, 2, 3}) / 6;
    CHECK(vol[0] == doctest::Approx(truth).epsilon(1e-10));
    CHECK(vol[1] == doctest::Approx(-truth).epsilon(1e-10));
    CHECK(vol[2] == doctest::Approx(truth).epsilon(1e-10));
    Mat3<> A;
    for (Index i = 0; i < 9; ++i) A.data()[i] = n(rng);
    const Points<> W = (V * A.transpose()).rowwise() + Eigen::RowVector3d(n(rng), n(rng), n(rng));
    CHECK(signed_volumes(exec::seq, W, T)[0] == doctest::Approx(A.determinant() * truth).epsilon(1e-9));
  }
}

TEST_CASE("signed_volumes and total_volume: seq and omp agree bitwise; float meshes work") {
  std::mt19937 rng(12);
  TetMesh<> m = box_tets(12, 10, 9);
  jitter(m.V, 0.2, rng);
  CHECK(signed_volumes(exec::seq, m.V, m.T) == signed_volumes(exec::omp, m.V, m.T));
  CHECK(total_volume(exec::seq, m.V, m.T) == total_volume(exec::omp, m.V, m.T));
  const Points<float> Vf = m.V.cast<float>();
  CHECK(double(total_volume(exec::omp, Vf, m.T)) == doctest::Approx(total_volume(exec::seq, m.V, m.T)).epsilon(1e-4));
  Eigen::MatrixXd Vd(m.V);  // dynamic-size inputs
  Eigen::MatrixXi Td = m.T.cast<int>();
  CHECK(total_volume(exec::seq, Vd, Td) == total_volume(exec::seq, m.V, m.T));
  CHECK_THROWS_AS(total_volume(exec::seq, Eigen::MatrixXd(4, 2), Td), ShapeError);
}

}  // namespace mesh_test_volume
