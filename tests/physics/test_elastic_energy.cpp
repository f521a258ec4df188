#include <simsr/mesh/generators.hpp>
#include <simsr/physics/elastic_energy.hpp>

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <random>

#include "stvk_material.hpp"

using namespace simsr;
using namespace simsr::physics;

namespace {

Points<> perturbed(const Points<>& V, double amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  Points<> x = V;
  for (Index i = 0; i < x.size(); ++i) x.data()[i] += u(rng);
  return x;
}

Eigen::MatrixXd dense(const BlockTriplets<>& h, Index n) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (Index k = 0; k < h.size(); ++k) H.block<3, 3>(3 * h.row(k), 3 * h.col(k)) += h.block(k);
  return H;
}

}  // namespace

TEST_CASE("tet_rest_data: volumes and Dm⁻¹; flat and inverted rest tets are MeshErrors naming the tet") {
  const auto mesh = box_tet_mesh<double>(2, 1, 1, Vec3<>(0, 0, 0), Vec3<>(2, 1, 1));
  const auto rest = tet_rest_data(mesh.V, mesh.T);
  CHECK(rest.volume.sum() == doctest::Approx(2.0));
  for (Index t = 0; t < mesh.num_tets(); ++t)  // F(rest) = I
    CHECK((deformation_gradient(mesh.V, mesh.T, t, rest.Dm_inv[std::size_t(t)]) - Mat3<>::Identity()).norm() < 1e-14);
  auto bad = mesh;
  std::swap(bad.T(3, 1), bad.T(3, 2));
  CHECK_THROWS_WITH_AS(tet_rest_data(bad.V, bad.T), doctest::Contains("tet 3: inverted"), MeshError);
  bad = mesh;
  bad.V.row(bad.T(5, 3)) = bad.V.row(bad.T(5, 0));
  CHECK_THROWS_AS(tet_rest_data(bad.V, bad.T), MeshError);
  bad = mesh;
  bad.T(2, 0) = 99;
  CHECK_THROWS_WITH_AS(tet_rest_data(bad.V, bad.T), doctest::Contains("out of range"), MeshError);
}

TEST_CASE("ElasticEnergy: gradient is the finite difference of the energy, Hessian that of the gradient") {
  const auto mesh = box_tet_mesh<double>(2, 2, 1, Vec3<>(0, 0, 0), Vec3<>(1, 1, 0.5));
  simsr_test::StVK m{1.3, 0.7};
  ElasticEnergy<simsr_test::StVK> E(mesh, m);
  const Index n = mesh.num_vertices();
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Points<> x = perturbed(mesh.V, 0.15, seed);
    Points<> g = Points<>::Zero(n, 3);
    E.add_gradient(x, g);
    const double h = 1e-6;
    double worst = 0;
    for (Index i = 0; i < 3 * n; ++i) {
      Points<> xp = x, xm = x;
      xp.data()[i] += h;
      xm.data()[i] -= h;
      const double fd = (E.energy(xp) - E.energy(xm)) / (2 * h);
      worst = std::max(worst, std::abs(fd - g.data()[i]));
    }
    CHECK(worst < 1e-7 * std::max(1.0, g.cwiseAbs().maxCoeff()));

    BlockTriplets<> trip;
    E.add_hessian(x, trip);
    const Eigen::MatrixXd H = dense(trip, n);
    double worst_h = 0;
    for (Index i = 0; i < 3 * n; ++i) {
      Points<> xp = x, xm = x, gp = Points<>::Zero(n, 3), gm = Points<>::Zero(n, 3);
      xp.data()[i] += h;
      xm.data()[i] -= h;
      E.add_gradient(xp, gp);
      E.add_gradient(xm, gm);
      const Eigen::VectorXd col = (Eigen::Map<Eigen::VectorXd>(gp.data(), 3 * n) - Eigen::Map<Eigen::VectorXd>(gm.data(), 3 * n)) / (2 * h);
      // Points is vertex-major (row-major #V×3): data index i = 3v + c, the Hessian's DOF order.
      worst_h = std::max(worst_h, (col - H.col(i)).cwiseAbs().maxCoeff());
    }
    CHECK(worst_h < 1e-6 * std::max(1.0, H.cwiseAbs().maxCoeff()));
    CHECK((H - H.transpose()).cwiseAbs().maxCoeff() < 1e-12 * H.cwiseAbs().maxCoeff());
  }
}

TEST_CASE("ElasticEnergy: the fast BlockHessian path equals the triplet path; seq and omp agree bitwise") {
  const auto mesh = box_tet_mesh<double>(3, 2, 2);
  const Points<> x = perturbed(mesh.V, 0.1, 7);
  ElasticEnergy<simsr_test::StVK> seq(mesh, {});
  ElasticEnergy<simsr_test::StVK, exec::omp_t> omp(mesh, {});
  BlockTriplets<> trip;
  seq.add_hessian(x, trip);
  BlockHessian<> ref(mesh.num_vertices(), mesh.T);
  ref.set_zero();
  ref.add(trip);
  BlockHessian<> fast(mesh.num_vertices(), mesh.T), fast_omp(mesh.num_vertices(), mesh.T);
  fast.set_zero();
  seq.add_hessian(x, fast);
  fast_omp.set_zero();
  omp.add_hessian(x, fast_omp);
  std::vector<char> free(std::size_t(3 * mesh.num_vertices()), 0);
  const Eigen::MatrixXd A = Eigen::MatrixXd(ref.assemble(exec::seq, free));
  const Eigen::MatrixXd B = Eigen::MatrixXd(fast.assemble(exec::seq, free));
  const Eigen::MatrixXd C = Eigen::MatrixXd(fast_omp.assemble(exec::omp, free));
  CHECK((A - B).cwiseAbs().maxCoeff() < 1e-12 * A.cwiseAbs().maxCoeff());
  CHECK((B - C).cwiseAbs().maxCoeff() == 0.0);
  Points<> g1 = Points<>::Zero(mesh.num_vertices(), 3), g2 = g1;
  seq.add_gradient(x, g1);
  omp.add_gradient(x, g2);
  CHECK((g1 - g2).cwiseAbs().maxCoeff() == 0.0);
  CHECK(seq.energy(x) == omp.energy(x));
}

TEST_CASE("BlockHessian: blocks outside the pattern grow it, keep every value and change the version") {
  const auto mesh = box_tet_mesh<double>(2, 1, 1);
  BlockHessian<> H(mesh.num_vertices(), mesh.T);
  const auto v0 = H.pattern_version();
  const VIndex far_a = 0, far_b = VIndex(mesh.num_vertices() - 1);
  REQUIRE(H.slot(far_a, far_b) < 0);
  H.set_zero();
  H.add(0, 0, Mat3<>::Identity());
  Mat3<> b = Mat3<>::Constant(2.0);
  H.add(far_a, far_b, b);
  H.add(far_b, far_a, b);
  std::vector<char> free(std::size_t(3 * mesh.num_vertices()), 0);
  const Eigen::MatrixXd A = Eigen::MatrixXd(H.assemble(exec::seq, free));
  CHECK(H.pattern_version() != v0);
  CHECK(A(0, 0) == 1.0);
  CHECK(A(3 * far_a + 1, 3 * far_b + 2) == 2.0);
  CHECK(A(3 * far_b, 3 * far_a) == 2.0);
  CHECK_THROWS_AS(H.add(0, VIndex(mesh.num_vertices()), b), ShapeError);
  // fixed DOFs: identity row and column
  free[4] = 1;
  H.set_zero();
  H.add(1, 1, Mat3<>::Constant(5.0));
  const Eigen::MatrixXd F = Eigen::MatrixXd(H.assemble(exec::seq, free));
  CHECK(F(4, 4) == 1.0);
  CHECK(F(3, 4) == 0.0);
  CHECK(F(4, 5) == 0.0);
  CHECK(F(3, 5) == 5.0);
}

TEST_CASE("ElasticEnergy: element data count is checked") {
  const auto mesh = box_tet_mesh<double>(1, 1, 1);
  CHECK_THROWS_AS(ElasticEnergy<simsr_test::StVK>(mesh, {}, std::vector<NoElementData>(3)), ShapeError);
  ElasticEnergy<simsr_test::StVK> E(mesh, {});
  CHECK_THROWS_AS(E.energy(Points<>::Zero(3, 3)), ShapeError);
}
