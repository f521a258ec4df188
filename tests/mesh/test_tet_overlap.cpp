#include <doctest/doctest.h>

#include <simsr/mesh/tet_overlap.hpp>

#include <random>

namespace mesh_test_tet_overlap {

using namespace simsr;

namespace {

/// Independent check: tets a and b share interior volume iff the origin lies strictly inside the
/// convex hull of the 16 differences a_i − b_j (their Minkowski difference). The hull's facets are
/// found by brute force over all point triples (a plane with every point on one side), and the
/// origin must be on the inner side of each, by more than `margin`.
bool overlap_by_minkowski(const TetCorners<double>& a, const TetCorners<double>& b, double margin) {
  std::vector<Vec3<double>> p;
  for (const auto& x : a)
    for (const auto& y : b) p.push_back(x - y);
  bool any_facet = false;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      for (std::size_t k = j + 1; k < p.size(); ++k) {
        Vec3<double> n = (p[j] - p[i]).cross(p[k] - p[i]);
        if (n.norm() < 1e-12) continue;
        n.normalize();
        double lo = 1e300, hi = -1e300;
        for (const auto& q : p) {
          lo = std::min(lo, n.dot(q - p[i]));
          hi = std::max(hi, n.dot(q - p[i]));
        }
        if (lo < -1e-12 && hi > 1e-12) continue;  // not a supporting plane
        any_facet = true;
        const double o = n.dot(-p[i]);            // the origin's side
        if (hi <= 1e-12 ? o >= -margin : o <= margin) return false;
      }
  return any_facet;
}

TetCorners<double> random_tet(std::mt19937& rng, double spread) {
  std::uniform_real_distribution<double> u(-spread, spread);
  for (;;) {
    TetCorners<double> t;
    for (auto& c : t) c = Vec3<double>(u(rng), u(rng), u(rng));
    if (std::abs((t[1] - t[0]).dot((t[2] - t[0]).cross(t[3] - t[0]))) > 1e-3 * spread * spread * spread) return t;
  }
}

}  // namespace

TEST_CASE("tets_overlap agrees with the Minkowski-difference hull on random pairs") {
  std::mt19937 rng(7);
  Index overlapping = 0, disjoint = 0, undecided = 0;
  for (int trial = 0; trial < 1500; ++trial) {
    auto a = random_tet(rng, 1.0), b = random_tet(rng, 1.0);
    const Vec3<double> shift(std::uniform_real_distribution<double>(-1.5, 1.5)(rng), 0, 0);
    for (auto& c : b) c += shift;
    const bool strict_in = overlap_by_minkowski(a, b, 1e-9);   // origin clearly inside
    const bool loose_in = overlap_by_minkowski(a, b, -1e-9);   // inside or on the hull
    if (strict_in != loose_in) {
      ++undecided;  // touching within round-off: either answer is right
      continue;
    }
    CAPTURE(trial);
    CHECK(tets_overlap(a, b) == strict_in);
    CHECK(tets_overlap(b, a) == strict_in);
    (strict_in ? overlapping : disjoint) += 1;
  }
  CHECK(overlapping > 300);
  CHECK(disjoint > 300);
  CHECK(undecided < 5);
}

TEST_CASE("tets that only touch do not overlap; nested and identical tets do") {
  const TetCorners<double> a{Vec3<double>(0, 0, 0), Vec3<double>(1, 0, 0), Vec3<double>(0, 1, 0), Vec3<double>(0, 0, 1)};
  // mirrored across the face x + y + z = 1: shares that face only
  TetCorners<double> m = a;
  m[0] = Vec3<double>(2.0 / 3, 2.0 / 3, 2.0 / 3);
  CHECK_FALSE(tets_overlap(a, m, 1e-12));
  // mirrored across z = 0 (shares the face on z = 0)
  TetCorners<double> z = a;
  z[3] = Vec3<double>(0, 0, -1);
  CHECK_FALSE(tets_overlap(a, z, 1e-12));
  // touching at a vertex
  TetCorners<double> v = a;
  for (auto& c : v) c += Vec3<double>(1, 0, 0);
  CHECK_FALSE(tets_overlap(a, v, 1e-12));
  // sharing an edge, on opposite sides
  const TetCorners<double> e{Vec3<double>(0, 0, 0), Vec3<double>(0, 0, 1), Vec3<double>(-1, -1, 0), Vec3<double>(-1, 0, 0)};
  CHECK_FALSE(tets_overlap(a, e, 1e-12));
  CHECK(tets_overlap(a, a));
  TetCorners<double> inner = a;
  const Vec3<double> c = (a[0] + a[1] + a[2] + a[3]) / 4;
  for (auto& p : inner) p = c + 0.1 * (p - c);
  CHECK(tets_overlap(a, inner));
  CHECK(tets_overlap(inner, a));
  // slightly pushed through the shared face: overlap
  TetCorners<double> through = m;
  through[0] = Vec3<double>(0.3, 0.3, 0.3);
  CHECK(tets_overlap(a, through, 1e-12));
  // a flat tet overlaps nothing
  TetCorners<double> flat = a;
  flat[3] = Vec3<double>(0.2, 0.2, 0);
  CHECK_FALSE(tets_overlap(a, flat));
}

}  // namespace mesh_test_tet_overlap
