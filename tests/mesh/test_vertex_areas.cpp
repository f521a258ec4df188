#include <doctest/doctest.h>

#include <simsr/mesh/normals.hpp>
#include <simsr/mesh/vertex_areas.hpp>

#include "fixtures.hpp"

namespace mesh_test_vertex_areas {

using namespace simsr;
using namespace simsr::test;

namespace {
double polygon_area(const std::vector<Vec3<>>& p) {
  Vec3<> s = Vec3<>::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) s += p[i].cross(p[(i + 1) % p.size()]);
  return s.norm() / 2;
}
}  // namespace

TEST_CASE("voronoi_areas and barycentric_areas sum to the total area, are non-negative") {
  std::mt19937 rng(40);
  for (int trial = 0; trial < 20; ++trial) {
    TriMesh<> m = trial % 2 ? icosphere(1 + trial % 3, 1.0) : grid_surface(2 + trial % 5, rng);
    jitter(m.V, 0.25, rng);  // plenty of obtuse triangles
    const double total = face_areas(exec::seq, m.V, m.F).sum();
    const VecX<> vor = voronoi_areas(m.V, m.F), bar = barycentric_areas(m.V, m.F);
    CHECK(vor.sum() == doctest::Approx(total).epsilon(1e-12));
    CHECK(bar.sum() == doctest::Approx(total).epsilon(1e-12));
    CHECK(vor.minCoeff() >= 0);
    const Eigen::SparseMatrix<double> M = mass_matrix(m.V, m.F);
    CHECK(M.nonZeros() == m.V.rows());
    CHECK((Eigen::VectorXd(M.diagonal()) - vor).norm() == 0);
    CHECK((Eigen::VectorXd(mass_matrix(m.V, m.F, MassType::barycentric).diagonal()) - bar).norm() == 0);
  }
}

TEST_CASE("voronoi_areas of one triangle: circumcentre regions if acute, ½/¼/¼ if obtuse") {
  std::mt19937 rng(41);
  std::normal_distribution<double> n;
  int acute = 0, obtuse = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Points<> V(3, 3);
    for (Index i = 0; i < 9; ++i) V.data()[i] = n(rng);
    Tris F(1, 3);
    F << 0, 1, 2;
    const VecX<> A = voronoi_areas(V, F);
    const Vec3<> x[3] = {V.row(0), V.row(1), V.row(2)};
    const double area = (x[1] - x[0]).cross(x[2] - x[0]).norm() / 2;
    int obtuse_at = -1;
    for (int c = 0; c < 3; ++c)
      if ((x[(c + 1) % 3] - x[c]).dot(x[(c + 2) % 3] - x[c]) < 0) obtuse_at = c;
    if (obtuse_at < 0) {
      ++acute;
      // Circumcentre from the perpendicular-bisector formula.
      const Vec3<> a = x[1] - x[0], b = x[2] - x[0], axb = a.cross(b);
      const Vec3<> cc = x[0] + (b.squaredNorm() * axb.cross(a) + a.squaredNorm() * b.cross(axb)) / (2 * axb.squaredNorm());
      for (int c = 0; c < 3; ++c) {
        const Vec3<> m1 = (x[c] + x[(c + 1) % 3]) / 2, m2 = (x[c] + x[(c + 2) % 3]) / 2;
        CHECK(A[c] == doctest::Approx(polygon_area({x[c], m1, cc, m2})).epsilon(1e-8));
      }
    } else {
      ++obtuse;
      for (int c = 0; c < 3; ++c) CHECK(A[c] == doctest::Approx(area * (c == obtuse_at ? 0.5 : 0.25)));
    }
  }
  CHECK(acute > 20);
  CHECK(obtuse > 20);
}

TEST_CASE("voronoi_areas of a regular grid: interior vertices get one cell") {
  std::mt19937 rng(42);
  const TriMesh<> g = grid_surface(6, rng);  // right triangles: Voronoi = exact dual cells
  const VecX<> A = voronoi_areas(g.V, g.F);
  for (Index v = 0; v < g.V.rows(); ++v) {
    const double x = g.V(v, 0), y = g.V(v, 1);
    const double wx = (x == 0 || x == 6) ? 0.5 : 1.0, wy = (y == 0 || y == 6) ? 0.5 : 1.0;
    CHECK(A[v] == doctest::Approx(wx * wy));
  }
}

}  // namespace mesh_test_vertex_areas
