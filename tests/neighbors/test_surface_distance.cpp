#include <doctest/doctest.h>

#include <simsr/mesh/closest_point.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/neighbors/surface_distance.hpp>

#include <random>

using namespace simsr;

namespace {

/// Brute force: every triangle, exact closest points.
double brute_surface_distance(const TriMesh<>& s, const Vec3<>& q, Index* tri) {
  double best = 1e300;
  for (Index f = 0; f < s.F.rows(); ++f) {
    const Vec3<> a = s.V.row(s.F(f, 0)).transpose(), b = s.V.row(s.F(f, 1)).transpose(), c = s.V.row(s.F(f, 2)).transpose();
    const Vec3<> w = closest_point_on_triangle(q, a, b, c);
    const double d = (w[0] * a + w[1] * b + w[2] * c - q).norm();
    if (d < best) best = d, *tri = f;
  }
  return best;
}

}  // namespace

TEST_CASE("SurfaceDistance equals brute force on random surfaces, with a few huge triangles and unused vertices") {
  std::mt19937 rng(41);
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 10; ++trial) {
    TriMesh<> s = icosphere<double>(1 + Index(trial % 3), 1.0);
    for (Index v = 0; v < s.V.rows(); ++v) s.V.row(v) *= 1 + 0.2 * n(rng);  // bumpy
    // a far vertex, a fan of 3 huge triangles to it, and an unused vertex beside the sphere
    const Index far = s.V.rows(), unused = far + 1;
    s.V.conservativeResize(s.V.rows() + 2, 3);
    s.V.row(far) << 30, 0, 0;
    s.V.row(unused) << 0.2, 0.1, 0.0;
    const Index nf = s.F.rows();
    s.F.conservativeResize(nf + 3, 3);
    s.F.row(nf) << 0, 1, VIndex(far);
    s.F.row(nf + 1) << 1, 2, VIndex(far);
    s.F.row(nf + 2) << 2, 3, VIndex(far);
    const neighbors::SurfaceDistance<> dist(s);
    Points<> Q(300, 3);
    for (Index i = 0; i < Q.size(); ++i) Q.data()[i] = 1.5 * n(rng);
    const VecX<> d_seq = dist.distances(exec::seq, Q), d_omp = dist.distances(exec::omp, Q);
    CHECK(d_seq == d_omp);
    for (Index i = 0; i < Q.rows(); ++i) {
      Index tri = -1;
      const double want = brute_surface_distance(s, Q.row(i).transpose(), &tri);
      const auto hit = dist.closest(Q.row(i).transpose());
      CHECK(hit.distance == doctest::Approx(want).epsilon(1e-12));
      CHECK(d_seq[i] == hit.distance);
      const Vec3<> p = hit.barycentric[0] * s.V.row(s.F(hit.triangle, 0)).transpose() + hit.barycentric[1] * s.V.row(s.F(hit.triangle, 1)).transpose() +
                       hit.barycentric[2] * s.V.row(s.F(hit.triangle, 2)).transpose();
      CHECK((p - Q.row(i).transpose()).norm() == doctest::Approx(want).epsilon(1e-12));
    }
  }
}

TEST_CASE("SurfaceDistance: bad surfaces and queries are named") {
  TriMesh<> s = icosphere<double>(1, 1.0);
  TriMesh<> empty;
  empty.V = s.V;
  CHECK_THROWS_WITH_AS(neighbors::SurfaceDistance<>{empty}, doctest::Contains("no triangles"), ArgumentError);
  TriMesh<> bad = s;
  bad.F(3, 1) = VIndex(bad.V.rows());
  CHECK_THROWS_WITH_AS(neighbors::SurfaceDistance<>{bad}, doctest::Contains("outside [0,"), ArgumentError);
  const neighbors::SurfaceDistance<> dist(s);
  CHECK_THROWS_AS(dist.closest(Vec3<>(std::nan(""), 0, 0)), ArgumentError);
}
