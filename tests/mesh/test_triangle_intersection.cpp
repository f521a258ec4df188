#include <doctest/doctest.h>

#include <simsr/mesh/triangle_intersection.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

namespace mesh_test_triangle_intersection {

using namespace simsr;

namespace {

using Tri = std::array<Vec3<double>, 3>;

/// A point with coordinates in 1/256 (dyadic, so exactly on the default grid; all cases stay
/// within the ±0.25 the default quantum 2^-40 allows).
Vec3<double> P(double x, double y, double z) { return Vec3<double>(x, y, z) / 256.0; }

bool meet(const Tri& a, const Tri& b, double quantum = 0x1p-40) {
  return triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2], quantum);
}

/// The answer for a and b, checked to be the same for all 6 × 6 corner orders and both argument orders.
bool meet_all_orders(Tri a, Tri b) {
  const bool expected = meet(a, b);
  std::array<int, 3> pa{0, 1, 2};
  do {
    std::array<int, 3> pb{0, 1, 2};
    do {
      const Tri a2{a[pa[0]], a[pa[1]], a[pa[2]]}, b2{b[pb[0]], b[pb[1]], b[pb[2]]};
      CHECK(meet(a2, b2) == expected);
      CHECK(meet(b2, a2) == expected);
    } while (std::next_permutation(pb.begin(), pb.end()));
  } while (std::next_permutation(pa.begin(), pa.end()));
  return expected;
}

Tri shifted(Tri t, const Vec3<double>& d) {
  for (auto& v : t) v += d;
  return t;
}

constexpr double q = 0x1p-40;  // the default quantum

}  // namespace

TEST_CASE("triangles_intersect: hand-made configurations in general position") {
  const Tri a{P(0, 0, 0), P(8, 0, 0), P(0, 8, 0)};
  SUBCASE("one pierces the other") {
    CHECK(meet_all_orders(a, Tri{P(2, 2, -4), P(3, 2, 4), P(2, 3, 4)}));
    // a thin triangle through the middle, no corner of either inside the other
    CHECK(meet_all_orders(a, Tri{P(-2, 2, -1), P(10, 2, -1), P(2, 2, 5)}));
  }
  SUBCASE("parallel planes") {
    CHECK_FALSE(meet_all_orders(a, shifted(a, P(0, 0, 1))));
    CHECK_FALSE(meet_all_orders(a, shifted(a, Vec3<double>(0, 0, q))));  // one quantum apart
  }
  SUBCASE("a vertex on the other's face, and one quantum off it") {
    const Tri b{P(2, 2, 0), P(3, 2, 4), P(2, 3, 4)};
    CHECK(meet_all_orders(a, b));
    CHECK_FALSE(meet_all_orders(a, shifted(b, Vec3<double>(0, 0, q))));
    CHECK(meet_all_orders(a, shifted(b, Vec3<double>(0, 0, -q))));
  }
  SUBCASE("edges crossing at a single point, and one quantum off it") {
    // b lies in the plane x = 4, where it is {y + z <= 0, y >= -2, z >= -2}; a meets that plane in
    // {(4, y, 0): 0 <= y <= 4}: the two share only (4, 0, 0), on an edge of each
    const Tri b{P(4, -2, 2), P(4, 2, -2), P(4, -2, -2)};
    CHECK(meet_all_orders(a, b));
    CHECK_FALSE(meet_all_orders(a, shifted(b, Vec3<double>(0, -q, 0))));
    CHECK(meet_all_orders(a, shifted(b, Vec3<double>(0, q, 0))));
    // skew edges through one point: a's edge along x, b's edge along y at height 0, b tilted
    const Tri c{P(4, -2, 0), P(4, 6, 0), P(4, 2, 5)};
    CHECK(meet_all_orders(Tri{P(0, 0, 0), P(8, 0, 0), P(4, 0, -6)}, c));
    CHECK_FALSE(meet_all_orders(Tri{P(0, 0, 0), P(8, 0, 0), P(4, 0, -6)}, shifted(c, Vec3<double>(0, 0, q))));
  }
  SUBCASE("edges overlapping collinearly, planes different") {
    CHECK(meet_all_orders(a, Tri{P(4, 0, 0), P(12, 0, 0), P(4, 0, 8)}));
    CHECK(meet_all_orders(a, Tri{P(8, 0, 0), P(12, 0, 0), P(8, 0, 8)}));  // corner to corner
    CHECK_FALSE(meet_all_orders(a, shifted(Tri{P(8, 0, 0), P(12, 0, 0), P(8, 0, 8)}, Vec3<double>(q, 0, 0))));
  }
}

TEST_CASE("triangles_intersect: coplanar configurations, in several planes") {
  // (u, v) -> a point of one of five planes, exactly (integer maps of dyadic coordinates)
  const std::array<Vec3<double> (*)(double, double), 5> plane{
      [](double u, double v) { return P(u, v, 0); },
      [](double u, double v) { return P(0, u, v); },
      [](double u, double v) { return P(v, 0, u); },
      [](double u, double v) { return P(u, v, u + 2 * v); },
      [](double u, double v) { return P(3 * u + v, u - v, 2 * v); },
  };
  for (std::size_t k = 0; k < plane.size(); ++k) {
    CAPTURE(k);
    auto tri = [&](double u0, double v0, double u1, double v1, double u2, double v2) {
      return Tri{plane[k](u0, v0), plane[k](u1, v1), plane[k](u2, v2)};
    };
    const Tri a = tri(0, 0, 8, 0, 0, 8);
    CHECK(meet_all_orders(a, tri(2, 2, 10, 2, 2, 10)));         // overlapping
    CHECK(meet_all_orders(a, tri(-2, 3, 10, 3, 10, 4)));        // edges crossing, no corner inside
    CHECK_FALSE(meet_all_orders(a, tri(9, 0, 17, 0, 9, 8)));    // disjoint, side by side
    CHECK_FALSE(meet_all_orders(a, tri(5, 5, 9, 5, 5, 9)));     // disjoint, bounding boxes overlap
    CHECK(meet_all_orders(a, tri(4, 4, 8, 4, 4, 8)));           // a corner on the hypotenuse
    CHECK(meet_all_orders(a, tri(1, 1, 2, 1, 1, 2)));           // one inside the other
    CHECK(meet_all_orders(a, a));                               // identical
    CHECK(meet_all_orders(a, tri(0, 0, -8, 0, 0, -8)));         // sharing only a vertex
    CHECK(meet_all_orders(a, tri(8, 0, 16, 0, 8, -4)));         // sharing a vertex, touching along nothing else
    CHECK(meet_all_orders(a, tri(2, 0, 6, 0, 4, -4)));          // collinear edge overlap
    CHECK_FALSE(meet_all_orders(a, tri(9, 0, 12, 0, 10, -4)));  // collinear edges, apart
  }
}

TEST_CASE("triangles_intersect: degenerate triangles are segments and points") {
  const Tri a{P(0, 0, 0), P(8, 0, 0), P(0, 8, 0)};
  const Tri seg_through{P(2, 2, -4), P(2, 2, 4), P(2, 2, 0)};  // collinear corners: a segment
  CHECK(meet_all_orders(a, seg_through));
  CHECK_FALSE(meet_all_orders(a, Tri{P(2, 2, 1), P(2, 2, 4), P(2, 2, 2)}));
  CHECK(meet_all_orders(a, Tri{P(2, 2, 0), P(2, 2, 0), P(2, 2, 0)}));        // a point on the face
  CHECK(meet_all_orders(a, Tri{P(8, 0, 0), P(8, 0, 0), P(8, 0, 0)}));        // a point at a corner
  CHECK_FALSE(meet_all_orders(a, Tri{P(5, 5, 0), P(5, 5, 0), P(5, 5, 0)}));  // a point beside it
  CHECK(meet_all_orders(a, Tri{P(-2, 1, 0), P(10, 1, 0), P(4, 1, 0)}));      // a segment in the plane
  CHECK_FALSE(meet_all_orders(a, Tri{P(5, 5, 0), P(9, 9, 0), P(7, 7, 0)}));
  // segment against segment and point
  const Tri s{P(0, 0, 0), P(8, 8, 8), P(4, 4, 4)};
  CHECK(meet_all_orders(s, Tri{P(0, 8, 0), P(8, 0, 8), P(2, 6, 2)}));        // crossing at (4, 4, 4)
  CHECK_FALSE(meet_all_orders(s, Tri{P(0, 8, 1), P(8, 0, 9), P(2, 6, 3)}));  // skew
  CHECK(meet_all_orders(s, Tri{P(6, 6, 6), P(12, 12, 12), P(9, 9, 9)}));     // collinear overlap
  CHECK_FALSE(meet_all_orders(s, Tri{P(9, 9, 9), P(12, 12, 12), P(10, 10, 10)}));
  CHECK(meet_all_orders(s, Tri{P(2, 2, 2), P(2, 2, 2), P(2, 2, 2)}));
  CHECK_FALSE(meet_all_orders(s, Tri{P(2, 2, 3), P(2, 2, 3), P(2, 2, 3)}));
  CHECK(meet_all_orders(Tri{P(1, 2, 3), P(1, 2, 3), P(1, 2, 3)}, Tri{P(1, 2, 3), P(1, 2, 3), P(1, 2, 3)}));
  CHECK_FALSE(meet_all_orders(Tri{P(1, 2, 3), P(1, 2, 3), P(1, 2, 3)}, Tri{P(1, 2, 4), P(1, 2, 4), P(1, 2, 4)}));
}

TEST_CASE("triangles_intersect: argument errors") {
  const Vec3<double> o = Vec3<double>::Zero(), x = Vec3<double>::UnitX() * 0.1, y = Vec3<double>::UnitY() * 0.1;
  const Vec3<double> nan(0, std::numeric_limits<double>::quiet_NaN(), 0);
  CHECK_THROWS_WITH_AS(triangles_intersect(o, x, y, o, nan, y), doctest::Contains("b corner 1[1]"), ArgumentError);
  CHECK_THROWS_WITH_AS(triangles_intersect(o, x, y, o, nan, y), doctest::Contains("not finite"), ArgumentError);
  const Vec3<double> far(0, 0, 0.5);  // 2^39 quanta of 2^-40
  CHECK_THROWS_WITH_AS(triangles_intersect(o, x, far, o, x, y), doctest::Contains("a corner 2[2]"), ArgumentError);
  CHECK(triangles_intersect(o, x, far, o, x, y, 0x1p-30));
  CHECK_THROWS_AS(triangles_intersect(o, x, y, o, x, y, 0.0), ArgumentError);
}

namespace {

/// A point with coordinates drawn one at a time, multiples of 2^-22 in [-range, range] · 2^-22.
Vec3<double> draw_point(std::mt19937& rng, std::int64_t range) {
  std::uniform_int_distribution<std::int64_t> u(-range, range);
  Vec3<double> p;
  for (int k = 0; k < 3; ++k) p[k] = double(u(rng)) * 0x1p-22;
  return p;
}

Tri draw_triangle(std::mt19937& rng, std::int64_t center_range, std::int64_t size) {
  const Vec3<double> c = draw_point(rng, center_range);
  Tri t;
  for (auto& v : t) v = c + draw_point(rng, size);
  return t;
}

/// Möller–Trumbore for segment pq against triangle abc: the smallest of t, 1 − t, u, v, 1 − u − v
/// (> 0: the segment clearly crosses the triangle; < 0: clearly misses), or NaN when pq is
/// nearly parallel to the plane (no clear answer).
double crossing_margin(const Vec3<double>& p, const Vec3<double>& q, const Tri& tri) {
  const Vec3<double> e1 = tri[1] - tri[0], e2 = tri[2] - tri[0], d = q - p;
  const Vec3<double> h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-4 * e1.cross(e2).norm() * d.norm()) return std::numeric_limits<double>::quiet_NaN();
  const Vec3<double> s = p - tri[0], sq = s.cross(e1);
  const double u = s.dot(h) / det, v = d.dot(sq) / det, t = e2.dot(sq) / det;
  return std::min({t, 1 - t, u, v, 1 - u - v});
}

/// Floating-point reference: +1 clearly intersecting, −1 clearly disjoint, 0 ambiguous (an edge
/// within 1e-9 of touching, or nearly parallel to the other's plane).
int reference(const Tri& a, const Tri& b) {
  constexpr double eps = 1e-9;
  bool ambiguous = false;
  const Tri* both[2] = {&a, &b};
  for (int s = 0; s < 2; ++s) {
    const Tri& e = *both[s];
    const Tri& t = *both[1 - s];
    for (int i = 0; i < 3; ++i) {
      const double m = crossing_margin(e[i], e[(i + 1) % 3], t);
      if (m > eps) return 1;
      if (!(m < -eps)) ambiguous = true;
    }
  }
  return ambiguous ? 0 : -1;
}

/// A unit axis among the 2 normals and 9 edge cross products along which b lies beyond a by more
/// than 1e-9 (oriented from a to b), or zero when there is none.
Vec3<double> separating_axis(const Tri& a, const Tri& b) {
  std::vector<Vec3<double>> axes{(a[1] - a[0]).cross(a[2] - a[0]), (b[1] - b[0]).cross(b[2] - b[0])};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) axes.push_back((a[(i + 1) % 3] - a[i]).cross(b[(j + 1) % 3] - b[j]));
  for (Vec3<double> n : axes) {
    if (n.norm() < 1e-12) continue;
    n.normalize();
    double alo = 1e300, ahi = -1e300, blo = 1e300, bhi = -1e300;
    for (int i = 0; i < 3; ++i) {
      alo = std::min(alo, n.dot(a[i]));
      ahi = std::max(ahi, n.dot(a[i]));
      blo = std::min(blo, n.dot(b[i]));
      bhi = std::max(bhi, n.dot(b[i]));
    }
    if (blo > ahi + 1e-9) return n;
    if (alo > bhi + 1e-9) return -n;
  }
  return Vec3<double>::Zero();
}

}  // namespace

TEST_CASE("triangles_intersect agrees with a floating-point reference on random pairs") {
  std::mt19937 rng(20240611);
  std::uniform_int_distribution<int> scale_exponent(-16, 0);
  std::uniform_int_distribution<int> rotate(0, 2);
  const int pairs = 20000;
  int intersecting = 0, disjoint = 0, skipped = 0, translated_apart = 0;
  for (int trial = 0; trial < pairs; ++trial) {
    // b drawn around a point of a (so that about half the pairs meet); coordinates are multiples
    // of 2^-24 within ±0.125, exactly on the 2^-40 grid even when scaled by 2^-16
    const Tri a = draw_triangle(rng, 0x20000, 0x40000);
    Tri b;
    for (auto& v : b) v = (a[0] + a[1] + 2 * a[2]) / 4 + draw_point(rng, 0x40000);
    CAPTURE(trial);
    const bool exact = meet(a, b);
    const int ref = reference(a, b);
    if (ref == 0) {
      ++skipped;
    } else {
      CHECK(exact == (ref > 0));
      (ref > 0 ? intersecting : disjoint) += 1;
    }
    // symmetric and independent of corner order
    const int r = rotate(rng);
    const Tri b_rot{b[r], b[(r + 1) % 3], b[(r + 2) % 3]}, a_rev{a[2], a[1], a[0]};
    CHECK(meet(b_rot, a_rev) == exact);
    // moved together by a grid vector, scaled by 2^k (still on the grid), or on a coarser grid
    const Vec3<double> shift = draw_point(rng, 0x20000);
    CHECK(meet(shifted(a, shift), shifted(b, shift)) == exact);
    const double s = std::ldexp(1.0, scale_exponent(rng));
    CHECK(meet(Tri{a[0] * s, a[1] * s, a[2] * s}, Tri{b[0] * s, b[1] * s, b[2] * s}) == exact);
    CHECK(meet(Tri{a[0] * 256, a[1] * 256, a[2] * 256}, Tri{b[0] * 256, b[1] * 256, b[2] * 256}, 0x1p-32) == exact);
    // a disjoint pair moved apart (b by a random vector with a non-negative component along a
    // separating axis) stays disjoint
    if (!exact) {
      const Vec3<double> n = separating_axis(a, b);
      if (n.squaredNorm() > 0) {
        Vec3<double> v = draw_point(rng, 0x20000);
        if (v.dot(n) < 0) v = -v;
        CHECK_FALSE(meet(a, shifted(b, v)));
        ++translated_apart;
      }
    }
  }
  MESSAGE("intersecting " << intersecting << ", disjoint " << disjoint << ", skipped " << skipped
                          << ", translated apart " << translated_apart);
  CHECK(intersecting > pairs / 4);
  CHECK(disjoint > pairs / 4);
  CHECK(skipped < pairs / 200);
  CHECK(translated_apart > disjoint * 9 / 10);
}

namespace {

/// All intersecting pairs by brute force, skipping pairs that share a vertex index.
std::vector<std::pair<Index, Index>> brute_force_pairs(const Points<>& X, const Tris& A, const Tris& B) {
  std::vector<std::pair<Index, Index>> out;
  for (Index i = 0; i < A.rows(); ++i)
    for (Index j = 0; j < B.rows(); ++j) {
      bool shared = false;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) shared = shared || A(i, r) == B(j, c);
      if (shared) continue;
      const Vec3<double> a0 = X.row(A(i, 0)).transpose(), a1 = X.row(A(i, 1)).transpose(), a2 = X.row(A(i, 2)).transpose();
      const Vec3<double> b0 = X.row(B(j, 0)).transpose(), b1 = X.row(B(j, 1)).transpose(), b2 = X.row(B(j, 2)).transpose();
      if (triangles_intersect(a0, a1, a2, b0, b1, b2)) out.emplace_back(i, j);
    }
  return out;
}

/// n triangles over V vertices: each takes a vertex and two others at most `reach` indices after
/// it (reach = V: anywhere), all distinct.
Tris random_tris(std::mt19937& rng, Index n, VIndex V, VIndex reach) {
  std::uniform_int_distribution<VIndex> first(0, V - 1), offset(1, reach - 1);
  Tris T(n, 3);
  for (Index f = 0; f < n; ++f) {
    const VIndex i = first(rng);
    VIndex j = 0, k = 0;
    do {
      j = (i + offset(rng)) % V;
      k = (i + offset(rng)) % V;
    } while (j == k);
    T(f, 0) = i;
    T(f, 1) = j;
    T(f, 2) = k;
  }
  return T;
}

}  // namespace

TEST_CASE("intersecting_triangle_pairs matches brute force on random soups") {
  std::mt19937 rng(5);
  // vertices along a random walk in a ±0.2 box, so nearby indices are nearby points and the walk
  // comes back on itself
  const VIndex V = 600;
  Points<> X(V, 3);
  std::uniform_int_distribution<std::int64_t> step(-0x8000, 0x8000);
  std::array<std::int64_t, 3> g{0, 0, 0};
  for (VIndex v = 0; v < V; ++v) {
    for (int k = 0; k < 3; ++k) {
      g[k] += step(rng);
      g[k] = std::clamp<std::int64_t>(g[k], -0xC0000, 0xC0000);
      X(v, k) = double(g[k]) * 0x1p-22;
    }
  }
  for (const VIndex reach : {VIndex(6), V}) {
    CAPTURE(reach);
    const Tris A = random_tris(rng, reach == V ? 60 : 400, V, reach);
    const Tris B = random_tris(rng, reach == V ? 60 : 400, V, reach);
    const auto pairs = intersecting_triangle_pairs(X, A, B);
    MESSAGE("reach " << reach << ": " << pairs.size() << " intersecting pairs");
    CHECK(pairs == brute_force_pairs(X, A, B));
    CHECK(pairs.size() > 5);
    CHECK(std::is_sorted(pairs.begin(), pairs.end()));
    // pairs sharing a vertex touch, and are left out
    Index shared = 0;
    for (Index i = 0; i < A.rows(); ++i)
      for (Index j = 0; j < B.rows(); ++j)
        if (A(i, 0) == B(j, 0) || A(i, 0) == B(j, 1) || A(i, 0) == B(j, 2)) {
          ++shared;
          CHECK(std::find(pairs.begin(), pairs.end(), std::make_pair(i, j)) == pairs.end());
        }
    CHECK(shared > 0);
    // one soup against itself: every intersecting pair of distinct, vertex-disjoint triangles, both ways
    const auto self = intersecting_triangle_pairs(X, A, A);
    CHECK(self == brute_force_pairs(X, A, A));
    for (const auto& [i, j] : self) CHECK(std::binary_search(self.begin(), self.end(), std::make_pair(j, i)));
  }
  CHECK(intersecting_triangle_pairs(X, Tris(0, 3), Tris(0, 3)).empty());
}

TEST_CASE("intersecting_triangle_pairs: argument errors") {
  Points<> X(4, 3);
  X << 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1;
  Tris A(2, 3), B(1, 3);
  A << 0, 1, 2, 0, 1, 3;
  B << 1, 2, 3;
  CHECK_NOTHROW(intersecting_triangle_pairs(X, A, B));
  Tris bad = A;
  bad(1, 2) = 4;
  CHECK_THROWS_WITH_AS(intersecting_triangle_pairs(X, bad, B), doctest::Contains("A row 1"), ArgumentError);
  bad(1, 2) = -1;
  CHECK_THROWS_WITH_AS(intersecting_triangle_pairs(X, A, bad), doctest::Contains("B row 1"), ArgumentError);
  Points<> Y = X;
  Y(3, 2) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH_AS(intersecting_triangle_pairs(Y, A, B), doctest::Contains("X(3, 2)"), ArgumentError);
  Tris A0 = A.topRows(1);
  Tris B0(1, 3);
  B0 << 0, 1, 2;
  CHECK_NOTHROW(intersecting_triangle_pairs(Y, A0, B0));  // vertex 3 unused: not checked
  Y(3, 2) = 1.0;                                          // 2^40 quanta
  CHECK_THROWS_WITH_AS(intersecting_triangle_pairs(Y, A, B), doctest::Contains("X(3, 2)"), ArgumentError);
  CHECK_NOTHROW(intersecting_triangle_pairs(Y, A, B, 0x1p-36));
}

}  // namespace mesh_test_triangle_intersection
