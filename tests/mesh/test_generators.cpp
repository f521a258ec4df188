#include <doctest/doctest.h>

#include <simsr/discretize/voxelize.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/quality.hpp>
#include <simsr/mesh/validate.hpp>
#include <simsr/mesh/volume.hpp>

#include <cmath>
#include <numbers>

#include "fixtures.hpp"

namespace mesh_test_generators {

using namespace simsr;

namespace {

/// Enclosed volume of a closed triangle surface by the divergence theorem (3×3 determinants).
double enclosed_volume(const TriMesh<>& m) {
  double v = 0;
  for (Index f = 0; f < m.F.rows(); ++f) {
    Eigen::Matrix3d M;
    for (int c = 0; c < 3; ++c) M.col(c) = m.V.row(m.F(f, c)).transpose();
    v += M.determinant() / 6;
  }
  return v;
}

double tets_volume(const TetMesh<>& m) {
  double v = 0;
  for (Index t = 0; t < m.T.rows(); ++t) v += test::det_volume6(m.V, {m.T(t, 0), m.T(t, 1), m.T(t, 2), m.T(t, 3)}) / 6;
  return v;
}

/// Closed, consistently oriented, one component, Euler characteristic 2 (a sphere).
void check_sphere_surface(const TriMesh<>& m) {
  CHECK_NOTHROW(discretize::detail::check_closed_surface(m.F));
  const Index E = unique_edges(m.F).rows();
  CHECK(m.V.rows() - E + m.F.rows() == 2);
  CHECK(connected_components(m.F, m.V.rows()).count == 1);
  CHECK_NOTHROW(validate(exec::seq, m));
}

}  // namespace

TEST_CASE("box_tet_mesh: exact volume, positive tets, boundary = 2 triangles per outer square") {
  for (const auto split : {CubeSplit::six, CubeSplit::five})
    for (const auto& n : std::vector<std::array<int, 3>>{{1, 1, 1}, {3, 2, 4}, {5, 5, 5}}) {
      CAPTURE(n[0]);
      const Vec3<> lo(-1, 0.5, 2), hi(2, 1.5, 2.25);
      const auto m = box_tet_mesh(n[0], n[1], n[2], lo, hi, split);
      CHECK_NOTHROW(validate(exec::seq, m));
      CHECK(m.T.rows() == (split == CubeSplit::six ? 6 : 5) * n[0] * n[1] * n[2]);
      CHECK(tets_volume(m) == doctest::Approx(3.0 * 1.0 * 0.25).epsilon(1e-13));
      CHECK(boundary_faces(m.T).rows() == test::box_boundary_count(n[0], n[1], n[2]));
      const auto q = element_quality(exec::seq, m.V, m.T);
      CHECK(q.minCoeff() > 0);
    }
  CHECK_THROWS_AS(box_tet_mesh(0, 1, 1), ArgumentError);
  CHECK_THROWS_AS(box_tet_mesh(1, 1, 1, Vec3<>(0, 0, 0), Vec3<>(1, 0, 1)), ArgumentError);
}

TEST_CASE("cylinder_tet_mesh: inscribed-prism volume exactly, O(h^2) convergence to pi r^2 H") {
  const double r = 0.7, H = 1.3, pi = std::numbers::pi;
  std::vector<double> err;
  for (const Index n : {2, 4, 8, 16}) {
    const auto m = cylinder_tet_mesh(r, H, n, 3);
    CHECK_NOTHROW(validate(exec::seq, m));
    CHECK(m.T.rows() == 18 * n * n * 3);
    const double N = 6.0 * double(n), polygon = 0.5 * N * r * r * std::sin(2 * pi / N);
    CHECK(tets_volume(m) == doctest::Approx(polygon * H).epsilon(1e-12));
    const auto B = boundary_surface(m);
    CHECK_NOTHROW(discretize::detail::check_closed_surface(B.F));
    for (Index v = 0; v < m.V.rows(); ++v) CHECK(std::hypot(m.V(v, 0), m.V(v, 1)) <= r * (1 + 1e-12));
    err.push_back(pi * r * r * H - tets_volume(m));
  }
  for (std::size_t i = 1; i < err.size(); ++i) CHECK(std::log2(err[i - 1] / err[i]) == doctest::Approx(2.0).epsilon(0.05));
}

TEST_CASE("sphere_shell_tet_mesh: conforming shell, two boundary spheres, O(h^2) volume") {
  const double r0 = 0.5, r1 = 1.2, pi = std::numbers::pi, exact = 4.0 / 3.0 * pi * (r1 * r1 * r1 - r0 * r0 * r0);
  std::vector<double> err;
  for (const Index level : {1, 2, 3, 4}) {
    const auto m = sphere_shell_tet_mesh(r0, r1, level, 3);
    CHECK_NOTHROW(validate(exec::seq, m));
    const auto B = boundary_faces(m.T);
    CHECK(B.rows() == 2 * 20 * (Index(1) << (2 * level)));  // inner + outer icosphere
    CHECK(connected_components(B, m.V.rows()).count == m.V.rows() - 2 * (10 * (Index(1) << (2 * level)) + 2) + 2);
    err.push_back(exact - tets_volume(m));
  }
  for (std::size_t i = 1; i < err.size(); ++i) CHECK(std::log2(err[i - 1] / err[i]) == doctest::Approx(2.0).epsilon(0.05));
}

TEST_CASE("icosphere: counts, outward orientation, O(h^2) volume, same as the independent test fixture") {
  std::vector<double> err;
  for (const Index level : {0, 1, 2, 3, 4, 5}) {
    const auto m = icosphere(level, 2.0);
    CHECK(m.V.rows() == 10 * (Index(1) << (2 * level)) + 2);
    CHECK(m.F.rows() == 20 * (Index(1) << (2 * level)));
    check_sphere_surface(m);
    for (Index v = 0; v < m.V.rows(); ++v) CHECK(m.V.row(v).norm() == doctest::Approx(2.0));
    const auto ref = test::icosphere(int(level), 2.0);
    CHECK(enclosed_volume(m) == doctest::Approx(enclosed_volume(ref)).epsilon(1e-12));
    err.push_back(4.0 / 3.0 * std::numbers::pi * 8.0 - enclosed_volume(m));
  }
  for (std::size_t i = 2; i < err.size(); ++i) CHECK(std::log2(err[i - 1] / err[i]) == doctest::Approx(2.0).epsilon(0.05));
  CHECK_THROWS_AS(icosphere(-1), ArgumentError);
  CHECK_THROWS_AS(icosphere(11), ArgumentError);
}

TEST_CASE("ellipsoid_surface: exact vertex count, closed sphere, outward, O(1/nv) volume convergence") {
  const double a = 1.0, b = 0.8, c = 0.6, exact = 4.0 / 3.0 * std::numbers::pi * a * b * c;
  for (const Index nv : {8, 9, 50, 641, 3001, 35637}) {
    CAPTURE(nv);
    const auto m = ellipsoid_surface(nv, a, b, c);
    CHECK(m.V.rows() == nv);
    CHECK(m.F.rows() == 2 * nv - 4);
    check_sphere_surface(m);
    for (Index v = 0; v < nv; ++v)
      CHECK(std::pow(m.V(v, 0) / a, 2) + std::pow(m.V(v, 1) / b, 2) + std::pow(m.V(v, 2) / c, 2) == doctest::Approx(1.0));
    CHECK(enclosed_volume(m) > 0);
    CHECK(enclosed_volume(m) < exact);  // inscribed polyhedron
  }
  // Edge length ~ nv^(-1/2), so the volume error ~ 1/nv: ×4 vertices → error / 4.
  std::vector<double> err;
  for (const Index nv : {500, 2000, 8000, 32000}) err.push_back(exact - enclosed_volume(ellipsoid_surface(nv, a, b, c)));
  for (std::size_t i = 1; i < err.size(); ++i) CHECK(std::log2(err[i - 1] / err[i]) == doctest::Approx(2.0).epsilon(0.08));
  CHECK_THROWS_AS(ellipsoid_surface(7, a, b, c), ArgumentError);
  CHECK_THROWS_AS(ellipsoid_surface(100, a, -1.0, c), ArgumentError);
}

namespace {
/// Area of a mesh in the plane z = 0, checking that every triangle is counter-clockwise from +z.
double ccw_area_in_plane(const TriMesh<>& m) {
  double area = 0;
  for (Index f = 0; f < m.F.rows(); ++f) {
    const Vec3<> p = m.V.row(m.F(f, 0)), q = m.V.row(m.F(f, 1)), r = m.V.row(m.F(f, 2));
    const double z = (q - p).cross(r - p)[2];
    CHECK(z > 0);
    area += z / 2;
  }
  return area;
}
}  // namespace

TEST_CASE("disk_surface: counter-clockwise, area converges to pi r^2") {
  for (const Index n : {1, 3, 9}) {
    const auto d = disk_surface(1.5, n);
    CHECK(d.V.rows() == 1 + 3 * n * (n + 1));
    CHECK(d.F.rows() == 6 * n * n);
    const double area = ccw_area_in_plane(d);
    const double N = 6.0 * double(n);
    CHECK(area == doctest::Approx(0.5 * N * 2.25 * std::sin(2 * std::numbers::pi / N)).epsilon(1e-12));
    CHECK(boundary_loops(d.F).size() == 1);
  }
}

TEST_CASE("square_sheet: counts, counter-clockwise, exact area, one boundary loop, alternating diagonals") {
  for (const Index n : {1, 2, 8}) {
    const auto s = square_sheet(2.0, n);
    CHECK(s.V.rows() == (n + 1) * (n + 1));
    CHECK(s.F.rows() == 2 * n * n);
    const double area = ccw_area_in_plane(s);
    CHECK(area == doctest::Approx(4.0).epsilon(1e-14));
    CHECK(boundary_loops(s.F).size() == 1);
    CHECK(unique_edges(s.F).rows() == 2 * n * (n + 1) + n * n);  // axis edges + one diagonal per cell
  }
  // 8 cells: the SHEET scene's 81 coarse vertices; neighbouring cells carry crossing diagonals
  const auto s = square_sheet(1.0, 8);
  CHECK(s.V.rows() == 81);
  const Edges E = unique_edges(s.F);
  auto has = [&](VIndex a, VIndex b) {
    for (Index e = 0; e < E.rows(); ++e)
      if (E(e, 0) == std::min(a, b) && E(e, 1) == std::max(a, b)) return true;
    return false;
  };
  CHECK(has(0, 10));   // cell (0, 0): diagonal from (0, 0) to (1, 1)
  CHECK(has(2, 10));   // cell (1, 0): diagonal from (2, 0) to (1, 1)
  CHECK(!has(1, 9));
}

}  // namespace mesh_test_generators
