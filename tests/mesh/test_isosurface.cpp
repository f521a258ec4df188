#include <doctest/doctest.h>

#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/isosurface.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/volume.hpp>

#include <cmath>
#include <numbers>
#include <random>

namespace mesh_test_isosurface {

using namespace simsr;

namespace {

/// Enclosed volume of a closed, outward-oriented triangle mesh (tets from the origin).
double enclosed_volume(const TriMesh<>& m) {
  double v6 = 0;
  for (Index f = 0; f < m.F.rows(); ++f)
    v6 += m.V.row(m.F(f, 0)).dot(m.V.row(m.F(f, 1)).cross(m.V.row(m.F(f, 2))));
  return v6 / 6;
}

/// Every undirected edge in exactly two triangles, once in each direction.
bool closed_and_consistent(const Tris& F) {
  std::vector<std::pair<std::pair<VIndex, VIndex>, int>> half;
  for (Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const VIndex a = F(f, c), b = F(f, (c + 1) % 3);
      half.push_back({{std::min(a, b), std::max(a, b)}, a < b ? 1 : -1});
    }
  std::sort(half.begin(), half.end());
  for (std::size_t i = 0; i < half.size(); i += 2)
    if (i + 1 >= half.size() || half[i].first != half[i + 1].first || half[i].second + half[i + 1].second != 0 ||
        (i + 2 < half.size() && half[i + 2].first == half[i].first))
      return false;
  return true;
}

}  // namespace

TEST_CASE("marching_tets: spheres of random centre and radius come out closed, consistently outward, on the sphere") {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (int trial = 0; trial < 12; ++trial) {
    const Index n = 8 + Index(rng() % 12);
    const TetMesh<> box = box_tet_mesh<double>(n, n, n, Vec3<>(-1, -1, -1), Vec3<>(1, 1, 1));
    const double h = 2.0 / double(n);
    const Vec3<> c(u(rng), u(rng), u(rng));
    const double r = 0.4 + 3 * std::abs(u(rng));
    VecX<> phi(box.V.rows());
    for (Index v = 0; v < phi.size(); ++v) phi[v] = r - (box.V.row(v).transpose() - c).norm();  // > 0 inside
    const IsosurfaceOptions opt{.snap = 0.1};
    const TriMesh<> s = marching_tets(exec::seq, box, phi, 0.0, opt);
    CAPTURE(n);
    CAPTURE(r);
    REQUIRE(s.F.rows() > 0);
    CHECK(closed_and_consistent(s.F));
    CHECK(s.V.rows() - unique_edges(s.F).rows() + s.F.rows() == 2);  // a sphere
    // on the sphere up to the snap (≤ 0.1 of an edge ≤ h√3) and the chord error of linear interpolation
    double worst = 0;
    for (Index v = 0; v < s.V.rows(); ++v) worst = std::max(worst, std::abs((s.V.row(v).transpose() - c).norm() - r));
    CHECK(worst < 0.1 * std::sqrt(3.0) * h + h * h / r);
    const double vol = enclosed_volume(s);
    CHECK(vol > 0);  // outward
    CHECK(vol == doctest::Approx(4.0 / 3.0 * std::numbers::pi * r * r * r).epsilon(0.15));
    // no triangle is a sliver of nearly coincident points: the snap keeps crossings off the vertices
    double shortest = 1e300;
    for (Index f = 0; f < s.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) shortest = std::min(shortest, (s.V.row(s.F(f, k)) - s.V.row(s.F(f, (k + 1) % 3))).norm());
    CHECK(shortest > 1e-3 * h);
    const TriMesh<> s_omp = marching_tets(exec::omp, box, phi, 0.0, opt);
    CHECK(s_omp.V == s.V);
    CHECK(s_omp.F == s.F);
  }
}

TEST_CASE("marching_tets: a linear field gives its plane exactly; a region touching the mesh boundary stays open there") {
  const TetMesh<> box = box_tet_mesh<double>(5, 4, 3, Vec3<>(0, 0, 0), Vec3<>(1, 1, 1));
  VecX<> phi(box.V.rows());
  const Vec3<> g(0.3, -0.5, 0.8);
  for (Index v = 0; v < phi.size(); ++v) phi[v] = box.V.row(v).dot(g) - 0.2;
  const TriMesh<> s = marching_tets(exec::seq, box, phi, 0.123, {.snap = 0.0});
  for (Index v = 0; v < s.V.rows(); ++v) CHECK(s.V.row(v).dot(g) - 0.2 == doctest::Approx(0.123).epsilon(1e-12));
  for (Index f = 0; f < s.F.rows(); ++f) {  // normals point out of {φ > iso}: against g
    const Vec3<> nrm = (s.V.row(s.F(f, 1)) - s.V.row(s.F(f, 0))).cross(s.V.row(s.F(f, 2)) - s.V.row(s.F(f, 0))).transpose();
    CHECK(nrm.dot(g) < 0);
  }
  CHECK(boundary_edges(s.F).rows() > 0);  // the plane leaves the box
}

TEST_CASE("marching_tets: bad input is named") {
  const TetMesh<> box = box_tet_mesh<double>(2, 2, 2);
  VecX<> phi = VecX<>::Zero(box.V.rows());
  CHECK_THROWS_AS(marching_tets(exec::seq, box, VecX<>(VecX<>::Zero(3)), 0.0), ShapeError);
  phi[4] = std::nan("");
  CHECK_THROWS_WITH_AS(marching_tets(exec::seq, box, phi, 0.0), doctest::Contains("non-finite"), ArgumentError);
  phi[4] = 0;
  CHECK_THROWS_WITH_AS(marching_tets(exec::seq, box, phi, 0.0, {.snap = 0.5}), doctest::Contains("snap"), ArgumentError);
}

}  // namespace mesh_test_isosurface
