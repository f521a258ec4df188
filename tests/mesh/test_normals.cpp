#include <doctest/doctest.h>

#include <simsr/mesh/normals.hpp>

#include "fixtures.hpp"

namespace mesh_test_normals {

using namespace simsr;
using namespace simsr::test;

TEST_CASE("face_areas: Heron's formula; face_normals: unit, orthogonal to edges, right-handed") {
  std::mt19937 rng(20);
  std::normal_distribution<double> n;
  Points<> V(3 * 300, 3);
  for (Index i = 0; i < V.size(); ++i) V.data()[i] = n(rng);
  Tris F(300, 3);
  for (Index f = 0; f < F.rows(); ++f) F.row(f) << 3 * f, 3 * f + 1, 3 * f + 2;
  const VecX<> A = face_areas(exec::seq, V, F);
  const Points<> N = face_normals(exec::seq, V, F);
  for (Index f = 0; f < F.rows(); ++f) {
    const Vec3<> a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const double x = (b - a).norm(), y = (c - b).norm(), z = (a - c).norm(), s = (x + y + z) / 2;
    CHECK(A[f] == doctest::Approx(std::sqrt(s * (s - x) * (s - y) * (s - z))).epsilon(1e-8));
    const Vec3<> nf = N.row(f);
    CHECK(nf.norm() == doctest::Approx(1.0));
    CHECK(std::abs(nf.dot(b - a)) < 1e-12 * (1 + (b - a).norm()));
    CHECK(std::abs(nf.dot(c - a)) < 1e-12 * (1 + (c - a).norm()));
    Mat3<> M;
    M << (b - a), (c - a), nf;
    CHECK(M.determinant() > 0);
  }
  Tris flat(1, 3);
  flat << 0, 0, 1;
  CHECK(face_normals(exec::seq, V, flat).row(0).norm() == 0);
  CHECK(face_areas(exec::omp, V, F) == A);
  CHECK(face_normals(exec::omp, V, F) == N);
}

TEST_CASE("icosphere: total area → 4πr², vertex normals → radial under every weighting") {
  const double r = 2.5;
  double prev_err = 0;
  for (int level = 1; level <= 4; ++level) {
    const TriMesh<> s = icosphere(level, r);
    const double area = face_areas(exec::seq, s.V, s.F).sum();
    CHECK(area < 4 * M_PI * r * r);  // inscribed polyhedron
    if (level == 4) CHECK(area == doctest::Approx(4 * M_PI * r * r).epsilon(5e-3));
    const Points<> fn = face_normals(exec::seq, s.V, s.F);
    for (Index f = 0; f < s.F.rows(); ++f) {  // outward: the normal points away from the centre
      CHECK(fn.row(f).dot(s.V.row(s.F(f, 0))) > 0);
    }
    double worst = 0;
    for (auto w : {NormalWeighting::uniform, NormalWeighting::area, NormalWeighting::angle}) {
      const Points<> N = vertex_normals(s.V, s.F, w);
      for (Index v = 0; v < s.V.rows(); ++v) {
        const Vec3<> radial = s.V.row(v).normalized();
        CHECK(N.row(v).norm() == doctest::Approx(1.0));
        worst = std::max(worst, (N.row(v).transpose() - radial).norm());
      }
    }
    if (level == 1) CHECK(worst < 1e-12);  // all vertices equivalent by symmetry: exactly radial
    if (level >= 3) CHECK(worst < prev_err);
    prev_err = worst;
  }
  CHECK(prev_err < 1e-2);
}

TEST_CASE("vertex_normals: flat grid gives +z; an isolated vertex gets zero; weightings differ where they should") {
  std::mt19937 rng(21);
  TriMesh<> g = grid_surface(5, rng);
  g.V.conservativeResize(g.V.rows() + 1, 3);
  g.V.row(g.V.rows() - 1) << 9, 9, 9;
  for (auto w : {NormalWeighting::uniform, NormalWeighting::area, NormalWeighting::angle}) {
    const Points<> N = vertex_normals(g.V, g.F, w);
    for (Index v = 0; v + 1 < N.rows(); ++v) CHECK((N.row(v) - Eigen::RowVector3d(0, 0, 1)).norm() < 1e-12);
    CHECK(N.row(N.rows() - 1).norm() == 0);
  }
  // Corner of a cube (three unit squares as six triangles): angle weighting gives −(1,1,1)/√3
  // however the squares are split; uniform weighting does not.
  Points<> V(7, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 0, 0, 1, 1, 1, 0, 1;
  Tris F(6, 3);  // squares z=0, x=0 split through vertex 0, square y=0 split by the other diagonal; normals −z, −x, −y
  F << 0, 2, 4, 0, 4, 1, 0, 3, 5, 0, 5, 2, 0, 1, 3, 1, 6, 3;
  Points<> Nangle = vertex_normals(V, F, NormalWeighting::angle);
  const Eigen::RowVector3d expect = -Eigen::RowVector3d(1, 1, 1).normalized();
  CHECK((Nangle.row(0) - expect).norm() < 1e-12);
  const Points<> Nuni = vertex_normals(V, F, NormalWeighting::uniform);
  CHECK((Nuni.row(0) - expect).norm() > 1e-3);  // (z,x) square contributes only one triangle at vertex 0
}

}  // namespace mesh_test_normals
