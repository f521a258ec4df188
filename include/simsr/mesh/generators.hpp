#pragma once
/// \file
/// Meshes of simple solids and closed surfaces at any resolution, for tests, benchmarks and
/// examples. Every tet mesh is conforming (neighbouring tets share whole faces) and positively
/// oriented; every closed surface is counter-clockwise seen from outside (the disk and the sheet are
/// open, in z = 0, counter-clockwise seen from +z).
///
///     auto box = simsr::box_tet_mesh(10, 10, 10);                  // unit cube, 6000 Kuhn tets
///     auto cyl = simsr::cylinder_tet_mesh(1.0, 2.0, 8, 12);        // r = 1, height 2
///     auto shell = simsr::sphere_shell_tet_mesh(0.5, 1.0, 3, 4);   // icosphere level 3, 4 layers
///     auto face = simsr::ellipsoid_surface(35637, 1.0, 0.8, 0.6);  // exactly 35,637 vertices
///     auto sheet = simsr::square_sheet(1.0, 8);                    // 81 vertices, 128 triangles
///
/// Curved boundaries are inscribed polyhedra: volumes converge to the analytic value as O(ℓ²)
/// in the boundary edge length ℓ.

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "detail/elements.hpp"
#include "tet_mesh.hpp"
#include "tri_mesh.hpp"

namespace simsr {

/// How a hexahedral cell is cut into tets.
enum class CubeSplit {
  six,  ///< 6 Kuhn (Freudenthal) simplices around the main diagonal; conforming between any neighbours
  five  ///< 5 tets (4 corner tets + a regular central one), orientation alternating with the cell's
        ///< parity i+j+k so that neighbouring faces carry the same diagonal
};

namespace detail {

/// Cube corner b ∈ [0, 8) sits at local (b & 1, (b >> 1) & 1, (b >> 2) & 1).
/// Kuhn simplices: 0 → axis a → a + axis b → 7, for the six axis orders.
inline constexpr std::array<std::array<int, 4>, 6> kuhn_tets{
    {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}}};
/// 5-tet split whose central tet uses the even corners {0, 3, 5, 6}.
inline constexpr std::array<std::array<int, 4>, 5> five_tets_even{
    {{0, 3, 5, 6}, {1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}}};
/// 5-tet split whose central tet uses the odd corners {1, 2, 4, 7}.
inline constexpr std::array<std::array<int, 4>, 5> five_tets_odd{
    {{1, 2, 4, 7}, {0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}}};

/// Appends tet (a, b, c, d) to `T`, swapping two corners when its signed volume is negative.
template <class S>
void push_positive(std::vector<std::array<VIndex, 4>>& T, const Points<S>& V, std::array<VIndex, 4> t) {
  if (tet_volume6(point(V, t[0]), point(V, t[1]), point(V, t[2]), point(V, t[3])) < S(0)) std::swap(t[2], t[3]);
  T.push_back(t);
}

template <class Rows, class M>
void fill_rows(M& out, const std::vector<Rows>& rows) {
  out.resize(Index(rows.size()), out.cols());
  for (Index r = 0; r < out.rows(); ++r)
    for (Index c = 0; c < out.cols(); ++c) out(r, c) = rows[r][c];
}

/// Splits the prism (bottom triangle b, top triangle t, t[i] above b[i]) into 3 tets. Each quad
/// side gets the diagonal from its bottom vertex of larger index to the top vertex above the
/// smaller one: the choice depends on the side alone, so prisms sharing a side conform.
template <class S>
void split_prism(std::vector<std::array<VIndex, 4>>& T, const Points<S>& V, std::array<VIndex, 3> b,
                 std::array<VIndex, 3> t) {
  std::array<int, 3> o{0, 1, 2};
  std::sort(o.begin(), o.end(), [&](int x, int y) { return b[x] < b[y]; });
  const VIndex b0 = b[o[0]], b1 = b[o[1]], b2 = b[o[2]], t0 = t[o[0]], t1 = t[o[1]], t2 = t[o[2]];
  push_positive(T, V, {b0, b1, b2, t0});
  push_positive(T, V, {b1, b2, t0, t1});
  push_positive(T, V, {b2, t0, t1, t2});
}

/// Triangles zipping two closed rings A and B (vertex lists in angular order, vertex i of a ring
/// at angle 2π(i + offset)/|ring|), merged by angle; each triangle is (A, B, next of A or B).
inline void zip_rings(std::vector<std::array<VIndex, 3>>& F, const std::vector<VIndex>& A, double oa,
                      const std::vector<VIndex>& B, double ob) {
  std::size_t i = 0, j = 0;
  while (i < A.size() || j < B.size()) {
    const double na = (double(i + 1) + oa) / double(A.size()), nb = (double(j + 1) + ob) / double(B.size());
    if (j == B.size() || (i < A.size() && na < nb)) {
      F.push_back({A[i % A.size()], B[j % B.size()], A[(i + 1) % A.size()]});
      ++i;
    } else {
      F.push_back({A[i % A.size()], B[j % B.size()], B[(j + 1) % B.size()]});
      ++j;
    }
  }
}

inline void require_positive(const char* what, double value) {
  if (!(value > 0) || !std::isfinite(value)) throw ArgumentError(std::string(what) + " must be positive and finite, got " + std::to_string(value));
}
inline void require_at_least(const char* what, Index value, Index min) {
  if (value < min) throw ArgumentError(std::string(what) + " must be at least " + std::to_string(min) + ", got " + std::to_string(value));
}

}  // namespace detail

/// Box [lo, hi] as nx×ny×nz equal cells, each cut into 6 or 5 tets (CubeSplit). Vertex (i,j,k)
/// of the (nx+1)×(ny+1)×(nz+1) grid has index i + (nx+1)(j + (ny+1)k). Returns 6·nx·ny·nz or
/// 5·nx·ny·nz tets. Throws ArgumentError for a count < 1 or hi ≤ lo.
template <class S = Scalar>
TetMesh<S> box_tet_mesh(Index nx, Index ny, Index nz, const Vec3<S>& lo = Vec3<S>::Zero(),
                        const Vec3<S>& hi = Vec3<S>::Ones(), CubeSplit split = CubeSplit::six) {
  detail::require_at_least("box_tet_mesh: nx", nx, 1);
  detail::require_at_least("box_tet_mesh: ny", ny, 1);
  detail::require_at_least("box_tet_mesh: nz", nz, 1);
  for (int a = 0; a < 3; ++a) detail::require_positive("box_tet_mesh: hi - lo", double(hi[a] - lo[a]));
  TetMesh<S> m;
  m.V.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
  const auto id = [&](Index i, Index j, Index k) { return VIndex(i + (nx + 1) * (j + (ny + 1) * k)); };
  const Vec3<S> step((hi[0] - lo[0]) / S(nx), (hi[1] - lo[1]) / S(ny), (hi[2] - lo[2]) / S(nz));
  for (Index k = 0; k <= nz; ++k)
    for (Index j = 0; j <= ny; ++j)
      for (Index i = 0; i <= nx; ++i)
        m.V.row(id(i, j, k)) << (i == nx ? hi[0] : lo[0] + step[0] * S(i)), (j == ny ? hi[1] : lo[1] + step[1] * S(j)),
            (k == nz ? hi[2] : lo[2] + step[2] * S(k));
  std::vector<std::array<VIndex, 4>> tets;
  tets.reserve(std::size_t(nx * ny * nz * (split == CubeSplit::six ? 6 : 5)));
  for (Index k = 0; k < nz; ++k)
    for (Index j = 0; j < ny; ++j)
      for (Index i = 0; i < nx; ++i) {
        VIndex c[8];
        for (int b = 0; b < 8; ++b) c[b] = id(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
        const auto emit = [&](const auto& table) {
          for (const auto& t : table) detail::push_positive(tets, m.V, {c[t[0]], c[t[1]], c[t[2]], c[t[3]]});
        };
        if (split == CubeSplit::six)
          emit(detail::kuhn_tets);
        else if ((i + j + k) % 2 == 0)
          emit(detail::five_tets_even);
        else
          emit(detail::five_tets_odd);
      }
  m.T.resize(Index(tets.size()), 4);
  detail::fill_rows(m.T, tets);
  return m;
}

/// Square sheet [0, size]² in the plane z = 0 as cells×cells squares, each cut along a diagonal
/// that alternates with the cell's parity (i + j), so that no direction is favoured (a cloth
/// sheet's usual "criss-cross" triangulation). Vertex (i, j) of the (cells+1)² grid has index
/// i + (cells+1)·j. 2·cells² triangles, counter-clockwise seen from +z. cells = 8 gives the
/// 81-vertex coarse sheet of Chen et al. 2023's SHEET scene.
template <class S = Scalar>
TriMesh<S> square_sheet(S size, Index cells) {
  detail::require_positive("square_sheet: size", double(size));
  detail::require_at_least("square_sheet: cells", cells, 1);
  const Index n = cells + 1;
  TriMesh<S> m;
  m.V.resize(n * n, 3);
  for (Index j = 0; j < n; ++j)
    for (Index i = 0; i < n; ++i) m.V.row(i + n * j) << size * S(i) / S(cells), size * S(j) / S(cells), S(0);
  m.F.resize(2 * cells * cells, 3);
  Index f = 0;
  for (Index j = 0; j < cells; ++j)
    for (Index i = 0; i < cells; ++i) {
      const VIndex a = VIndex(i + n * j), b = VIndex(a + 1), c = VIndex(a + n), d = VIndex(a + n + 1);
      if ((i + j) % 2 == 0) {  // diagonal a–d
        m.F.row(f++) << a, b, d;
        m.F.row(f++) << a, d, c;
      } else {  // diagonal b–c
        m.F.row(f++) << a, b, c;
        m.F.row(f++) << b, d, c;
      }
    }
  return m;
}

/// Triangulated disk of radius r in the plane z = 0: a centre vertex and `rings` concentric rings,
/// ring q (1-based) holding 6q vertices at radius q·r/rings. V #(1 + 3·rings·(rings+1))×3, F
/// (6·rings² triangles) counter-clockwise seen from +z.
template <class S = Scalar>
TriMesh<S> disk_surface(S radius, Index rings) {
  detail::require_positive("disk_surface: radius", double(radius));
  detail::require_at_least("disk_surface: rings", rings, 1);
  TriMesh<S> m;
  m.V.resize(1 + 3 * rings * (rings + 1), 3);
  m.V.row(0).setZero();
  std::vector<std::vector<VIndex>> ring{{0}};
  VIndex next = 1;
  for (Index q = 1; q <= rings; ++q) {
    std::vector<VIndex> ids;
    for (Index i = 0; i < 6 * q; ++i) {
      const double ph = 2 * std::numbers::pi * double(i) / double(6 * q);
      m.V.row(next) << radius * S(q) / S(rings) * S(std::cos(ph)), radius * S(q) / S(rings) * S(std::sin(ph)), S(0);
      ids.push_back(next++);
    }
    ring.push_back(std::move(ids));
  }
  std::vector<std::array<VIndex, 3>> F;
  for (Index q = 1; q <= rings; ++q) {
    const auto& in = ring[q - 1];
    const auto& out = ring[q];
    if (q == 1) {
      for (std::size_t i = 0; i < out.size(); ++i) F.push_back({0, out[i], out[(i + 1) % out.size()]});
    } else {
      detail::zip_rings(F, out, 0.0, in, 0.0);  // outer ring first: (out_i, in_j, next) turns counter-clockwise
    }
  }
  for (auto& f : F) {  // enforce counter-clockwise seen from +z
    const Vec3<S> a = detail::point(m.V, f[0]), b = detail::point(m.V, f[1]), c = detail::point(m.V, f[2]);
    if ((b - a).cross(c - a)[2] < S(0)) std::swap(f[1], f[2]);
  }
  m.F.resize(Index(F.size()), 3);
  detail::fill_rows(m.F, F);
  return m;
}

/// Solid cylinder of radius r around the z axis, z ∈ [0, height]: disk_surface(r, radial) extruded
/// through `axial` layers, each prism cut into 3 conforming tets. Boundary vertices lie exactly on
/// the cylinder, so the volume is that of the inscribed 6·radial-gon prism (error O(radial⁻²)).
/// 18·radial²·axial tets.
template <class S = Scalar>
TetMesh<S> cylinder_tet_mesh(S radius, S height, Index radial, Index axial) {
  detail::require_positive("cylinder_tet_mesh: height", double(height));
  detail::require_at_least("cylinder_tet_mesh: axial", axial, 1);
  const TriMesh<S> disk = disk_surface(radius, radial);
  const Index n = disk.V.rows();
  TetMesh<S> m;
  m.V.resize(n * (axial + 1), 3);
  for (Index l = 0; l <= axial; ++l) {
    m.V.middleRows(l * n, n) = disk.V;
    m.V.middleRows(l * n, n).col(2).setConstant(l == axial ? height : height * S(l) / S(axial));
  }
  std::vector<std::array<VIndex, 4>> tets;
  for (Index l = 0; l < axial; ++l)
    for (Index f = 0; f < disk.F.rows(); ++f) {
      const VIndex o = VIndex(l * n), p = VIndex((l + 1) * n);
      detail::split_prism(tets, m.V, {disk.F(f, 0) + o, disk.F(f, 1) + o, disk.F(f, 2) + o},
                          {disk.F(f, 0) + p, disk.F(f, 1) + p, disk.F(f, 2) + p});
    }
  m.T.resize(Index(tets.size()), 4);
  detail::fill_rows(m.T, tets);
  return m;
}

/// Icosahedron subdivided `level` times (each triangle into 4, midpoints projected onto the
/// sphere) of radius r centred at the origin: 10·4^level + 2 vertices, 20·4^level triangles.
template <class S = Scalar>
TriMesh<S> icosphere(Index level, S radius = S(1)) {
  detail::require_at_least("icosphere: level", level, 0);
  detail::require_positive("icosphere: radius", double(radius));
  if (level > 10) throw ArgumentError("icosphere: level " + std::to_string(level) + " would exceed 20 million triangles");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3<double>> P = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<VIndex, 3>> F = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                          {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                          {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                          {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : P) p.normalize();
  for (Index l = 0; l < level; ++l) {
    std::unordered_map<std::uint64_t, VIndex> mid;
    mid.reserve(F.size() * 2);
    const auto midpoint = [&](VIndex a, VIndex b) {
      const auto key = detail::pair_key(std::min(a, b), std::max(a, b));
      const auto [it, fresh] = mid.try_emplace(key, VIndex(P.size()));
      if (fresh) P.push_back((P[a] + P[b]).normalized());
      return it->second;
    };
    std::vector<std::array<VIndex, 3>> G;
    G.reserve(4 * F.size());
    for (const auto& f : F) {
      const VIndex a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      G.insert(G.end(), {{f[0], a, c}, {f[1], b, a}, {f[2], c, b}, {a, b, c}});
    }
    F = std::move(G);
  }
  TriMesh<S> m;
  m.V.resize(Index(P.size()), 3);
  for (Index i = 0; i < m.V.rows(); ++i) m.V.row(i) = (double(radius) * P[i]).template cast<S>().transpose();
  m.F.resize(Index(F.size()), 3);
  detail::fill_rows(m.F, F);
  return m;
}

/// Thick spherical shell r_inner ≤ |x| ≤ r_outer: icosphere(level) copied onto `layers` + 1
/// spheres of radii evenly spaced in [r_inner, r_outer], each radial prism cut into 3 conforming
/// tets. 3·20·4^level·layers tets; both boundary spheres carry their vertices exactly.
template <class S = Scalar>
TetMesh<S> sphere_shell_tet_mesh(S r_inner, S r_outer, Index level, Index layers) {
  detail::require_positive("sphere_shell_tet_mesh: r_inner", double(r_inner));
  detail::require_positive("sphere_shell_tet_mesh: r_outer - r_inner", double(r_outer - r_inner));
  detail::require_at_least("sphere_shell_tet_mesh: layers", layers, 1);
  const TriMesh<S> unit = icosphere<S>(level, S(1));
  const Index n = unit.V.rows();
  TetMesh<S> m;
  m.V.resize(n * (layers + 1), 3);
  for (Index l = 0; l <= layers; ++l)
    m.V.middleRows(l * n, n) = unit.V * (l == layers ? r_outer : r_inner + (r_outer - r_inner) * S(l) / S(layers));
  std::vector<std::array<VIndex, 4>> tets;
  for (Index l = 0; l < layers; ++l)
    for (Index f = 0; f < unit.F.rows(); ++f) {
      const VIndex o = VIndex(l * n), p = VIndex((l + 1) * n);
      detail::split_prism(tets, m.V, {unit.F(f, 0) + o, unit.F(f, 1) + o, unit.F(f, 2) + o},
                          {unit.F(f, 0) + p, unit.F(f, 1) + p, unit.F(f, 2) + p});
    }
  m.T.resize(Index(tets.size()), 4);
  detail::fill_rows(m.T, tets);
  return m;
}

/// Closed ellipsoid surface with semi-axes a, b, c (along x, y, z) and exactly `nv` ≥ 8 vertices:
/// the poles (0, 0, ±c) and R − 1 latitude rings (R ≈ √(π(nv−2)/4)) at polar angles πr/R, whose
/// vertex counts follow sin θ (adjusted one by one from the equator outwards to hit nv exactly),
/// odd rings rotated by half a step; consecutive rings are zipped in angular order. 2·nv − 4
/// triangles, counter-clockwise seen from outside. Vertex 0 is the north pole, nv − 1 the south.
template <class S = Scalar>
TriMesh<S> ellipsoid_surface(Index nv, S a, S b, S c) {
  detail::require_at_least("ellipsoid_surface: vertex count", nv, 8);
  detail::require_positive("ellipsoid_surface: a", double(a));
  detail::require_positive("ellipsoid_surface: b", double(b));
  detail::require_positive("ellipsoid_surface: c", double(c));
  const double pi = std::numbers::pi;
  const Index R = std::max<Index>(3, Index(std::lround(std::sqrt(pi * double(nv - 2) / 4))));
  std::vector<Index> n(static_cast<std::size_t>(R - 1));
  Index total = 0;
  for (Index r = 1; r < R; ++r) total += n[r - 1] = std::max<Index>(3, std::lround(2.0 * double(R) * std::sin(pi * double(r) / double(R))));
  for (Index r = 0; total != nv - 2; r = (r + 1) % (R - 1)) {
    const Index ring = (R - 1) / 2 + (r % 2 ? -(r + 1) / 2 : r / 2);
    if (total < nv - 2)
      ++n[ring], ++total;
    else if (n[ring] > 3)
      --n[ring], --total;
  }
  TriMesh<S> m;
  m.V.resize(nv, 3);
  std::vector<std::vector<VIndex>> rings;
  m.V.row(0) << S(0), S(0), c;
  Index next = 1;
  for (Index r = 1; r < R; ++r) {
    const double th = pi * double(r) / double(R);
    std::vector<VIndex> ids;
    for (Index i = 0; i < n[r - 1]; ++i) {
      const double ph = 2 * pi * (double(i) + 0.5 * double(r % 2)) / double(n[r - 1]);
      m.V.row(next) << a * S(std::sin(th) * std::cos(ph)), b * S(std::sin(th) * std::sin(ph)), c * S(std::cos(th));
      ids.push_back(static_cast<VIndex>(next++));
    }
    rings.push_back(std::move(ids));
  }
  m.V.row(next) << S(0), S(0), -c;
  std::vector<std::array<VIndex, 3>> F;
  F.reserve(std::size_t(2 * nv - 4));
  const auto fan = [&](VIndex pole, const std::vector<VIndex>& ring, bool north) {
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const VIndex u = ring[i], w = ring[(i + 1) % ring.size()];
      F.push_back(north ? std::array<VIndex, 3>{pole, u, w} : std::array<VIndex, 3>{pole, w, u});
    }
  };
  fan(0, rings.front(), true);
  for (std::size_t r = 0; r + 1 < rings.size(); ++r)
    detail::zip_rings(F, rings[r], 0.5 * double((r + 1) % 2), rings[r + 1], 0.5 * double((r + 2) % 2));
  fan(static_cast<VIndex>(nv - 1), rings.back(), false);
  m.F.resize(Index(F.size()), 3);
  detail::fill_rows(m.F, F);
  return m;
}

}  // namespace simsr
