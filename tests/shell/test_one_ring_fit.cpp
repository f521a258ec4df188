#include <doctest/doctest.h>

#include <simsr/mesh/generators.hpp>
#include <simsr/shell/one_ring_fit.hpp>

#include <Eigen/QR>
#include <random>

#include "../support/error_of.hpp"

namespace shell_test_one_ring_fit {

using namespace simsr;
using namespace simsr::shell;

namespace {

/// Eq. 1 with the normal row, solved independently: the 9 entries of T from the stacked rows
/// √w (d − T e) and (σn − T σ⁰n⁰), by a dense QR.
Mat3<> brute_force_gradient(const OneRingFit<double>& fit, const Points<>& V, Index i) {
  const Adjacency& A = fit.adjacency();
  const Points<> N0 = vertex_normals(fit.rest(), fit.faces()), N = vertex_normals(V, fit.faces());
  const Index m = A.degree(i) + 1;
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(3 * m, 9);
  Eigen::VectorXd b(3 * m);
  double len0 = 0, len = 0;
  for (Index k = 0; k < A.degree(i); ++k) {
    const Index j = A[i][k];
    len0 += (fit.rest().row(i) - fit.rest().row(j)).norm();
    len += (V.row(i) - V.row(j)).norm();
  }
  const double scale = fit.options().normal_scale;
  auto put = [&](Index row, const Vec3<>& e, const Vec3<>& d, double w) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) M(3 * row + r, 3 * r + c) = std::sqrt(w) * e[c];  // (T e)_r = Σ_c T(r, c) e_c
      b[3 * row + r] = std::sqrt(w) * d[r];
    }
  };
  for (Index k = 0; k < A.degree(i); ++k) {
    const Index j = A[i][k];
    put(k, Vec3<>(fit.rest().row(i) - fit.rest().row(j)), Vec3<>(V.row(i) - V.row(j)), fit.weights()[A.offsets[i] + k]);
  }
  put(m - 1, Vec3<>(scale * len0 / double(A.degree(i)) * N0.row(i).transpose()),
      Vec3<>(scale * len / double(A.degree(i)) * N.row(i).transpose()), 1.0);
  const Eigen::VectorXd t = M.colPivHouseholderQr().solve(b);
  Mat3<> T;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) T(r, c) = t[3 * r + c];
  return T;
}

std::vector<TriMesh<>> test_meshes() {
  TriMesh<> bumpy = square_sheet(1.0, 6);
  for (Index v = 0; v < bumpy.V.rows(); ++v) bumpy.V(v, 2) = 0.1 * std::sin(5 * bumpy.V(v, 0)) * std::cos(3 * bumpy.V(v, 1));
  return {square_sheet(2.0, 8), disk_surface(1.0, 4), icosphere(2, 0.7), bumpy};
}

}  // namespace

TEST_CASE("OneRingFit: the rest state gives T = I, rigid motions and uniform scaling give T = λR exactly") {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  for (const TriMesh<>& m : test_meshes()) {
    for (const OneRingWeights w : {OneRingWeights::acap, OneRingWeights::uniform}) {
      const OneRingFit<double> fit(exec::seq, m.V, m.F, {w, 0.3});
      for (const Mat3<>& T : fit.gradients(exec::seq, m.V)) CHECK((T - Mat3<>::Identity()).norm() < 1e-12);
      for (int k = 0; k < 5; ++k) {
        const Mat3<> R = Eigen::AngleAxisd(3 * g(rng), Vec3<>(g(rng), g(rng), g(rng)).normalized()).toRotationMatrix();
        const double lambda = 0.5 + 0.3 * k;
        Points<> V = (lambda * m.V * R.transpose()).eval();
        V.rowwise() += Eigen::RowVector3d(g(rng), g(rng), g(rng));
        for (const Mat3<>& T : fit.gradients(exec::omp, V)) CHECK((T - lambda * R).norm() < 1e-11);
      }
    }
  }
}

TEST_CASE("OneRingFit: equals a dense least-squares solve of Eq. 1 (+ the normal row) on random deformations") {
  std::mt19937 rng(4);
  std::normal_distribution<double> g;
  for (const TriMesh<>& m : test_meshes()) {
    const OneRingFit<double> fit(exec::seq, m.V, m.F);
    Points<> V = m.V;
    for (Index v = 0; v < V.rows(); ++v) V.row(v) += 0.05 * Eigen::RowVector3d(g(rng), g(rng), g(rng));
    const std::vector<Mat3<>> T = fit.gradients(exec::seq, V), To = fit.gradients(exec::omp, V);
    for (Index i = 0; i < V.rows(); ++i) {
      CHECK((T[i] - brute_force_gradient(fit, V, i)).norm() < 1e-9 * (1 + T[i].norm()));
      CHECK(T[i] == To[i]);  // seq and omp bitwise equal
    }
  }
}

TEST_CASE("OneRingFit: an affine map of a flat sheet is reproduced on the sheet's plane") {
  const TriMesh<> m = square_sheet(1.0, 8);
  const OneRingFit<double> fit(exec::seq, m.V, m.F, {OneRingWeights::cotangent, 0.3});
  Mat3<> A;
  A << 1.3, 0.2, 0.0, -0.4, 0.8, 0.1, 0.3, 0.5, 1.0;
  const Points<> V = (m.V * A.transpose()).eval();
  for (const Mat3<>& T : fit.gradients(exec::seq, V)) {
    CHECK((T.col(0) - A.col(0)).norm() < 1e-12);
    CHECK((T.col(1) - A.col(1)).norm() < 1e-12);
  }
}

TEST_CASE("OneRingFit: bad input is a typed error naming what and where") {
  TriMesh<> m = square_sheet(1.0, 3);
  CHECK(!test::typed_error_of<ArgumentError>([&] { OneRingFit<double>(exec::seq, m.V, m.F, {OneRingWeights::acap, 0.0}); }).empty());
  Points<> extra(m.V.rows() + 1, 3);
  extra << m.V, Eigen::RowVector3d(5, 5, 5);
  const std::string lone = test::typed_error_of<MeshError>([&] { OneRingFit<double>(exec::seq, extra, m.F); });
  CHECK(lone.find("vertex 16") != std::string::npos);
  // an obtuse pair under the literal cotangent weights
  TriMesh<> obtuse;
  obtuse.V.resize(4, 3);
  obtuse.V << 0, 0, 0, 1, 0, 0, 0.5, 0.1, 0, 0.5, -0.1, 0;
  obtuse.F.resize(2, 3);
  obtuse.F << 0, 1, 2, 1, 0, 3;
  CHECK(test::typed_error_of<MeshError>([&] { OneRingFit<double>(exec::seq, obtuse.V, obtuse.F, {OneRingWeights::cotangent, 0.3}); })
            .find("obtuse") != std::string::npos);
  const OneRingFit<double> fit(exec::seq, m.V, m.F);
  CHECK(!test::typed_error_of<ShapeError>([&] { fit.gradients(exec::seq, Points<>(m.V.topRows(5))); }).empty());
  Points<> nan = m.V;
  nan(3, 1) = std::nan("");
  CHECK(!test::typed_error_of<ArgumentError>([&] { fit.gradients(exec::seq, nan); }).empty());
}

}  // namespace shell_test_one_ring_fit
