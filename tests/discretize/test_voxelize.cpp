#include <doctest/doctest.h>

#include <simsr/discretize/voxelize.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/topology.hpp>

#include <cmath>
#include <random>
#include <vector>

using namespace simsr;
using namespace simsr::discretize;

namespace {

/// Sutherland–Hodgman: clips the triangle against the 6 slabs of the closed box; true when
/// something of positive area or a point strictly inside the open box survives. Independent of SAT.
bool clip_overlap(const Vec3<>& centre, const Vec3<>& half, const Vec3<>& a, const Vec3<>& b, const Vec3<>& c) {
  std::vector<Vec3<>> poly{a, b, c};
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      const double bound = centre[axis] + side * half[axis];
      const auto in = [&](const Vec3<>& p) { return side * (p[axis] - bound) <= 0; };
      std::vector<Vec3<>> out;
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const Vec3<>& p = poly[i];
        const Vec3<>& q = poly[(i + 1) % poly.size()];
        if (in(p)) out.push_back(p);
        if (in(p) != in(q)) {
          const double t = (bound - p[axis]) / (q[axis] - p[axis]);
          out.push_back(p + t * (q - p));
        }
      }
      poly = out;
      if (poly.empty()) return false;
    }
  Vec3<> mean = Vec3<>::Zero();
  for (const auto& p : poly) mean += p;
  mean /= double(poly.size());
  return ((mean - centre).cwiseAbs() - half).maxCoeff() < 0;  // the clipped polygon's centroid is interior
}

/// Some sample of the triangle (barycentric grid of resolution n) strictly inside the box.
bool sampled_inside(const Vec3<>& centre, const Vec3<>& half, const Vec3<>& a, const Vec3<>& b, const Vec3<>& c, int n) {
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const Vec3<> p = a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n);
      if (((p - centre).cwiseAbs() - half).maxCoeff() < 0) return true;
    }
  return false;
}

/// Octahedron |x| + |y| + |z| = r: vertices on the axes, so grid rays hit vertices and edges exactly.
TriMesh<> octahedron(double r) {
  TriMesh<> m;
  m.V.resize(6, 3);
  m.V << r, 0, 0, -r, 0, 0, 0, r, 0, 0, -r, 0, 0, 0, r, 0, 0, -r;
  m.F.resize(8, 3);
  m.F << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return m;
}

}  // namespace

TEST_CASE("triangle_box_overlap (SAT) agrees with polygon clipping and with dense sampling on random cases") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5), s(0.05, 1.0);
  int overlaps = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Vec3<> centre(u(rng) * 0.3, u(rng) * 0.3, u(rng) * 0.3), half(s(rng), s(rng), s(rng));
    Vec3<> a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
    if (trial % 4 == 0) c = a + 0.3 * (b - a);  // degenerate (segment) triangles too
    const bool sat = discretize::detail::triangle_box_overlap(centre, half, a, b, c);
    overlaps += sat;
    CAPTURE(trial);
    if (trial % 4 != 0) CHECK(sat == clip_overlap(centre, half, a, b, c));
    if (sampled_inside(centre, half, a, b, c, 40)) CHECK(sat);  // a witness point forces overlap
  }
  CHECK(overlaps > 800);  // both outcomes well represented
  CHECK(overlaps < 3200);
  // Touching only: a triangle in the plane of a face, or meeting only an edge, is no overlap.
  const Vec3<> o = Vec3<>::Zero(), h = Vec3<>::Constant(0.5);
  CHECK_FALSE(discretize::detail::triangle_box_overlap(o, h, Vec3<>(0.5, -1, -1), Vec3<>(0.5, 2, -1), Vec3<>(0.5, 0, 2)));
  CHECK(discretize::detail::triangle_box_overlap(o, h, Vec3<>(0.49, -1, -1), Vec3<>(0.49, 2, -1), Vec3<>(0.49, 0, 2)));
  CHECK_FALSE(discretize::detail::triangle_box_overlap(o, h, Vec3<>(0.5, 0.5, -3), Vec3<>(1.5, 1.5, -3), Vec3<>(1, 1, 3)));
}

TEST_CASE("tet_box_overlap (SAT) agrees with dense sampling of the tet on random cases") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.2, 1.2), s(0.05, 0.8);
  int overlaps = 0;
  for (int trial = 0; trial < 1500; ++trial) {
    const Vec3<> centre = Vec3<>::Zero(), half(s(rng), s(rng), s(rng));
    std::array<Vec3<>, 4> p;
    for (auto& q : p) q = Vec3<>(u(rng), u(rng), u(rng));
    const bool sat = discretize::detail::tet_box_overlap(centre, half, p);
    overlaps += sat;
    // Samples: barycentric grid of resolution n; the closest sample to the box lies within the
    // grid spacing of the tet's closest point, so "overlap" must show a sample near the box.
    const int n = 24;
    bool inside = false;
    double nearest = 1e300;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j)
        for (int k = 0; i + j + k <= n; ++k) {
          const Vec3<> x = p[0] + (p[1] - p[0]) * (double(i) / n) + (p[2] - p[0]) * (double(j) / n) + (p[3] - p[0]) * (double(k) / n);
          const double d = ((x - centre).cwiseAbs() - half).maxCoeff();
          inside |= d < 0;
          nearest = std::min(nearest, d);
        }
    double diam = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) diam = std::max(diam, (p[i] - p[j]).norm());
    CAPTURE(trial);
    if (inside) CHECK(sat);
    if (sat) CHECK(nearest < diam / n);
  }
  CHECK(overlaps > 300);
  CHECK(overlaps < 1200);
}

TEST_CASE("inside test: watertight on rays through vertices and edges (octahedron), exact vs analytic") {
  const auto oct = octahedron(1.0);
  // Rows at y, z ∈ {-1, -0.5, 0, 0.5, 1} pass exactly through vertices and along edges; x off-surface.
  Index count = 0;
  const auto in2 = discretize::detail::inside_on_grid(oct.V, oct.F, Vec3<>(-1.3, -1.0, -1.0), 0.5, {6, 5, 5});
  for (Index k = 0; k < 5; ++k)
    for (Index j = 0; j < 5; ++j)
      for (Index i = 0; i < 6; ++i) {
        const double x = -1.3 + 0.5 * double(i), y = -1.0 + 0.5 * double(j), z = -1.0 + 0.5 * double(k);
        const double l1 = std::abs(x) + std::abs(y) + std::abs(z);
        CAPTURE(x);
        CAPTURE(y);
        CAPTURE(z);
        REQUIRE(std::abs(l1 - 1.0) > 1e-9);
        CHECK(bool(in2[std::size_t(i + 6 * (j + 5 * k))]) == (l1 < 1.0));
        count += l1 < 1.0;
      }
  CHECK(count > 5);
  // Same points through inside_surface (one ray each) and a reversed (inward) copy: winding −1 still inside.
  auto inv = oct;
  inv.F.col(1).swap(inv.F.col(2));
  Points<> P(3, 3);
  P << 0.2, 0.0, 0.0, 0.0, 0.5, 0.49, 0.5, 0.5, 0.01;
  const auto a = inside_surface(oct, P), b = inside_surface(inv, P);
  CHECK(a == std::vector<char>{1, 1, 0});
  CHECK(b == a);
}

TEST_CASE("voxelize a sphere surface: kept cells vs the analytic inside test") {
  const double r = 1.0;
  const auto sphere = icosphere(4, r);
  double r_in = r;  // inscribed radius of the polyhedron: its smallest face-plane distance
  for (Index f = 0; f < sphere.F.rows(); ++f) {
    const Vec3<> a = sphere.V.row(sphere.F(f, 0)), b = sphere.V.row(sphere.F(f, 1)), c = sphere.V.row(sphere.F(f, 2));
    r_in = std::min(r_in, std::abs((b - a).cross(c - a).normalized().dot(a)));
  }
  for (const auto alignment : {GridAlignment::anchored, GridAlignment::bounding_box})
    for (const double h : {0.3, 0.11, 0.05}) {
      VoxelizeOptions opt;
      opt.alignment = alignment;
      opt.anchor = Vec3<>(0.013, -0.02, 0.007);
      const auto vox = voxelize(sphere, h, opt);
      const Grid& g = vox.grid;
      if (alignment == GridAlignment::anchored)
        for (int a = 0; a < 3; ++a) CHECK(std::abs(std::remainder(g.origin[a] - opt.anchor[a], h)) < 1e-9);
      std::vector<char> kept(std::size_t(g.num_cells()), 0);
      for (const auto& c : vox.cells) kept[std::size_t(g.linear(c[0], c[1], c[2]))] = 1;
      Index undecided = 0;
      for (Index k = 0; k < g.dims[2]; ++k)
        for (Index j = 0; j < g.dims[1]; ++j)
          for (Index i = 0; i < g.dims[0]; ++i) {
            const Vec3<> lo = g.origin + h * Vec3<>(double(i), double(j), double(k)), hi = lo + Vec3<>::Constant(h);
            const double near = (lo.cwiseMax(Vec3<>::Zero()).cwiseMin(hi) - Vec3<>::Zero()).norm();  // box point nearest the centre
            const double far = lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).norm();
            const bool k_ = kept[std::size_t(g.linear(i, j, k))];
            const Vec3<> centre = g.centre(i, j, k);
            if (centre.norm() < r_in) CHECK(k_);  // analytic inside test on the cell centre
            if (near < r_in) CHECK(k_);           // meets the inscribed ball
            if (near >= r) CHECK_FALSE(k_);       // misses the circumscribed ball
            if (far < r_in) CHECK(k_);
            undecided += near >= r_in && near < r;
          }
      // Kept volume brackets the sphere's and converges to it.
      const double vs = 4.0 / 3.0 * std::numbers::pi * r * r * r;
      CHECK(vox.volume() > 4.0 / 3.0 * std::numbers::pi * r_in * r_in * r_in);
      if (h < 0.1) CHECK(vox.volume() / vs - 1 < 8 * h);
      CHECK(undecided < vox.size());
    }
}

TEST_CASE("voxelize: a surface on grid planes keeps no extra layer; region mask; tets == their boundary surface") {
  // Unit cube as 12 triangles (boundary of a box tet mesh), grid of h = 0.25 anchored at 0.
  const auto box = box_tet_mesh(1, 1, 1);
  const auto cube = boundary_surface(box);
  auto vox = voxelize(cube, 0.25);
  CHECK(vox.size() == 64);
  CHECK(vox.volume() == doctest::Approx(1.0));
  CHECK(voxelize(box, 0.25).cells == vox.cells);
  // Shifted grid: 5 cells per axis cover the cube.
  VoxelizeOptions shifted;
  shifted.anchor = Vec3<>::Constant(0.1);
  CHECK(voxelize(cube, 0.25, shifted).size() == 125);
  CHECK(voxelize(box, 0.25, shifted).size() == 125);

  VoxelizeOptions masked;
  masked.region = [](const Vec3<>& c) { return c.z() > 0.5 && c.x() < 0.3; };
  const auto m = voxelize(cube, 0.25, masked);
  CHECK(m.size() == 2 * 1 * 4);  // z: 2 of 4 layers, x: 1 of 4 columns, y: all 4
  for (const auto& c : m.cells) CHECK(masked.region(m.grid.centre(c[0], c[1], c[2])));

  // Two different algorithms must agree: SAT on tets vs surface SAT + winding of their boundary.
  for (const double h : {0.13, 0.071}) {
    const auto cyl = cylinder_tet_mesh(0.6, 1.1, 4, 5);
    CHECK(voxelize(cyl, h).cells == voxelize(boundary_surface(cyl), h).cells);
    const auto shell = sphere_shell_tet_mesh(0.45, 0.9, 2, 2);
    const auto sv = voxelize(shell, h);
    CHECK(sv.cells == voxelize(boundary_surface(shell), h).cells);  // inner sphere faces inward: winding 0 in the hole
    bool hole_empty = true;
    for (const auto& c : sv.cells) hole_empty &= !((sv.grid.centre(c[0], c[1], c[2]).norm() + h) < 0.4);
    CHECK(hole_empty);
  }
}

TEST_CASE("voxelize: errors name what is wrong and where") {
  auto s = icosphere(1);
  CHECK_THROWS_AS(voxelize(s, 0.0), ArgumentError);
  CHECK_THROWS_AS(voxelize(s, -0.1), ArgumentError);
  CHECK_THROWS_AS(voxelize(s, std::nan("")), ArgumentError);
  CHECK_THROWS_WITH_AS(voxelize(s, 1e-6), doctest::Contains("max_cells"), ArgumentError);
  auto open = s;
  open.F.conservativeResize(open.F.rows() - 1, 3);
  CHECK_THROWS_WITH_AS(voxelize(open, 0.1), doctest::Contains("the surface is open"), MeshError);
  auto flipped = s;
  std::swap(flipped.F(5, 1), flipped.F(5, 2));
  CHECK_THROWS_WITH_AS(voxelize(flipped, 0.1), doctest::Contains("inconsistent orientation"), MeshError);
  auto fin = s;  // a fin: a third triangle on edge (F(0,0), F(0,1)) and its reverse
  fin.V.conservativeResize(fin.V.rows() + 1, 3);
  fin.V.row(fin.V.rows() - 1) << 3, 3, 3;
  fin.F.conservativeResize(fin.F.rows() + 2, 3);
  fin.F.row(fin.F.rows() - 2) << s.F(0, 0), s.F(0, 1), VIndex(fin.V.rows() - 1);
  fin.F.row(fin.F.rows() - 1) << s.F(0, 1), s.F(0, 0), VIndex(fin.V.rows() - 1);
  CHECK_THROWS_WITH_AS(voxelize(fin, 0.1), doctest::Contains("not manifold"), MeshError);
  auto bad = box_tet_mesh(1, 1, 1);
  bad.T(0, 0) = 99;
  CHECK_THROWS_AS(voxelize(bad, 0.1), MeshError);
}
