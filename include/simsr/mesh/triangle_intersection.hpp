#pragma once
/// \file
/// Do two closed triangles in 3D meet? An exact answer: the corners are first rounded to a grid
/// of spacing `quantum` (integers of at most 2^38 in magnitude), and every predicate after that
/// (orient3d, orient2d, comparisons) is evaluated exactly in `__int128`. So the answer is exact
/// for the rounded triangles, whatever their shape: touching at a single point counts as meeting,
/// and triangles that lose their area in the rounding are treated as the segment or point they
/// became. Rounding moves a corner by at most quantum/2 per coordinate (2^-41 by default).
///
/// Algorithm (Guigue & Devillers 2003 in spirit, without their case tables):
///  * Two triangles in different planes meet iff an edge of one meets the other (closed)
///    triangle: their intersection lies on the line where the planes cross, and is the overlap of
///    two intervals of that line, so its endpoints lie on edges of the triangles.
///  * Segment pq against triangle abc: with p and q strictly on one side of the plane of abc
///    (signs of orient3d(a,b,c,·)) they miss. With pq in the plane, see "coplanar" below.
///    Otherwise pq crosses or touches the plane in one point, and that point lies in the closed
///    triangle iff orient3d(p,q,a,b), orient3d(p,q,b,c), orient3d(p,q,c,a) do not have strictly
///    opposite signs (Plücker: the line passes on the same side of all three edges).
///  * Coplanar: project onto the axis plane that drops the largest component of the triangle's
///    exact normal (projection is then one-to-one on the plane) and test in 2D: some pair of
///    closed edges meets (crossing, touching or overlapping collinearly), or a corner of one lies
///    in the other (the containment case).
///  * Segments and points (degenerate triangles) against each other: they meet iff they are
///    coplanar and their projections meet on all three axis planes (necessary, and sufficient
///    because at least one of the three projections is one-to-one on their common plane).
///
///     bool meet = simsr::triangles_intersect(a0, a1, a2, b0, b1, b2);
///     auto pairs = simsr::intersecting_triangle_pairs(X, lips_upper, lips_lower);  // (row of A, row of B)

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"

namespace simsr {

/// A point of the integer grid (corner coordinates divided by the quantum and rounded).
using GridPoint = std::array<std::int64_t, 3>;

namespace detail {

__extension__ typedef __int128 Int128;

/// Largest |coordinate| / quantum accepted. Bit budget: grid coordinates ≤ 2^38, so differences
/// ≤ 2^39; a 2×2 minor ≤ 2·2^78; an orient3d determinant is a sum of 3 products of a difference
/// and a minor, each ≤ 2^118, total < 2^120 (equivalently 6 terms ≤ 2^117 each); normals and
/// squared lengths ≤ 3·2^78; orient2d ≤ 2^79. All far below the 2^127 of `__int128`.
inline constexpr double grid_limit = 0x1p38;

inline std::int64_t quantize(double x, double quantum, const std::string& what) {
  if (!std::isfinite(x)) throw ArgumentError(what + " = " + std::to_string(x) + " is not finite");
  if (std::abs(x) / quantum > grid_limit)
    throw ArgumentError(what + " = " + std::to_string(x) + " exceeds 2^38 quanta (quantum " + std::to_string(quantum) +
                        "): pass a larger quantum");
  return std::llround(x / quantum);
}

inline void check_quantum(double quantum, const char* where) {
  if (!(quantum > 0) || !std::isfinite(quantum))
    throw ArgumentError(std::string(where) + ": quantum must be positive and finite, got " + std::to_string(quantum));
}

inline int sign(Int128 v) { return (v > 0) - (v < 0); }

/// Sign of det[b − a, c − a, d − a]: which side of plane abc the point d lies on (0: in it).
inline int orient3d(const GridPoint& a, const GridPoint& b, const GridPoint& c, const GridPoint& d) {
  const Int128 bx = b[0] - a[0], by = b[1] - a[1], bz = b[2] - a[2];
  const Int128 cx = c[0] - a[0], cy = c[1] - a[1], cz = c[2] - a[2];
  const Int128 dx = d[0] - a[0], dy = d[1] - a[1], dz = d[2] - a[2];
  return sign(bx * (cy * dz - cz * dy) - by * (cx * dz - cz * dx) + bz * (cx * dy - cy * dx));
}

using Point2 = std::array<std::int64_t, 2>;

/// Sign of the 2D cross product (b − a) × (c − a).
inline int orient2d(const Point2& a, const Point2& b, const Point2& c) {
  return sign(Int128(b[0] - a[0]) * (c[1] - a[1]) - Int128(b[1] - a[1]) * (c[0] - a[0]));
}

/// c (known to lie on the line ab, or a == b) within the bounding box of a and b.
inline bool in_box(const Point2& a, const Point2& b, const Point2& c) {
  return std::min(a[0], b[0]) <= c[0] && c[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= c[1] &&
         c[1] <= std::max(a[1], b[1]);
}

/// Closed segments pq and rs meet (either may be a single point: p == q).
inline bool segments_meet_2d(const Point2& p, const Point2& q, const Point2& r, const Point2& s) {
  const int o1 = orient2d(p, q, r), o2 = orient2d(p, q, s), o3 = orient2d(r, s, p), o4 = orient2d(r, s, q);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;  // proper crossing
  return (o1 == 0 && in_box(p, q, r)) || (o2 == 0 && in_box(p, q, s)) || (o3 == 0 && in_box(r, s, p)) ||
         (o4 == 0 && in_box(r, s, q));
}

/// p in the closed triangle abc (which must have nonzero area).
inline bool in_triangle_2d(const Point2& a, const Point2& b, const Point2& c, const Point2& p) {
  const int o1 = orient2d(a, b, p), o2 = orient2d(b, c, p), o3 = orient2d(c, a, p);
  return !((o1 < 0 || o2 < 0 || o3 < 0) && (o1 > 0 || o2 > 0 || o3 > 0));
}

/// The convex hulls of P[0..np) and Q[0..nq) (1 to 3 points each, degenerate allowed) meet.
inline bool hulls_meet_2d(const Point2* P, int np, const Point2* Q, int nq) {
  const int ep = np == 3 ? 3 : 1, eq = nq == 3 ? 3 : 1;  // 1 or 2 points: one (possibly zero-length) edge
  for (int i = 0; i < ep; ++i)
    for (int j = 0; j < eq; ++j)
      if (segments_meet_2d(P[i], P[(i + 1) % np], Q[j], Q[(j + 1) % nq])) return true;
  if (np == 3 && orient2d(P[0], P[1], P[2]) != 0 && in_triangle_2d(P[0], P[1], P[2], Q[0])) return true;
  if (nq == 3 && orient2d(Q[0], Q[1], Q[2]) != 0 && in_triangle_2d(Q[0], Q[1], Q[2], P[0])) return true;
  return false;
}

/// Drop coordinate `axis`.
inline Point2 project(const GridPoint& p, int axis) { return {p[(axis + 1) % 3], p[(axis + 2) % 3]}; }

}  // namespace detail

/// A triangle on the integer grid, reduced to the simplex its corners span: `size` 3 (a triangle
/// with nonzero area), 2 (collinear corners: the segment between the two farthest apart) or 1
/// (all corners equal). `p[0..size)` are the corners kept; `drop` is the axis of the largest
/// component of the exact normal (triangles only), the one the coplanar tests project away.
/// Built from grid points directly, their coordinates must lie within ±2^38 (not checked: the
/// bit budget above); `quantized` rounds and checks double corners.
struct ExactTriangle {
  std::array<GridPoint, 3> p{};
  int size = 0;
  int drop = 0;

  ExactTriangle() = default;
  ExactTriangle(const GridPoint& a, const GridPoint& b, const GridPoint& c) : p{a, b, c}, size(3) {
    using detail::Int128;
    Int128 n[3];
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      n[k] = Int128(b[i] - a[i]) * (c[j] - a[j]) - Int128(b[j] - a[j]) * (c[i] - a[i]);
    }
    auto abs = [](Int128 v) { return v < 0 ? -v : v; };
    if (n[0] != 0 || n[1] != 0 || n[2] != 0) {
      drop = abs(n[0]) >= abs(n[1]) ? (abs(n[0]) >= abs(n[2]) ? 0 : 2) : (abs(n[1]) >= abs(n[2]) ? 1 : 2);
      return;
    }
    // collinear: keep the farthest pair (their segment is the hull); all equal: a point
    auto dist2 = [](const GridPoint& u, const GridPoint& v) {
      Int128 s = 0;
      for (int k = 0; k < 3; ++k) s += Int128(u[k] - v[k]) * (u[k] - v[k]);
      return s;
    };
    const Int128 dab = dist2(a, b), dbc = dist2(b, c), dca = dist2(c, a);
    if (dab == 0 && dbc == 0) {
      size = 1;
    } else {
      size = 2;
      if (dbc >= dab && dbc >= dca)
        p = {b, c, c};
      else if (dca >= dab)
        p = {c, a, a};
    }
  }

  /// Corners rounded to multiples of `quantum` (ArgumentError naming the coordinate, by `name`,
  /// when one is not finite or exceeds 2^38 quanta).
  static ExactTriangle quantized(const Vec3<double>& a, const Vec3<double>& b, const Vec3<double>& c, double quantum,
                                 const std::string& name = "triangle") {
    detail::check_quantum(quantum, "ExactTriangle::quantized");
    const Vec3<double>* v[3] = {&a, &b, &c};
    GridPoint g[3];
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        g[i][k] = detail::quantize((*v[i])[k], quantum, name + " corner " + std::to_string(i) + "[" + std::to_string(k) + "]");
    return ExactTriangle(g[0], g[1], g[2]);
  }
};

namespace detail {

/// s and t are coplanar and s is a proper triangle: test in the projection that drops s.drop.
inline bool coplanar_meet(const ExactTriangle& s, const ExactTriangle& t) {
  Point2 P[3], Q[3];
  for (int i = 0; i < s.size; ++i) P[i] = project(s.p[i], s.drop);
  for (int i = 0; i < t.size; ++i) Q[i] = project(t.p[i], s.drop);
  return hulls_meet_2d(P, s.size, Q, t.size);
}

/// Segment pq against the proper triangle t; sp, sq are orient3d(t, p), orient3d(t, q).
inline bool segment_meets_triangle(const GridPoint& p, const GridPoint& q, int sp, int sq, const ExactTriangle& t) {
  if (sp * sq > 0) return false;  // strictly on one side
  if (sp == 0 && sq == 0) return coplanar_meet(t, ExactTriangle(p, q, q));
  const int o1 = orient3d(p, q, t.p[0], t.p[1]), o2 = orient3d(p, q, t.p[1], t.p[2]), o3 = orient3d(p, q, t.p[2], t.p[0]);
  return !((o1 < 0 || o2 < 0 || o3 < 0) && (o1 > 0 || o2 > 0 || o3 > 0));
}

}  // namespace detail

/// True when the closed simplices s and t share a point (exactly; see the file comment).
inline bool triangles_intersect(const ExactTriangle& s0, const ExactTriangle& t0) {
  using detail::orient3d;
  const bool swap = s0.size < t0.size;
  const ExactTriangle& s = swap ? t0 : s0;  // s has the larger dimension
  const ExactTriangle& t = swap ? s0 : t0;
  if (s.size == 3) {
    int st[3] = {0, 0, 0};  // sides of t's corners against s's plane
    int sum = 0;
    for (int i = 0; i < t.size; ++i) {
      st[i] = orient3d(s.p[0], s.p[1], s.p[2], t.p[i]);
      sum += st[i];
    }
    if (sum == t.size || sum == -t.size) return false;  // all strictly on one side
    if (st[0] == 0 && st[1] == 0 && st[2] == 0) return detail::coplanar_meet(s, t);
    if (t.size == 2) return detail::segment_meets_triangle(t.p[0], t.p[1], st[0], st[1], s);
    // two proper triangles in different planes: an edge of one meets the other
    int ss[3];
    sum = 0;
    for (int i = 0; i < 3; ++i) {
      ss[i] = orient3d(t.p[0], t.p[1], t.p[2], s.p[i]);
      sum += ss[i];
    }
    if (sum == 3 || sum == -3) return false;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      if (detail::segment_meets_triangle(t.p[i], t.p[j], st[i], st[j], s)) return true;
      if (detail::segment_meets_triangle(s.p[i], s.p[j], ss[i], ss[j], t)) return true;
    }
    return false;
  }
  // segments and points: coplanar, and meeting in all three axis projections
  if (s.size == 2 && t.size == 2 && orient3d(s.p[0], s.p[1], t.p[0], t.p[1]) != 0) return false;
  for (int axis = 0; axis < 3; ++axis) {
    detail::Point2 P[2], Q[2];
    for (int i = 0; i < s.size; ++i) P[i] = detail::project(s.p[i], axis);
    for (int i = 0; i < t.size; ++i) Q[i] = detail::project(t.p[i], axis);
    if (!detail::hulls_meet_2d(P, s.size, Q, t.size)) return false;
  }
  return true;
}

/// True when the closed triangles a0a1a2 and b0b1b2 share a point, decided exactly for the
/// corners rounded to multiples of `quantum` (file comment). ArgumentError when a coordinate is
/// not finite or exceeds 2^38 quanta (|x| > 0.25 with the default quantum 2^-40), or when the
/// quantum is not positive.
inline bool triangles_intersect(const Vec3<double>& a0, const Vec3<double>& a1, const Vec3<double>& a2,
                                const Vec3<double>& b0, const Vec3<double>& b1, const Vec3<double>& b2,
                                double quantum = 0x1p-40) {
  return triangles_intersect(ExactTriangle::quantized(a0, a1, a2, quantum, "triangles_intersect: a"),
                             ExactTriangle::quantized(b0, b1, b2, quantum, "triangles_intersect: b"));
}

/// Every pair (row of A, row of B) of triangles over the vertices X that intersect (exactly, for
/// X rounded to multiples of `quantum`), sorted. Pairs that share a vertex index are skipped:
/// they always touch at that vertex, so for two surfaces of one mesh (or A == B, a
/// self-intersection check) they would only report the mesh's own connectivity; crossings
/// between such neighbours are not reported. Candidates come from a sort-and-sweep over the
/// exact bounding boxes along their longest axis. Only the vertices A or B use are checked;
/// ArgumentError names the row with an index outside [0, X.rows()) or the coordinate that is not
/// finite or too large.
inline std::vector<std::pair<Index, Index>> intersecting_triangle_pairs(const Points<>& X, const Tris& A, const Tris& B,
                                                                        double quantum = 0x1p-40) {
  const char* where = "intersecting_triangle_pairs";
  detail::check_quantum(quantum, where);
  const Tris* sets[2] = {&A, &B};
  std::vector<GridPoint> g(std::size_t(X.rows()));
  std::vector<char> used(std::size_t(X.rows()), 0);
  for (int set = 0; set < 2; ++set)
    for (Index f = 0; f < sets[set]->rows(); ++f)
      for (int c = 0; c < 3; ++c) {
        const VIndex v = (*sets[set])(f, c);
        if (v < 0 || v >= X.rows())
          throw ArgumentError(std::string(where) + ": " + (set ? "B" : "A") + " row " + std::to_string(f) +
                              " has vertex index " + std::to_string(v) + " outside [0, " + std::to_string(X.rows()) + ")");
        if (used[std::size_t(v)]) continue;
        used[std::size_t(v)] = 1;
        for (int k = 0; k < 3; ++k)
          g[std::size_t(v)][k] = detail::quantize(X(v, k), quantum,
                                                  std::string(where) + ": X(" + std::to_string(v) + ", " + std::to_string(k) + ")");
      }

  struct Box {
    GridPoint lo, hi;
    Index row;
    bool in_b;
  };
  std::vector<Box> boxes;
  boxes.reserve(std::size_t(A.rows() + B.rows()));
  for (int set = 0; set < 2; ++set)
    for (Index f = 0; f < sets[set]->rows(); ++f) {
      const Tris& T = *sets[set];
      Box b{g[std::size_t(T(f, 0))], g[std::size_t(T(f, 0))], f, set == 1};
      for (int c = 1; c < 3; ++c)
        for (int k = 0; k < 3; ++k) {
          b.lo[k] = std::min(b.lo[k], g[std::size_t(T(f, c))][k]);
          b.hi[k] = std::max(b.hi[k], g[std::size_t(T(f, c))][k]);
        }
      boxes.push_back(b);
    }
  if (boxes.empty()) return {};
  GridPoint lo = boxes[0].lo, hi = boxes[0].hi;
  for (const Box& b : boxes)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], b.lo[k]);
      hi[k] = std::max(hi[k], b.hi[k]);
    }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  std::sort(boxes.begin(), boxes.end(), [axis](const Box& x, const Box& y) { return x.lo[axis] < y.lo[axis]; });

  auto shares_vertex = [&](Index fa, Index fb) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (A(fa, i) == B(fb, j)) return true;
    return false;
  };
  auto exact = [&](const Tris& T, Index f) {
    return ExactTriangle(g[std::size_t(T(f, 0))], g[std::size_t(T(f, 1))], g[std::size_t(T(f, 2))]);
  };
  // sweep: each box is tested against the open boxes of the other set, which are pruned as the
  // sweep passes their upper end
  std::vector<std::pair<Index, Index>> out;
  std::vector<const Box*> open[2];
  for (const Box& b : boxes) {
    std::vector<const Box*>& other = open[b.in_b ? 0 : 1];
    for (std::size_t i = 0; i < other.size();) {
      const Box& o = *other[i];
      if (o.hi[axis] < b.lo[axis]) {
        other[i] = other.back();
        other.pop_back();
        continue;
      }
      ++i;
      bool overlap = true;
      for (int k = 0; k < 3; ++k) overlap = overlap && o.lo[k] <= b.hi[k] && b.lo[k] <= o.hi[k];
      const Index fa = b.in_b ? o.row : b.row, fb = b.in_b ? b.row : o.row;
      if (overlap && !shares_vertex(fa, fb) && triangles_intersect(exact(A, fa), exact(B, fb))) out.emplace_back(fa, fb);
    }
    open[b.in_b ? 1 : 0].push_back(&b);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace simsr
