#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <simsr/mesh/normals.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/triangulate.hpp>
#include <simsr/mesh/validate.hpp>

#include <filesystem>

#include "fixtures.hpp"

namespace mesh_test_triangulate {

using namespace simsr;
using namespace simsr::test;

namespace {

using P2 = Eigen::Vector2d;

/// Random simple polygon in the plane, counter-clockwise: convex (on an ellipse) or star-shaped around the origin.
std::vector<P2> random_polygon(int n, bool convex, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  // Angular gaps below π keep the origin in the kernel, so the polygon is simple.
  std::vector<double> angle(static_cast<std::size_t>(n));
  const double start = 2 * M_PI * u(rng);
  for (int i = 0; i < n; ++i) angle[i] = start + 2 * M_PI * (i + 0.4 * u(rng)) / n;
  const double ax = 0.5 + u(rng), ay = 0.5 + u(rng);
  std::vector<P2> p;
  for (double a : angle) {
    const double r = convex ? 1.0 : 0.15 + 0.85 * u(rng);
    p.emplace_back(ax * r * std::cos(a), ay * r * std::sin(a));
  }
  return p;
}

double cross2(const P2& a, const P2& b, const P2& c) { return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x(); }

double shoelace(const std::vector<P2>& p) {
  double s = 0;
  for (std::size_t i = 0; i < p.size(); ++i) s += p[i].x() * p[(i + 1) % p.size()].y() - p[(i + 1) % p.size()].x() * p[i].y();
  return s / 2;
}

bool inside_polygon(const std::vector<P2>& p, const P2& q) {  // even-odd ray casting
  bool in = false;
  for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    if ((p[i].y() > q.y()) != (p[j].y() > q.y()) &&
        q.x() < (p[j].x() - p[i].x()) * (q.y() - p[i].y()) / (p[j].y() - p[i].y()) + p[i].x())
      in = !in;
  return in;
}

}  // namespace

TEST_CASE("triangulate: random convex and star-shaped polygons in random 3-D planes") {
  std::mt19937 rng(70);
  std::uniform_real_distribution<double> u(-1, 1);
  int nonconvex_seen = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const bool convex = trial % 2 == 0, reversed = trial % 4 >= 2;
    const int n = 3 + int(rng() % 18);
    std::vector<P2> p = random_polygon(n, convex, rng);
    if (reversed) std::reverse(p.begin(), p.end());
    const double signed_area = shoelace(p);
    bool is_convex = true;
    for (int i = 0; i < n; ++i) is_convex &= cross2(p[i], p[(i + 1) % n], p[(i + 2) % n]) * signed_area >= 0;
    nonconvex_seen += !is_convex;
    // Embed: x = o + R·(u, v, 0); the polygon's normal is sign(area)·R·e_z.
    const Mat3<> R = random_rotation(rng);
    const Vec3<> o(u(rng), u(rng), u(rng));
    const Vec3<> normal = (signed_area > 0 ? 1.0 : -1.0) * R.col(2);
    PolyMesh<> poly;
    poly.V.resize(n + 2, 3);  // two extra vertices that no polygon uses
    poly.V.row(0) = Eigen::RowVector3d(9, 9, 9);
    poly.V.row(1) = Eigen::RowVector3d(-9, 9, 9);
    std::vector<VIndex> corners;
    std::vector<int> offset(n);
    const int shift = int(rng() % n);  // arbitrary starting corner
    for (int i = 0; i < n; ++i) {
      const int k = (i + shift) % n;
      poly.V.row(2 + i) = (o + R * Vec3<>(p[k].x(), p[k].y(), 0)).transpose();
      corners.push_back(VIndex(2 + i));
      offset[i] = k;
    }
    poly.add_face(corners);
    std::vector<Index> face_of;
    const TriMesh<> tri = triangulate(poly, &face_of);
    CAPTURE(trial);
    REQUIRE(tri.F.rows() == n - 2);
    CHECK(face_of == std::vector<Index>(std::size_t(n - 2), 0));
    double total = 0;
    for (Index f = 0; f < tri.F.rows(); ++f) {
      for (int c = 0; c < 3; ++c) CHECK((tri.F(f, c) >= 2 && tri.F(f, c) < n + 2));
      const Vec3<> a = tri.V.row(tri.F(f, 0)), b = tri.V.row(tri.F(f, 1)), c = tri.V.row(tri.F(f, 2));
      const double oriented = (b - a).cross(c - a).dot(normal) / 2;
      CHECK(oriented > 0);  // every triangle keeps the polygon's orientation
      total += oriented;
    }
    CHECK(total == doctest::Approx(std::abs(signed_area)).epsilon(1e-10));
    // Coverage: random points inside the polygon lie in exactly one triangle.
    auto local = [&](VIndex v) { return p[offset[v - 2]]; };
    for (int s = 0; s < 40; ++s) {
      const P2 q(1.5 * u(rng), 1.5 * u(rng));
      if (!inside_polygon(p, q)) continue;
      int hits = 0;
      for (Index f = 0; f < tri.F.rows(); ++f) {
        const P2 a = local(tri.F(f, 0)), b = local(tri.F(f, 1)), c = local(tri.F(f, 2));
        const double sg = signed_area > 0 ? 1 : -1;
        hits += sg * cross2(a, b, q) > 0 && sg * cross2(b, c, q) > 0 && sg * cross2(c, a, q) > 0;
      }
      CHECK(hits == 1);
    }
  }
  CHECK(nonconvex_seen > 50);
}

TEST_CASE("triangulate: several polygons, face_of_triangle, and errors naming the polygon") {
  PolyMesh<> poly;
  poly.V.resize(8, 3);
  poly.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 3, 1, 0, 2, 0.5, 0;
  poly.add_face(std::vector<int>{0, 1, 2, 3});
  poly.add_face(std::vector<int>{1, 4, 7, 2});
  poly.add_face(std::vector<int>{4, 5, 6});
  std::vector<Index> face_of;
  const TriMesh<> t = triangulate(poly, &face_of);
  CHECK(t.F.rows() == 5);
  CHECK(face_of == std::vector<Index>{0, 0, 1, 1, 2});
  CHECK(face_areas(exec::seq, t.V, t.F).sum() == doctest::Approx(1.0 + 0.75 + 0.5));
  for (Index f = 0; f < t.F.rows(); ++f) CHECK(face_normals(exec::seq, t.V, t.F)(f, 2) == doctest::Approx(1.0));
  PolyMesh<> bad = poly;
  bad.add_face(std::vector<int>{0, 1});
  try {
    triangulate(bad);
    FAIL("expected MeshError");
  } catch (const MeshError& e) {
    CHECK(e.kind() == "polygon");
    CHECK(e.element() == 3);
  }
  bad = poly;
  bad.indices[5] = 8;  // polygon 1's second corner
  try {
    triangulate(bad);
    FAIL("expected MeshError");
  } catch (const MeshError& e) {
    CHECK(e.element() == 1);
  }
}

TEST_CASE("real data: the ICT face (quads) triangulates, keeps vector areas, is a disc with holes") {
  const std::string path = std::string(SIMSR_DATA_DIR) + "/ict_face/neutral_face_head.obj";
  if (!std::filesystem::exists(path)) {
    SIMSR_MISSING("ICT face OBJ not found: " << path);
    return;
  }
  const PolyMesh<> poly = load_obj_polygons(path);
  REQUIRE(poly.num_vertices() == 11248);
  REQUIRE(poly.num_faces() == 11144);
  std::vector<Index> face_of;
  const TriMesh<> tri = triangulate(poly, &face_of);
  CHECK(tri.F.rows() == 2 * 11144);
  // The vector area of a triangulated polygon equals its Newell vector area whatever the diagonal.
  Points<> newell = Points<>::Zero(poly.num_faces(), 3), tri_area = Points<>::Zero(poly.num_faces(), 3);
  for (Index f = 0; f < poly.num_faces(); ++f)
    for (Index i = 0; i < poly.face_size(f); ++i) {
      const Vec3<> a = poly.V.row(poly.indices[poly.offsets[f] + i]);
      const Vec3<> b = poly.V.row(poly.indices[poly.offsets[f] + (i + 1) % poly.face_size(f)]);
      newell.row(f) += a.cross(b).transpose() / 2;
    }
  for (Index t = 0; t < tri.F.rows(); ++t) {
    const Vec3<> a = tri.V.row(tri.F(t, 0)), b = tri.V.row(tri.F(t, 1)), c = tri.V.row(tri.F(t, 2));
    tri_area.row(face_of[t]) += (b - a).cross(c - a).transpose() / 2;
  }
  CHECK((newell - tri_area).cwiseAbs().maxCoeff() < 1e-9);
  CHECK_NOTHROW(validate(exec::seq, tri));
  // Topology: one connected piece, genus 0 with holes (eyes, mouth, neck...): χ = 2 − #loops.
  const Components C = connected_components(tri.F, tri.V.rows());
  CHECK(C.count == 1);
  const auto loops = boundary_loops(tri.F);
  CHECK(loops.size() >= 4);
  const Index chi = tri.V.rows() - unique_edges(tri.F).rows() + tri.F.rows();
  CHECK(chi == 2 - Index(loops.size()));
  // Orientation: the normal at the nose tip (largest z) points forward.
  Index tip = 0;
  tri.V.col(2).maxCoeff(&tip);
  CHECK(vertex_normals(tri.V, tri.F, NormalWeighting::area)(tip, 2) > 0.8);
}

}  // namespace mesh_test_triangulate
