#pragma once
/// \file
/// The embedded LR lattice of Park et al. (2023, §4): voxelize the flesh volume at cell size h,
/// keep the cells that overlap it, tetrahedralize every kept cell (default: body-centred cubic,
/// Molino et al. 2003). Resolution is one number, h.
///
///     auto L = simsr::discretize::bcc_lattice(face_surface, 0.0125);           // TetMesh in L.mesh
///     auto F = simsr::discretize::build_lattice<FreudenthalSplit>(voxelize(face_surface, 0.0125));
///
/// Shared nodes are merged and unused ones never created; every tet is positively oriented, and
/// the tets cover exactly the union of the kept cells (total volume #cells·h³).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/tri_mesh.hpp"
#include "cell_split.hpp"
#include "voxelize.hpp"

namespace simsr::discretize {

/// A tetrahedralized set of voxels.
template <class S = Scalar>
struct Lattice {
  TetMesh<S> mesh;     ///< #V nodes, #T positively oriented tets
  VoxelSet cells;      ///< the kept cells; cell c is cells.cells[c]
  /// Doubled integer lattice coordinates, #V×3: node v sits at cells.grid.origin + (h/2)·node_coords.row(v)
  /// (even = cube corner, odd = cube centre).
  Eigen::Matrix<std::int64_t, Eigen::Dynamic, 3, Eigen::RowMajor> node_coords;
  /// Cell → tets (CSR): the tets overlapping cell c are cell_tets[cell_offsets[c] .. cell_offsets[c+1]).
  /// A BCC face tet is listed by both cells it straddles.
  std::vector<Index> cell_offsets{0};
  std::vector<VIndex> cell_tets;
  /// Tet → the cell that emitted it (for a BCC face tet, the lower of its two cells).
  IndexVector tet_cell;

  Index num_cells() const { return cells.size(); }
};

namespace detail {

/// Exact sign of the determinant of (b−a, c−a, d−a) in integer coordinates.
inline int orientation(const std::array<NodeCoord, 4>& p) {
  std::int64_t m[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[r][c] = p[r + 1][c] - p[0][c];
  const __int128 det = __int128(m[0][0]) * (__int128(m[1][1]) * m[2][2] - __int128(m[1][2]) * m[2][1]) -
                       __int128(m[0][1]) * (__int128(m[1][0]) * m[2][2] - __int128(m[1][2]) * m[2][0]) +
                       __int128(m[0][2]) * (__int128(m[1][0]) * m[2][1] - __int128(m[1][1]) * m[2][0]);
  return det > 0 ? 1 : (det < 0 ? -1 : 0);
}

}  // namespace detail

/// Tetrahedralizes every kept cell of `cells` with the split policy `Split` (cell_split.hpp).
/// Throws ArgumentError for an empty cell set.
template <CellSplit Split = BccSplit, class S = Scalar>
Lattice<S> build_lattice(const VoxelSet& cells) {
  if (cells.cells.empty()) throw ArgumentError("build_lattice: no kept cells (h too large, or the region mask excludes everything?)");
  const Grid& g = cells.grid;
  // Kept-cell index by grid cell, through binary search on the sorted linear indices.
  std::vector<Index> linear(cells.cells.size());
  for (std::size_t c = 0; c < linear.size(); ++c) linear[c] = g.linear(cells.cells[c][0], cells.cells[c][1], cells.cells[c][2]);
  if (!std::is_sorted(linear.begin(), linear.end())) throw ArgumentError("build_lattice: cells are not sorted by linear index");
  const auto find = [&](std::array<Index, 3> ijk) -> Index {
    for (int a = 0; a < 3; ++a)
      if (ijk[a] < 0 || ijk[a] >= g.dims[a]) return -1;
    const Index l = g.linear(ijk[0], ijk[1], ijk[2]);
    const auto it = std::lower_bound(linear.begin(), linear.end(), l);
    return it != linear.end() && *it == l ? Index(it - linear.begin()) : -1;
  };
  // Node keys: doubled coordinates packed row-major over the (2n+1)³ node grid.
  const std::int64_t nx = 2 * g.dims[0] + 1, ny = 2 * g.dims[1] + 1;
  const auto key = [&](const NodeCoord& n) { return n[0] + nx * (n[1] + ny * n[2]); };
  std::vector<std::int64_t> tet_keys;
  std::vector<std::pair<Index, Index>> tet_cells;  // (emitting cell, other cell or −1)
  tet_keys.reserve(cells.cells.size() * 4 * (Split::uses_centres ? 12 : 6));
  for (Index c = 0; c < cells.size(); ++c) {
    const auto ijk = cells.cells[c];
    const auto nb = [&](int axis, int dir) {
      auto n = ijk;
      n[axis] += dir;
      return find(n);
    };
    const CellContext<decltype(nb)> ctx{ijk, c, nb};
    Split::split(ctx, [&](std::array<NodeCoord, 4> t, Index other) {
      if (detail::orientation(t) < 0) std::swap(t[2], t[3]);
      for (const auto& n : t) tet_keys.push_back(key(n));
      tet_cells.push_back({c, other});
    });
  }
  std::vector<std::int64_t> nodes = tet_keys;
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  Lattice<S> L;
  L.cells = cells;
  L.mesh.V.resize(Index(nodes.size()), 3);
  L.node_coords.resize(Index(nodes.size()), 3);
  const double half = 0.5 * g.h;
  for (Index v = 0; v < Index(nodes.size()); ++v) {
    const std::int64_t n = nodes[v], N[3] = {n % nx, (n / nx) % ny, n / (nx * ny)};
    for (int a = 0; a < 3; ++a) {
      L.node_coords(v, a) = N[a];
      L.mesh.V(v, a) = S(g.origin[a] + half * double(N[a]));
    }
  }
  const Index nt = Index(tet_cells.size());
  L.mesh.T.resize(nt, 4);
  for (Index t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c)
      L.mesh.T(t, c) = VIndex(std::lower_bound(nodes.begin(), nodes.end(), tet_keys[std::size_t(4 * t + c)]) - nodes.begin());
  L.tet_cell.resize(nt);
  L.cell_offsets.assign(std::size_t(cells.size() + 1), 0);
  for (Index t = 0; t < nt; ++t) {
    L.tet_cell[t] = VIndex(tet_cells[t].first);
    ++L.cell_offsets[tet_cells[t].first + 1];
    if (tet_cells[t].second >= 0) ++L.cell_offsets[tet_cells[t].second + 1];
  }
  for (Index c = 0; c < cells.size(); ++c) L.cell_offsets[c + 1] += L.cell_offsets[c];
  L.cell_tets.resize(std::size_t(L.cell_offsets.back()));
  std::vector<Index> fill(L.cell_offsets.begin(), L.cell_offsets.end() - 1);
  for (Index t = 0; t < nt; ++t) {
    L.cell_tets[fill[tet_cells[t].first]++] = VIndex(t);
    if (tet_cells[t].second >= 0) L.cell_tets[fill[tet_cells[t].second]++] = VIndex(t);
  }
  return L;
}

/// Voxelizes the closed `surface` at cell size h (voxelize.hpp: cells overlapping the enclosed
/// volume, `options.region` mask) and tetrahedralizes the kept cells with `Split` (default BCC).
template <CellSplit Split = BccSplit, class S>
Lattice<S> bcc_lattice(const TriMesh<S>& surface, double h, const VoxelizeOptions& options = {}) {
  return build_lattice<Split, S>(voxelize(surface, h, options));
}

/// As above for the cells overlapping a tet mesh (the paper voxelizes its HR conforming mesh).
template <CellSplit Split = BccSplit, class S>
Lattice<S> bcc_lattice(const TetMesh<S>& mesh, double h, const VoxelizeOptions& options = {}) {
  return build_lattice<Split, S>(voxelize(mesh, h, options));
}

/// Which nodes of `lattice` lie inside the closed `surface` (winding number ≠ 0): one flag per
/// node (nodes on the surface may go either way). Corners and centres each form a regular grid,
/// so this is two row-crossing passes, O(#F + #nodes), not a ray per node. MeshError for an open
/// surface.
template <class S, class S2>
std::vector<char> lattice_nodes_inside(const Lattice<S>& lattice, const TriMesh<S2>& surface) {
  detail::check_closed_surface(surface.F);
  const auto& C = lattice.node_coords;
  std::vector<char> out(std::size_t(C.rows()), 0);
  const double h = lattice.cells.grid.h;
  for (int parity = 0; parity < 2; ++parity) {  // 0: corners (even), 1: centres (odd)
    std::array<std::int64_t, 3> lo{}, hi{};
    bool any = false;
    for (Index v = 0; v < C.rows(); ++v) {
      if (std::int64_t(C(v, 0) & 1) != parity) continue;
      for (int d = 0; d < 3; ++d) {
        lo[std::size_t(d)] = any ? std::min(lo[std::size_t(d)], C(v, d)) : C(v, d);
        hi[std::size_t(d)] = any ? std::max(hi[std::size_t(d)], C(v, d)) : C(v, d);
      }
      any = true;
    }
    if (!any) continue;
    const std::array<Index, 3> n{Index((hi[0] - lo[0]) / 2 + 1), Index((hi[1] - lo[1]) / 2 + 1), Index((hi[2] - lo[2]) / 2 + 1)};
    const Vec3<double> o = lattice.cells.grid.origin + 0.5 * h * Vec3<double>(double(lo[0]), double(lo[1]), double(lo[2]));
    const auto in = detail::inside_on_grid(surface.V, surface.F, o, h, n);
    for (Index v = 0; v < C.rows(); ++v) {
      if (std::int64_t(C(v, 0) & 1) != parity) continue;
      const Index i = Index((C(v, 0) - lo[0]) / 2), j = Index((C(v, 1) - lo[1]) / 2), k = Index((C(v, 2) - lo[2]) / 2);
      out[std::size_t(v)] = in[std::size_t(i + n[0] * (j + n[1] * k))];
    }
  }
  return out;
}

/// Nodes of the infinite BCC lattice of spacing h (corners anchor + h·ℤ³, centres
/// anchor + h·(ℤ + ½)³) strictly inside the closed `surface` (winding number ≠ 0), corners first,
/// each group in (k, j, i) order. #P×3.
template <class S>
Points<S> bcc_nodes_inside(const TriMesh<S>& surface, double h, const Vec3<double>& anchor = Vec3<double>::Zero(),
                           Index max_nodes = Index(1) << 26) {
  detail::check_closed_surface(surface.F);
  VoxelizeOptions opt;
  opt.anchor = anchor;
  opt.max_cells = max_nodes / 2;
  const Grid g = detail::make_grid(surface.V, h, opt, "bcc_nodes_inside");
  std::vector<Vec3<double>> out;
  for (int centre = 0; centre < 2; ++centre) {
    const std::array<Index, 3> n{g.dims[0] + 1 - centre, g.dims[1] + 1 - centre, g.dims[2] + 1 - centre};
    const Vec3<double> o = g.origin + Vec3<double>::Constant(0.5 * h * centre);
    const auto in = detail::inside_on_grid(surface.V, surface.F, o, h, n);
    for (Index k = 0; k < n[2]; ++k)
      for (Index j = 0; j < n[1]; ++j)
        for (Index i = 0; i < n[0]; ++i)
          if (in[std::size_t(i + n[0] * (j + n[1] * k))]) out.push_back(o + h * Vec3<double>(double(i), double(j), double(k)));
  }
  Points<S> P(Index(out.size()), 3);
  for (Index p = 0; p < P.rows(); ++p) P.row(p) = out[p].template cast<S>().transpose();
  return P;
}

/// Exactly `count` BCC lattice nodes inside the closed `surface`: the spacing h is found by
/// bisection as (nearly) the largest one whose lattice puts ≥ count nodes inside, and the surplus
/// is trimmed from the outside — nodes sorted by their normalized radius
/// ‖(x − c) ⊘ e‖ (c, e = the surface's bounding-box centre and half-extents: the ellipsoidal
/// radius for an axis-aligned ellipsoid), innermost first (stable). `h_out` receives the spacing.
/// Throws ArgumentError for count < 1 or when even a fine lattice (≥ max_nodes) cannot hold count.
template <class S>
Points<S> bcc_points_inside(const TriMesh<S>& surface, Index count, double* h_out = nullptr, Index max_nodes = Index(1) << 26) {
  if (count < 1) throw ArgumentError("bcc_points_inside: count must be at least 1, got " + std::to_string(count));
  detail::check_closed_surface(surface.F);
  const Vec3<double> lo = surface.V.colwise().minCoeff().transpose().template cast<double>();
  const Vec3<double> hi = surface.V.colwise().maxCoeff().transpose().template cast<double>();
  const Vec3<double> c = 0.5 * (lo + hi), e = (0.5 * (hi - lo)).cwiseMax(1e-300);
  const auto inside = [&](double h) { return bcc_nodes_inside(surface, h, Vec3<double>::Zero(), max_nodes); };
  double h_hi = (hi - lo).maxCoeff(), h_lo = h_hi;
  Points<S> best = inside(h_lo);
  while (best.rows() < count) {
    h_hi = h_lo;
    h_lo *= 0.5;
    if (8.0 * double(count) > double(max_nodes)) throw ArgumentError("bcc_points_inside: " + std::to_string(count) + " nodes exceed max_nodes");
    best = inside(h_lo);
  }
  for (int it = 0; it < 40 && best.rows() != count; ++it) {
    const double mid = 0.5 * (h_lo + h_hi);
    Points<S> P = inside(mid);
    if (P.rows() >= count) {
      h_lo = mid;
      best = std::move(P);
    } else {
      h_hi = mid;
    }
  }
  if (h_out) *h_out = h_lo;
  std::vector<std::pair<double, Index>> order(std::size_t(best.rows()));
  for (Index p = 0; p < best.rows(); ++p)
    order[p] = {((best.row(p).transpose().template cast<double>() - c).cwiseQuotient(e)).norm(), p};
  std::stable_sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  Points<S> P(count, 3);
  for (Index p = 0; p < count; ++p) P.row(p) = best.row(order[p].second);
  return P;
}

}  // namespace simsr::discretize
