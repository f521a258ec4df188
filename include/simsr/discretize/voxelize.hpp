#pragma once
/// \file
/// Voxelization (Park et al. 2023, §4: "voxelizing the high-resolution mesh at a coarse
/// granularity"): the cells of a regular grid of cubes of side h that overlap the volume enclosed
/// by a closed surface, or covered by a tet mesh.
///
///     auto cells = simsr::discretize::voxelize(face_surface, 0.01);
///     auto front = simsr::discretize::voxelize(face_surface, 0.01, {.region = [](const Vec3<>& c) { return c.z() > 0; }});
///
/// A cell is kept when its open interior meets the enclosed volume (touching the surface along a
/// face, edge or corner only does not count). Two tests decide it:
///  * cells the surface crosses: exact triangle–box separating-axis test (Akenine-Möller 2001),
///    on the open box, so surfaces lying in a grid plane keep no extra layer;
///  * all other cells lie wholly inside or outside: their centre's winding number, counted along
///    grid rows (rays along +x). Ray crossings use *watertight* edge functions: each edge's sign is
///    evaluated from its two endpoints in a canonical order, with ties broken by symbolic
///    perturbation of the query point, so a ray through a vertex or an edge is counted exactly
///    once by exactly one of the triangles around it. This is O(#F + #cells) for a whole grid,
///    where the generalized winding number (Jacobson 2013) costs O(#F) per query; the latter's
///    tolerance of holes is not needed since open surfaces are rejected up front. Signed
///    crossings give the winding number, so nested or self-overlapping closed parts also work.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/detail/elements.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/topology.hpp"
#include "../mesh/tri_mesh.hpp"

namespace simsr::discretize {

/// A regular grid of cubic cells of side h: cell (i, j, k), 0 ≤ i < dims[0] …, spans
/// origin + h·([i, i+1] × [j, j+1] × [k, k+1]). Linear index i + dims[0]·(j + dims[1]·k).
struct Grid {
  Vec3<double> origin = Vec3<double>::Zero();
  double h = 1.0;
  std::array<Index, 3> dims{0, 0, 0};

  Index num_cells() const { return dims[0] * dims[1] * dims[2]; }
  Index linear(Index i, Index j, Index k) const { return i + dims[0] * (j + dims[1] * k); }
  Vec3<double> centre(Index i, Index j, Index k) const { return origin + h * Vec3<double>(i + 0.5, j + 0.5, k + 0.5); }
};

/// Kept cells of a grid: `cells` holds their (i, j, k), sorted by linear index.
struct VoxelSet {
  Grid grid;
  std::vector<std::array<Index, 3>> cells;

  Index size() const { return Index(cells.size()); }
  /// Total volume of the kept cells, #cells·h³.
  double volume() const { return double(cells.size()) * grid.h * grid.h * grid.h; }
};

/// Where the grid planes lie.
enum class GridAlignment {
  anchored,     ///< at anchor + h·ℤ along each axis: grids of equal h line up across meshes
  bounding_box  ///< centred on the bounding box, ⌈extent/h⌉ cells per axis (at least 1)
};

/// Options of voxelize.
struct VoxelizeOptions {
  GridAlignment alignment = GridAlignment::anchored;
  Vec3<double> anchor = Vec3<double>::Zero();  ///< a grid point, with GridAlignment::anchored
  /// Keep only cells whose centre satisfies this (the paper drops the neck and back of the head).
  std::function<bool(const Vec3<double>&)> region;
  /// Largest grid (cells of the bounding grid, kept or not) accepted; ArgumentError beyond,
  /// before anything is allocated.
  Index max_cells = Index(1) << 27;
};

namespace detail {

using simsr::detail::point;

/// Throws MeshError unless F (#F×3) is a closed, edge-manifold, consistently oriented surface:
/// every undirected edge in exactly two triangles, traversed once in each direction.
template <class DF>
void check_closed_surface(const Eigen::MatrixBase<DF>& F) {
  simsr::detail::require_cols("closed surface: triangles", F, 3);
  if (F.rows() == 0) throw MeshError("surface", -1, "no triangles: a closed surface is needed");
  simsr::detail::check_indices(F, -1);
  struct Half {
    std::uint64_t key;  // undirected (min, max)
    bool forward;       // a < b as traversed
    Index face;
  };
  std::vector<Half> half;
  half.reserve(std::size_t(3 * F.rows()));
  for (Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const VIndex a = F(f, c), b = F(f, (c + 1) % 3);
      if (a == b) throw MeshError("triangle", f, "uses vertex " + std::to_string(a) + " twice");
      half.push_back({simsr::detail::pair_key(std::min(a, b), std::max(a, b)), a < b, f});
    }
  std::sort(half.begin(), half.end(), [](const Half& x, const Half& y) { return x.key != y.key ? x.key < y.key : x.face < y.face; });
  for (std::size_t i = 0; i < half.size();) {
    std::size_t j = i + 1;
    while (j < half.size() && half[j].key == half[i].key) ++j;
    const std::string edge = "edge (" + std::to_string(half[i].key >> 32) + ", " + std::to_string(half[i].key & 0xffffffffu) + ")";
    if (j - i == 1) throw MeshError("triangle", half[i].face, edge + " is in no other triangle: the surface is open");
    if (j - i > 2)
      throw MeshError("triangle", half[i + 2].face, edge + " is shared by " + std::to_string(j - i) + " triangles: the surface is not manifold");
    if (half[i].forward == half[i + 1].forward)
      throw MeshError("triangle", half[i + 1].face,
                      edge + " is traversed in the same direction by triangles " + std::to_string(half[i].face) + " and " +
                          std::to_string(half[i + 1].face) + ": inconsistent orientation");
    i = j;
  }
}

/// Separating-axis test of a triangle (a, b, c) against the *open* axis-aligned box of centre
/// `centre` and half-side `half` > 0 (Akenine-Möller 2001: 3 box normals, the triangle normal,
/// 9 edge × axis products; zero axes of degenerate triangles are skipped). True when the
/// triangle meets the box interior.
inline bool triangle_box_overlap(const Vec3<double>& centre, const Vec3<double>& half, const Vec3<double>& a,
                                 const Vec3<double>& b, const Vec3<double>& c) {
  const Vec3<double> v[3] = {a - centre, b - centre, c - centre};
  const auto separated = [&](const Vec3<double>& axis) {
    const double r = half[0] * std::abs(axis[0]) + half[1] * std::abs(axis[1]) + half[2] * std::abs(axis[2]);
    if (!(r > 0)) return false;  // zero axis: no information
    const double p0 = v[0].dot(axis), p1 = v[1].dot(axis), p2 = v[2].dot(axis);
    return std::min({p0, p1, p2}) >= r || std::max({p0, p1, p2}) <= -r;
  };
  for (int k = 0; k < 3; ++k)
    if (std::min({v[0][k], v[1][k], v[2][k]}) >= half[k] || std::max({v[0][k], v[1][k], v[2][k]}) <= -half[k]) return false;
  const Vec3<double> e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  for (const auto& edge : e)
    for (int k = 0; k < 3; ++k)
      if (separated(edge.cross(Vec3<double>::Unit(k)))) return false;
  return !separated(e[0].cross(e[1]));
}

/// Separating-axis test of a tet (p[0..3]) against the open box (centre, half): 3 box normals,
/// 4 face normals, 6 edges × 3 axes. True when their interiors overlap (positive volume).
inline bool tet_box_overlap(const Vec3<double>& centre, const Vec3<double>& half, const std::array<Vec3<double>, 4>& p) {
  std::array<Vec3<double>, 4> v;
  for (int i = 0; i < 4; ++i) v[i] = p[i] - centre;
  const auto separated = [&](const Vec3<double>& axis) {
    const double r = half[0] * std::abs(axis[0]) + half[1] * std::abs(axis[1]) + half[2] * std::abs(axis[2]);
    if (!(r > 0)) return false;
    double lo = v[0].dot(axis), hi = lo;
    for (int i = 1; i < 4; ++i) lo = std::min(lo, v[i].dot(axis)), hi = std::max(hi, v[i].dot(axis));
    return lo >= r || hi <= -r;
  };
  for (int k = 0; k < 3; ++k)
    if (separated(Vec3<double>::Unit(k))) return false;
  static constexpr int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  static constexpr int faces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (const auto& f : faces)
    if (separated((v[f[1]] - v[f[0]]).cross(v[f[2]] - v[f[0]]))) return false;
  for (const auto& e : edges)
    for (int k = 0; k < 3; ++k)
      if (separated((v[e[1]] - v[e[0]]).cross(Vec3<double>::Unit(k)))) return false;
  return true;
}

/// Sign of orient(a, b, p) in the (y, z) plane, p perturbed by (ε, ε²): never 0 unless a and b
/// project to the same point. Callers pass (a, b) in a canonical vertex order.
inline int edge_sign(double ay, double az, double by, double bz, double py, double pz, double& value) {
  value = (by - ay) * (pz - az) - (bz - az) * (py - ay);
  if (value != 0) return value > 0 ? 1 : -1;
  if (bz != az) return bz < az ? 1 : -1;
  if (by != ay) return by > ay ? 1 : -1;
  return 0;
}

/// One ray crossing: row, x of the hit, +1 where the surface normal has positive x (exit).
struct Crossing {
  Index row;
  double x;
  int sign;
};

/// Crossings of the surface (V, F) with the rays along +x through (oy + sy·j, oz + sz·k),
/// 0 ≤ j < ny, 0 ≤ k < nz (row j + ny·k), sorted by (row, x).
template <class S>
std::vector<Crossing> row_crossings(const Points<S>& V, const Tris& F, double oy, double sy, Index ny, double oz, double sz, Index nz) {
  std::vector<Crossing> out;
  for (Index f = 0; f < F.rows(); ++f) {
    const VIndex id[3] = {F(f, 0), F(f, 1), F(f, 2)};
    Vec3<double> P[3];
    for (int c = 0; c < 3; ++c) P[c] = point(V, id[c]).template cast<double>();
    const double ylo = std::min({P[0][1], P[1][1], P[2][1]}), yhi = std::max({P[0][1], P[1][1], P[2][1]});
    const double zlo = std::min({P[0][2], P[1][2], P[2][2]}), zhi = std::max({P[0][2], P[1][2], P[2][2]});
    const Index j0 = std::max<Index>(0, Index(std::floor((ylo - oy) / sy))), j1 = std::min<Index>(ny - 1, Index(std::ceil((yhi - oy) / sy)));
    const Index k0 = std::max<Index>(0, Index(std::floor((zlo - oz) / sz))), k1 = std::min<Index>(nz - 1, Index(std::ceil((zhi - oz) / sz)));
    for (Index k = k0; k <= k1; ++k)
      for (Index j = j0; j <= j1; ++j) {
        const double py = oy + sy * double(j), pz = oz + sz * double(k);
        int s[3];
        double w[3];
        for (int e = 0; e < 3; ++e) {  // edge e runs id[e] → id[e+1], opposite corner e+2
          const int u = e, t = (e + 1) % 3;
          const bool swap = id[t] < id[u];
          const Vec3<double>& A = swap ? P[t] : P[u];
          const Vec3<double>& B = swap ? P[u] : P[t];
          s[e] = edge_sign(A[1], A[2], B[1], B[2], py, pz, w[e]);
          if (swap) s[e] = -s[e], w[e] = -w[e];
        }
        int sign = 0;
        bool hit = true;
        for (int e = 0; e < 3 && hit; ++e) {
          if (s[e] == 0) continue;  // edge parallel to x: the other two decide
          if (sign == 0) sign = s[e];
          hit = s[e] == sign;
        }
        if (!hit || sign == 0) continue;
        // w[e] is the weight of the corner opposite edge e, i.e. corner (e + 2) % 3.
        const double wsum = w[0] + w[1] + w[2];
        const double x = wsum != 0 ? (w[1] * P[0][0] + w[2] * P[1][0] + w[0] * P[2][0]) / wsum
                                   : std::min({P[0][0], P[1][0], P[2][0]});
        out.push_back({j + ny * k, x, sign});
      }
  }
  std::sort(out.begin(), out.end(), [](const Crossing& a, const Crossing& b) { return a.row != b.row ? a.row < b.row : a.x < b.x; });
  return out;
}

/// Checks a grid's size before anything is allocated.
inline std::array<Index, 3> checked_dims(const std::array<double, 3>& n, Index max_cells, const char* what) {
  double total = 1;
  for (double d : n) {
    if (!std::isfinite(d) || d < 1) throw ArgumentError(std::string(what) + ": grid extent is not finite");
    total *= d;
  }
  if (total > double(max_cells))
    throw ArgumentError(std::string(what) + ": the grid would hold " + std::to_string(total) + " cells, more than max_cells = " +
                        std::to_string(max_cells) + " (h too small?)");
  return {Index(n[0]), Index(n[1]), Index(n[2])};
}

template <class S>
Grid make_grid(const Points<S>& V, double h, const VoxelizeOptions& opt, const char* what) {
  if (!(h > 0) || !std::isfinite(h)) throw ArgumentError(std::string(what) + ": cell size h must be positive and finite, got " + std::to_string(h));
  if (V.rows() == 0) throw MeshError("surface", -1, std::string(what) + ": no vertices");
  if (!V.allFinite()) throw MeshError("vertex", -1, std::string(what) + ": non-finite vertex coordinate");
  const Vec3<double> lo = V.colwise().minCoeff().transpose().template cast<double>();
  const Vec3<double> hi = V.colwise().maxCoeff().transpose().template cast<double>();
  Grid g;
  g.h = h;
  std::array<double, 3> n;
  if (opt.alignment == GridAlignment::anchored) {
    Vec3<double> first;
    for (int a = 0; a < 3; ++a) {
      const double i0 = std::floor((lo[a] - opt.anchor[a]) / h), i1 = std::ceil((hi[a] - opt.anchor[a]) / h);
      first[a] = i0;
      n[a] = std::max(1.0, i1 - i0);
    }
    g.dims = checked_dims(n, opt.max_cells, what);
    g.origin = opt.anchor + h * first;
  } else {
    for (int a = 0; a < 3; ++a) n[a] = std::max(1.0, std::ceil((hi[a] - lo[a]) / h));
    g.dims = checked_dims(n, opt.max_cells, what);
    for (int a = 0; a < 3; ++a) g.origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * h * double(g.dims[a]);
  }
  return g;
}

/// Winding number ≠ 0 at the grid points origin + spacing·(i, j, k) (flag per point, linear
/// index i + n0·(j + n1·k)) of the closed surface (V, F), from crossings along rows.
template <class S>
std::vector<char> inside_on_grid(const Points<S>& V, const Tris& F, const Vec3<double>& origin, double spacing,
                                 const std::array<Index, 3>& n) {
  std::vector<char> inside(std::size_t(n[0] * n[1] * n[2]), 0);
  const auto cr = row_crossings(V, F, origin[1], spacing, n[1], origin[2], spacing, n[2]);
  for (std::size_t c = 0; c < cr.size();) {
    const Index row = cr[c].row;
    int winding = 0;
    Index i = 0;
    for (; c < cr.size() && cr[c].row == row; ++c) {
      // points before this crossing carry the winding accumulated so far (crossing strictly behind)
      for (; i < n[0] && origin[0] + spacing * double(i) <= cr[c].x; ++i)
        if (winding != 0) inside[std::size_t(i + n[0] * row)] = 1;
      winding -= cr[c].sign;
    }
    for (; i < n[0]; ++i)
      if (winding != 0) inside[std::size_t(i + n[0] * row)] = 1;
  }
  return inside;
}

}  // namespace detail

/// Cells of side h overlapping the volume enclosed by `surface` (closed, edge-manifold,
/// consistently oriented; see the file comment for the tests used), restricted to
/// `options.region`. Throws ArgumentError for h ≤ 0 or a grid above options.max_cells, MeshError
/// naming the triangle and edge of an open, non-manifold or inconsistently oriented surface.
template <class S>
VoxelSet voxelize(const TriMesh<S>& surface, double h, const VoxelizeOptions& options = {}) {
  VoxelSet out;
  out.grid = detail::make_grid(surface.V, h, options, "voxelize");
  detail::check_closed_surface(surface.F);
  simsr::detail::check_indices(surface.F, surface.V.rows());
  const Grid& g = out.grid;
  std::vector<char> keep(std::size_t(g.num_cells()), 0);
  const Vec3<double> half = Vec3<double>::Constant(0.5 * h);
  for (Index f = 0; f < surface.F.rows(); ++f) {
    Vec3<double> p[3];
    for (int c = 0; c < 3; ++c) p[c] = detail::point(surface.V, surface.F(f, c)).template cast<double>();
    Index lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max<Index>(0, Index(std::floor((std::min({p[0][a], p[1][a], p[2][a]}) - g.origin[a]) / h)));
      hi[a] = std::min<Index>(g.dims[a] - 1, Index(std::floor((std::max({p[0][a], p[1][a], p[2][a]}) - g.origin[a]) / h)));
    }
    for (Index k = lo[2]; k <= hi[2]; ++k)
      for (Index j = lo[1]; j <= hi[1]; ++j)
        for (Index i = lo[0]; i <= hi[0]; ++i) {
          char& kept = keep[std::size_t(g.linear(i, j, k))];
          if (!kept && detail::triangle_box_overlap(g.centre(i, j, k), half, p[0], p[1], p[2])) kept = 1;
        }
  }
  const auto inside = detail::inside_on_grid(surface.V, surface.F, g.origin + half, h, g.dims);
  for (Index k = 0; k < g.dims[2]; ++k)
    for (Index j = 0; j < g.dims[1]; ++j)
      for (Index i = 0; i < g.dims[0]; ++i) {
        const Index l = g.linear(i, j, k);
        if ((keep[l] || inside[l]) && (!options.region || options.region(g.centre(i, j, k)))) out.cells.push_back({i, j, k});
      }
  return out;
}

/// Cells of side h whose interior overlaps the interior of at least one tet of `mesh` (exact
/// separating-axis test), restricted to `options.region`. Inverted tets count as their mirror.
/// Throws as voxelize(TriMesh) for h and the grid size, MeshError for an index out of range.
template <class S>
VoxelSet voxelize(const TetMesh<S>& mesh, double h, const VoxelizeOptions& options = {}) {
  VoxelSet out;
  out.grid = detail::make_grid(mesh.V, h, options, "voxelize");
  simsr::detail::require_cols("voxelize: tets", mesh.T, 4);
  simsr::detail::check_indices(mesh.T, mesh.V.rows());
  const Grid& g = out.grid;
  std::vector<char> keep(std::size_t(g.num_cells()), 0);
  const Vec3<double> half = Vec3<double>::Constant(0.5 * h);
  for (Index t = 0; t < mesh.T.rows(); ++t) {
    std::array<Vec3<double>, 4> p;
    for (int c = 0; c < 4; ++c) p[c] = detail::point(mesh.V, mesh.T(t, c)).template cast<double>();
    Index lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      double mn = p[0][a], mx = p[0][a];
      for (int c = 1; c < 4; ++c) mn = std::min(mn, p[c][a]), mx = std::max(mx, p[c][a]);
      lo[a] = std::max<Index>(0, Index(std::floor((mn - g.origin[a]) / h)));
      hi[a] = std::min<Index>(g.dims[a] - 1, Index(std::floor((mx - g.origin[a]) / h)));
    }
    for (Index k = lo[2]; k <= hi[2]; ++k)
      for (Index j = lo[1]; j <= hi[1]; ++j)
        for (Index i = lo[0]; i <= hi[0]; ++i) {
          char& kept = keep[std::size_t(g.linear(i, j, k))];
          if (!kept && detail::tet_box_overlap(g.centre(i, j, k), half, p)) kept = 1;
        }
  }
  for (Index k = 0; k < g.dims[2]; ++k)
    for (Index j = 0; j < g.dims[1]; ++j)
      for (Index i = 0; i < g.dims[0]; ++i)
        if (keep[g.linear(i, j, k)] && (!options.region || options.region(g.centre(i, j, k)))) out.cells.push_back({i, j, k});
  return out;
}

/// Winding-number inside test of many points against a closed surface: true where the winding
/// number of `surface` around the point is non-zero. Points on the surface may go either way.
/// Grid-free: each point gets its own ray row. Throws MeshError for an open surface.
template <class S, class DP>
std::vector<char> inside_surface(const TriMesh<S>& surface, const Eigen::MatrixBase<DP>& P) {
  detail::check_closed_surface(surface.F);
  simsr::detail::require_cols("inside_surface: points", P, 3);
  std::vector<char> out(std::size_t(P.rows()), 0);
  for (Index q = 0; q < P.rows(); ++q) {  // one 1×1 row per point
    const auto cr = detail::row_crossings(surface.V, surface.F, double(P(q, 1)), 1.0, 1, double(P(q, 2)), 1.0, 1);
    int winding = 0;
    for (const auto& c : cr)
      if (c.x < double(P(q, 0))) winding -= c.sign;
    out[std::size_t(q)] = winding != 0;
  }
  return out;
}

}  // namespace simsr::discretize
