#include <doctest/doctest.h>

#include <simsr/mesh/cotangent_laplacian.hpp>
#include <simsr/mesh/normals.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/vertex_areas.hpp>

#include <Eigen/Eigenvalues>

#include "fixtures.hpp"

namespace mesh_test_cotangent_laplacian {

using namespace simsr;
using namespace simsr::test;

namespace {

/// Random test surfaces: jittered spheres (closed, many obtuse triangles) and bumpy open grids.
std::vector<TriMesh<>> random_surfaces(std::mt19937& rng) {
  std::vector<TriMesh<>> out;
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 4; ++i) {
    TriMesh<> s = icosphere(1 + i % 2, 0.5 + i);
    for (Index v = 0; v < s.V.rows(); ++v) s.V.row(v) *= 1 + 0.2 * u(rng);
    jitter(s.V, 0.05 * (0.5 + i), rng);
    out.push_back(s);
    TriMesh<> g = grid_surface(3 + i, rng);
    jitter(g.V, 0.3, rng);
    out.push_back(g);
  }
  return out;
}

}  // namespace

TEST_CASE("cotangent_laplacian: symmetric, annihilates constants, negative semi-definite, seq == omp") {
  std::mt19937 rng(30);
  for (const auto& m : random_surfaces(rng)) {
    const Eigen::SparseMatrix<double> L = cotangent_laplacian(exec::seq, m.V, m.F);
    REQUIRE(L.rows() == m.V.rows());
    const Eigen::MatrixXd D(L);
    CHECK((D - D.transpose()).cwiseAbs().maxCoeff() <= 1e-14 * D.cwiseAbs().maxCoeff());
    CHECK((D * Eigen::VectorXd::Ones(D.rows())).cwiseAbs().maxCoeff() <= 1e-12 * D.cwiseAbs().maxCoeff());
    const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(D).eigenvalues();
    CHECK(lambda.maxCoeff() <= 1e-10 * D.cwiseAbs().maxCoeff());
    // Off-diagonals only on mesh edges.
    const Edges E = unique_edges(m.F);
    Eigen::MatrixXi pattern = Eigen::MatrixXi::Identity(D.rows(), D.rows());
    for (Index e = 0; e < E.rows(); ++e) pattern(E(e, 0), E(e, 1)) = pattern(E(e, 1), E(e, 0)) = 1;
    for (Index i = 0; i < D.rows(); ++i)
      for (Index j = 0; j < D.cols(); ++j)
        if (!pattern(i, j)) CHECK(D(i, j) == 0);
    const Eigen::SparseMatrix<double> Lo = cotangent_laplacian(exec::omp, m.V, m.F);
    CHECK(Eigen::MatrixXd(Lo) == D);
  }
}

TEST_CASE("cotangent_laplacian: L·V = −∇(total area), checked by central differences") {
  std::mt19937 rng(31);
  for (const auto& m : random_surfaces(rng)) {
    const Eigen::SparseMatrix<double> L = cotangent_laplacian(exec::seq, m.V, m.F);
    const Eigen::MatrixXd LV = L * Eigen::MatrixXd(m.V);
    Points<> X = m.V;
    const double h = 1e-6;
    double worst = 0, scale = LV.cwiseAbs().maxCoeff();
    for (Index v = 0; v < X.rows(); ++v)
      for (int d = 0; d < 3; ++d) {
        const double x0 = X(v, d);
        X(v, d) = x0 + h;
        const double ap = face_areas(exec::seq, X, m.F).sum();
        X(v, d) = x0 - h;
        const double am = face_areas(exec::seq, X, m.F).sum();
        X(v, d) = x0;
        worst = std::max(worst, std::abs(LV(v, d) + (ap - am) / (2 * h)));
      }
    CHECK(worst <= 1e-6 * std::max(1.0, scale));
  }
}

TEST_CASE("cotangent_laplacian: exact on linear functions at interior vertices of a planar mesh") {
  std::mt19937 rng(32);
  for (int n = 3; n <= 7; ++n) {
    TriMesh<> g = grid_surface(n, rng);
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    for (Index v = 0; v < g.V.rows(); ++v) g.V(v, 0) += u(rng), g.V(v, 1) += u(rng);  // stays planar and valid
    const Eigen::SparseMatrix<double> L = cotangent_laplacian(exec::seq, g.V, g.F);
    const Eigen::VectorXd f = 0.7 * g.V.col(0) - 1.3 * g.V.col(1) + Eigen::VectorXd::Constant(g.V.rows(), 2.0);
    const Eigen::VectorXd Lf = L * f;
    const Edges B = boundary_edges(g.F);
    std::vector<char> on_boundary(static_cast<std::size_t>(g.V.rows()), 0);
    for (Index e = 0; e < B.rows(); ++e) on_boundary[B(e, 0)] = on_boundary[B(e, 1)] = 1;
    for (Index v = 0; v < g.V.rows(); ++v)
      if (!on_boundary[v]) CHECK(std::abs(Lf[v]) < 1e-12);
  }
}

TEST_CASE("cotangent_laplacian with Voronoi areas: mean curvature normal of a sphere is 2/r·n") {
  const double r = 1.7;
  const TriMesh<> s = icosphere(4, r);
  const Eigen::MatrixXd LV = cotangent_laplacian(exec::seq, s.V, s.F) * Eigen::MatrixXd(s.V);
  const VecX<> A = voronoi_areas(s.V, s.F);
  for (Index v = 0; v < s.V.rows(); ++v) {
    const Eigen::RowVector3d Hn = -LV.row(v) / A[v];
    CHECK((Hn - (2 / r) * s.V.row(v).normalized()).norm() < 0.02 * (2 / r));
  }
}

TEST_CASE("cotangent_weights of an equilateral and a right triangle") {
  Points<> V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 0.5, std::sqrt(3.0) / 2, 0, 0, 1, 0;
  Tris F(2, 3);
  F << 0, 1, 2, 0, 1, 3;
  const Points<> C = cotangent_weights(exec::seq, V, F);
  for (int c = 0; c < 3; ++c) CHECK(C(0, c) == doctest::Approx(0.5 / std::sqrt(3.0)));
  CHECK(C(1, 0) == doctest::Approx(0.0));  // right angle at vertex 0
  CHECK(C(1, 1) == doctest::Approx(0.5));  // 45°
  CHECK(C(1, 2) == doctest::Approx(0.5));
}

}  // namespace mesh_test_cotangent_laplacian
