// isotropic_remesh (CGAL): edge lengths near the target, the surface kept (on the input, same
// area, same orientation, manifold), patch boundaries and the open border kept on their input
// polylines, patch labels carried, typed errors. Built in test_cgal (tests/CMakeLists.txt).
#include <doctest/doctest.h>

#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/isotropic_remesh.hpp>
#include <simsr/mesh/topology.hpp>

#include <algorithm>
#include <map>
#include <random>
#include <utility>
#include <vector>

namespace mesh_test_isotropic_remesh {

using namespace simsr;

double area(const TriMesh<>& m) {
  double a = 0;
  for (Index f = 0; f < m.F.rows(); ++f)
    a += 0.5 * (m.V.row(m.F(f, 1)) - m.V.row(m.F(f, 0))).cross(m.V.row(m.F(f, 2)) - m.V.row(m.F(f, 0))).norm();
  return a;
}

double segment_distance(const Vec3<>& p, const Vec3<>& a, const Vec3<>& b) {
  const Vec3<> d = b - a;
  const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * d)).norm();
}

/// Distance from p to the nearest of the segments (brute force).
double polyline_distance(const Vec3<>& p, const std::vector<std::pair<Vec3<>, Vec3<>>>& segments) {
  double best = 1e300;
  for (const auto& [a, b] : segments) best = std::min(best, segment_distance(p, a, b));
  return best;
}

/// Edges between triangles of different labels, and border edges, as segments.
void feature_segments(const TriMesh<>& m, const std::vector<int>& label, std::vector<std::pair<Vec3<>, Vec3<>>>& between,
                      std::vector<std::pair<Vec3<>, Vec3<>>>& border) {
  std::map<std::pair<VIndex, VIndex>, std::vector<Index>> faces_of;
  for (Index f = 0; f < m.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const VIndex a = m.F(f, c), b = m.F(f, (c + 1) % 3);
      faces_of[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  for (const auto& [e, fs] : faces_of) {
    const std::pair<Vec3<>, Vec3<>> s{m.V.row(e.first).transpose(), m.V.row(e.second).transpose()};
    if (fs.size() == 1)
      border.push_back(s);
    else if (label[std::size_t(fs[0])] != label[std::size_t(fs[1])])
      between.push_back(s);
  }
}

TEST_CASE("isotropic_remesh: a cut sphere of two patches, at three target lengths") {
  // the unit icosphere with its top cap cut off (an open border) and two patches split by a plane
  const TriMesh<> sphere = icosphere<double>(4, 1.0);
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0, 1);
  for (const double target : {0.06, 0.12, 0.25}) {
    CAPTURE(target);
    const Vec3<> n = Vec3<>(normal(rng), normal(rng), normal(rng)).normalized();
    TriMesh<> in;
    in.V = sphere.V;
    std::vector<std::array<VIndex, 3>> kept;
    std::vector<int> label;
    for (Index f = 0; f < sphere.F.rows(); ++f) {
      const Vec3<> c = (sphere.V.row(sphere.F(f, 0)) + sphere.V.row(sphere.F(f, 1)) + sphere.V.row(sphere.F(f, 2))).transpose() / 3;
      if (c.z() > 0.8) continue;
      kept.push_back({sphere.F(f, 0), sphere.F(f, 1), sphere.F(f, 2)});
      label.push_back(c.dot(n) > 0 ? 7 : 3);
    }
    in.F.resize(Index(kept.size()), 3);
    for (std::size_t f = 0; f < kept.size(); ++f)
      for (int c = 0; c < 3; ++c) in.F(Index(f), c) = kept[f][std::size_t(c)];

    const RemeshedSurface r = isotropic_remesh(exec::omp, in, label, {.target_edge_length = target});
    const TriMesh<>& m = r.mesh;
    REQUIRE(Index(r.patch.size()) == m.F.rows());
    for (int p : r.patch) CHECK((p == 3 || p == 7));

    // edge lengths near the target (CGAL splits above 4/3 and collapses below 4/5 of it)
    const Edges e = unique_edges(m.F);
    std::vector<double> len;
    for (Index k = 0; k < e.rows(); ++k) len.push_back((m.V.row(e(k, 0)) - m.V.row(e(k, 1))).norm());
    std::sort(len.begin(), len.end());
    const double p05 = len[len.size() / 20], p95 = len[len.size() * 19 / 20];
    MESSAGE("target " << target << ": " << m.num_vertices() << " vertices, edges p5 " << p05 << ", median " << len[len.size() / 2] << ", p95 " << p95);
    CHECK(p05 > 0.5 * target);
    CHECK(p95 < 1.5 * target);
    CHECK(std::abs(len[len.size() / 2] / target - 1) < 0.25);

    // every vertex on the sphere (projected onto the input: within its chord error)
    const double chord = 0.02;  // the level-4 icosphere's facets lie within ~0.01 of the unit sphere
    for (Index i = 0; i < m.num_vertices(); ++i) CHECK(std::abs(m.V.row(i).norm() - 1) < chord);
    // same area, outward orientation, edge-manifold with one border loop
    CHECK(std::abs(area(m) / area(in) - 1) < 0.02);
    for (Index f = 0; f < m.F.rows(); ++f) {
      const Vec3<> a = m.V.row(m.F(f, 0)).transpose(), b = m.V.row(m.F(f, 1)).transpose(), c = m.V.row(m.F(f, 2)).transpose();
      CHECK((b - a).cross(c - a).dot(a + b + c) > 0);
    }
    CHECK(boundary_loops(m.F).size() == 1);

    // patch boundaries and the border stay on the input's polylines
    std::vector<std::pair<Vec3<>, Vec3<>>> in_between, in_border, out_between, out_border;
    feature_segments(in, label, in_between, in_border);
    feature_segments(m, r.patch, out_between, out_border);
    REQUIRE(!out_between.empty());
    REQUIRE(!out_border.empty());
    for (const auto& [a, b] : out_between) {
      CHECK(polyline_distance(a, in_between) < 1e-9);
      CHECK(polyline_distance(b, in_between) < 1e-9);
    }
    for (const auto& [a, b] : out_border) {
      CHECK(polyline_distance(a, in_border) < 1e-9);
      CHECK(polyline_distance(b, in_border) < 1e-9);
    }
  }
}

TEST_CASE("isotropic_remesh: typed errors") {
  const TriMesh<> s = icosphere<double>(1, 1.0);
  const std::vector<int> label(std::size_t(s.F.rows()), 0);
  CHECK_THROWS_AS(isotropic_remesh(exec::seq, s, std::vector<int>(3, 0), {.target_edge_length = 0.1}), ShapeError);
  CHECK_THROWS_AS(isotropic_remesh(exec::seq, s, label, {.target_edge_length = 0}), ArgumentError);
  CHECK_THROWS_AS(isotropic_remesh(exec::seq, s, label, {.target_edge_length = -1}), ArgumentError);
  CHECK_THROWS_AS(isotropic_remesh(exec::seq, s, label, {.target_edge_length = 0.1, .iterations = 0}), ArgumentError);
  TriMesh<> bad = s;
  bad.V(4, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(isotropic_remesh(exec::seq, bad, label, {.target_edge_length = 0.1}), ArgumentError);
  // a third triangle on an edge
  TriMesh<> fin = s;
  fin.V.conservativeResize(s.V.rows() + 1, 3);
  fin.V.row(s.V.rows()) << 0, 0, 3;
  fin.F.conservativeResize(s.F.rows() + 1, 3);
  fin.F.row(s.F.rows()) << s.F(0, 0), s.F(0, 1), VIndex(s.V.rows());
  std::vector<int> fin_label(std::size_t(fin.F.rows()), 0);
  try {
    isotropic_remesh(exec::seq, fin, fin_label, {.target_edge_length = 0.1});
    FAIL("no error for a non-manifold edge");
  } catch (const MeshError& e) {
    CHECK(std::string(e.what()).find(std::to_string(s.F.rows())) != std::string::npos);
  }
  TriMesh<> out_of_range = s;
  out_of_range.F(2, 1) = 999;
  CHECK_THROWS_AS(isotropic_remesh(exec::seq, out_of_range, label, {.target_edge_length = 0.1}), MeshError);
}

}  // namespace mesh_test_isotropic_remesh
