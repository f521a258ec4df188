#pragma once
/// \file
/// Point location in a tet mesh: which tet contains a point (barycentric weights), and which tet
/// is nearest to a point outside every tet (exact point–tetrahedron distance).
///
///     simsr::TetLocator<> loc(mesh);                  // MeshError on degenerate tets
///     Eigen::Vector4d w;
///     Index t = loc.locate(p, w);                      // lowest containing tet id, or -1
///     auto [tn, d] = loc.nearest(p);                   // nearest tet and its distance
///
/// Thread safety: a built locator is immutable; every const member may be called concurrently.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../mesh/tet_mesh.hpp"
#include "../mesh/validate.hpp"
#include "detail/embedding_geometry.hpp"

namespace simsr {

/// Options of TetLocator.
struct TetLocatorOptions {
  /// A point is inside a tet when all its barycentric weights are ≥ −inside_tolerance
  /// (dimensionless: a fraction of the tet's height over each face). Points on shared faces,
  /// edges and vertices are inside several tets; the lowest tet id wins.
  double inside_tolerance = 1e-10;
  /// A tet is degenerate when |volume| ≤ tol·ℓ³ (ℓ its longest edge), as in ValidateOptions.
  double degenerate_tolerance = 1e-10;
  /// Grid cell edge as a multiple of the mean tet bounding-box edge (> 0). 1 lists each tet in
  /// ~8 cells; on a 73k-tet lattice 0.75–1 is fastest (0.5 or 2 are 1.3–1.7× slower).
  double cell_scale = 1.0;
};

/// Nearest tet of a point: its id and exact Euclidean distance (0 when inside).
template <class S>
struct NearestTet {
  Index tet = -1;
  S distance = S(0);
};

/// Spatial index over the tets of a TetMesh for point location and nearest-tet queries.
///
/// Index: a uniform grid over tet bounding boxes (each tet listed in every cell its box overlaps,
/// cells stored CSR, tets in increasing id per cell). Why a grid and not a BVH: the meshes
/// embedded into here are BCC/cube-split lattices and volume meshes of nearly uniform element
/// size, so a cell the size of a tet's box holds O(1) tets and a query is one cell lookup with no
/// tree descent; building is two linear passes (count, fill). For strongly graded meshes a BVH
/// would adapt better; `cell_scale` trades memory against candidates per cell.
///
/// Per tet the four corners and the inverse edge matrix are stored contiguously (a candidate test
/// is 9 multiply-adds without touching the mesh), the bounding boxes in a separate compact array.
template <class S = Scalar>
class TetLocator {
 public:
  using scalar_type = S;
  using Weights = detail::Vec4<S>;

  TetLocator() = default;

  /// Builds the index. Throws MeshError for an empty mesh, non-finite vertices, out-of-range or
  /// repeated indices and degenerate tets (naming the first); inverted tets are accepted.
  explicit TetLocator(const TetMesh<S>& mesh, const TetLocatorOptions& options = {}) : options_(options) {
    if (!(options.inside_tolerance >= 0)) throw ArgumentError("TetLocator: inside_tolerance must be ≥ 0");
    if (!(options.cell_scale > 0)) throw ArgumentError("TetLocator: cell_scale must be > 0");
    check_mesh(mesh);
    build(mesh);
  }

  Index num_tets() const { return num_tets_; }
  /// Grid resolution (cells per axis).
  const std::array<Index, 3>& grid_size() const { return n_; }
  /// Grid cell edge length (mesh units).
  S cell_size() const { return h_; }
  /// Total (tet, cell) entries of the grid: the memory of the index and the average tets per cell.
  Index num_entries() const { return Index(items_.size()); }
  const TetLocatorOptions& options() const { return options_; }

  /// Corner k (0..3) of tet t.
  Vec3<S> corner(Index t, int k) const { return Eigen::Map<const Vec3<S>>(rec(t) + 3 * k); }

  /// Barycentric weights of p in tet t (w0 = 1 − w1 − w2 − w3; they reproduce p exactly in
  /// exact arithmetic, also outside the tet, where some are negative).
  Weights barycentric(Index t, const Vec3<S>& p) const {
    const S* r = rec(t);
    const Vec3<S> d = p - Eigen::Map<const Vec3<S>>(r);
    const S* m = r + kInv;
    const S l1 = m[0] * d[0] + m[1] * d[1] + m[2] * d[2];
    const S l2 = m[3] * d[0] + m[4] * d[1] + m[5] * d[2];
    const S l3 = m[6] * d[0] + m[7] * d[1] + m[8] * d[2];
    return {S(1) - l1 - l2 - l3, l1, l2, l3};
  }

  /// Exact distance from p to tet t (0 inside); `closest` gets the barycentrics of the closest point.
  S distance(Index t, const Vec3<S>& p, Weights* closest = nullptr) const {
    return std::sqrt(detail::point_tet_sqdist(p, corners(t), barycentric(t, p), closest));
  }

  /// Is p inside tet t within the inside tolerance? `w` receives its weights either way.
  bool contains(Index t, const Vec3<S>& p, Weights& w) const {
    w = barycentric(t, p);
    return (w.array() >= -S(options_.inside_tolerance)).all();
  }

  /// The lowest id of the tets containing p (see TetLocatorOptions::inside_tolerance), or −1;
  /// `w` receives p's weights in that tet.
  Index locate(const Vec3<S>& p, Weights& w) const {
    if (num_tets_ == 0) return -1;
    for (int k = 0; k < 3; ++k)
      if (p[k] < lo_[k] || p[k] > hi_[k]) return -1;
    const Index c = cell_index(cell_of(p, 0), cell_of(p, 1), cell_of(p, 2));
    for (Index i = start_[std::size_t(c)]; i < start_[std::size_t(c) + 1]; ++i) {
      const Index t = items_[std::size_t(i)];
      if (in_box(t, p) && contains(t, p, w)) return t;
    }
    return -1;
  }

  /// The tet nearest to p by exact point–tet distance; ties (equal computed distance) go to the
  /// lowest id. Searches grid rings around p's cell until no unvisited cell can hold a closer tet.
  NearestTet<S> nearest(const Vec3<S>& p) const {
    NearestTet<S> out;
    if (num_tets_ == 0) return out;
    const std::array<Index, 3> c{cell_of(p, 0), cell_of(p, 1), cell_of(p, 2)};
    S best = std::numeric_limits<S>::infinity();  // squared
    Index best_t = -1;
    const S margin = S(1e-12) * (hi_ - lo_).norm();
    auto visit_cell = [&](Index i, Index j, Index k) {
      const Vec3<S> clo = lo_ + h_ * Vec3<S>(S(i), S(j), S(k));
      const S cd = std::sqrt(detail::point_box_sqdist<S>(p, clo, (clo.array() + h_).matrix()));
      if (best_t >= 0 && cd > std::sqrt(best) + margin) return;
      const Index cell = cell_index(i, j, k);
      for (Index e = start_[std::size_t(cell)]; e < start_[std::size_t(cell) + 1]; ++e) {
        const Index t = items_[std::size_t(e)];
        if (t == best_t) continue;
        const S* bx = box(t);
        const S bd = detail::point_box_sqdist<S>(p, Eigen::Map<const Vec3<S>>(bx), Eigen::Map<const Vec3<S>>(bx + 3));
        if (bd > best) continue;
        const S d2 = detail::point_tet_sqdist(p, corners(t), barycentric(t, p));
        if (d2 < best || (d2 == best && t < best_t)) {
          best = d2;
          best_t = t;
        }
      }
    };
    const Index rmax = std::max({n_[0], n_[1], n_[2]});
    for (Index r = 0; r <= rmax; ++r) {
      std::array<Index, 3> a, b;
      for (int d = 0; d < 3; ++d) {
        a[d] = std::max<Index>(0, c[d] - r);
        b[d] = std::min<Index>(n_[d] - 1, c[d] + r);
      }
      for (Index k = a[2]; k <= b[2]; ++k)
        for (Index j = a[1]; j <= b[1]; ++j) {
          const bool shell_jk = std::abs(k - c[2]) == r || std::abs(j - c[1]) == r;
          if (shell_jk) {
            for (Index i = a[0]; i <= b[0]; ++i) visit_cell(i, j, k);
          } else {
            if (c[0] - r >= 0) visit_cell(c[0] - r, j, k);
            if (r > 0 && c[0] + r < n_[0]) visit_cell(c[0] + r, j, k);
          }
        }
      // Every tet not yet seen lies in a slab of the grid outside rings 0..r.
      S bound = std::numeric_limits<S>::infinity();
      for (int d = 0; d < 3; ++d) {
        if (a[d] > 0) {
          Vec3<S> shi = hi_;
          shi[d] = lo_[d] + h_ * S(a[d]);
          bound = std::min(bound, detail::point_box_sqdist<S>(p, lo_, shi));
        }
        if (b[d] < n_[d] - 1) {
          Vec3<S> slo = lo_;
          slo[d] = lo_[d] + h_ * S(b[d] + 1);
          bound = std::min(bound, detail::point_box_sqdist<S>(p, slo, hi_));
        }
      }
      if (!std::isfinite(bound)) break;
      if (best_t >= 0 && std::sqrt(best) + margin < std::sqrt(bound)) break;
    }
    out.tet = best_t;
    out.distance = std::sqrt(best);
    return out;
  }

 private:
  static constexpr int kInv = 12, kStride = 21;  // corners 0..11, inverse edge matrix 12..20

  const S* rec(Index t) const { return data_.data() + std::size_t(t) * kStride; }
  /// Padded bounding box of tet t: lo xyz, hi xyz (kept apart from the records: the cheap reject
  /// of most candidates touches 48 bytes instead of a 168-byte record).
  const S* box(Index t) const { return boxes_.data() + std::size_t(t) * 6; }
  bool in_box(Index t, const Vec3<S>& p) const {
    const S* b = box(t);
    return p[0] >= b[0] && p[1] >= b[1] && p[2] >= b[2] && p[0] <= b[3] && p[1] <= b[4] && p[2] <= b[5];
  }
  std::array<Vec3<S>, 4> corners(Index t) const {
    const S* r = rec(t);
    return {Vec3<S>(r[0], r[1], r[2]), Vec3<S>(r[3], r[4], r[5]), Vec3<S>(r[6], r[7], r[8]), Vec3<S>(r[9], r[10], r[11])};
  }
  Index cell_of(const Vec3<S>& p, int d) const {
    const S x = std::floor((p[d] - lo_[d]) / h_);
    if (!(x >= S(0))) return 0;
    return std::min<Index>(n_[d] - 1, Index(x));
  }
  Index cell_index(Index i, Index j, Index k) const { return i + n_[0] * (j + n_[1] * k); }

  void check_mesh(const TetMesh<S>& mesh) {
    if (mesh.T.rows() == 0) throw MeshError("tet mesh", -1, "empty (no tets): nothing to embed into");
    for (Index v = 0; v < mesh.V.rows(); ++v)
      if (!mesh.V.row(v).allFinite()) throw MeshError("vertex", v, "non-finite coordinate");
    for (Index t = 0; t < mesh.T.rows(); ++t) {
      S vol{};
      switch (detail::classify<4>(mesh.V, mesh.T, t, options_.degenerate_tolerance, vol)) {
        case detail::ElementProblem::out_of_range:
          throw MeshError("tet", t, "vertex index outside [0, " + std::to_string(mesh.V.rows()) + ")");
        case detail::ElementProblem::repeated: throw MeshError("tet", t, "repeated vertex");
        case detail::ElementProblem::degenerate:
          throw MeshError("tet", t, "degenerate (volume " + std::to_string(double(vol)) + "): no barycentric coordinates");
        default: break;
      }
    }
  }

  void build(const TetMesh<S>& mesh) {
    num_tets_ = mesh.T.rows();
    data_.assign(std::size_t(num_tets_) * kStride, S(0));
    boxes_.assign(std::size_t(num_tets_) * 6, S(0));
    lo_.setConstant(std::numeric_limits<S>::infinity());
    hi_.setConstant(-std::numeric_limits<S>::infinity());
    Vec3<S> mean_extent = Vec3<S>::Zero();
    const S tol = S(options_.inside_tolerance);
    for (Index t = 0; t < num_tets_; ++t) {
      S* r = data_.data() + std::size_t(t) * kStride;
      std::array<Vec3<S>, 4> x;
      for (int k = 0; k < 4; ++k) {
        x[std::size_t(k)] = mesh.V.row(mesh.T(t, k)).transpose();
        for (int d = 0; d < 3; ++d) r[3 * k + d] = x[std::size_t(k)][d];
      }
      Mat3<S> E;
      for (int k = 0; k < 3; ++k) E.col(k) = x[std::size_t(k) + 1] - x[0];
      const Mat3<S> inv = E.inverse();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r[kInv + 3 * i + j] = inv(i, j);
      Vec3<S> blo = x[0], bhi = x[0];
      for (int k = 1; k < 4; ++k) {
        blo = blo.cwiseMin(x[std::size_t(k)]);
        bhi = bhi.cwiseMax(x[std::size_t(k)]);
      }
      mean_extent += bhi - blo;
      // Pad by the distance a point with weights ≥ −tol can lie outside (≤ tol · longest edge).
      const S pad = tol * (bhi - blo).norm() * S(2) + std::numeric_limits<S>::epsilon() * bhi.cwiseAbs().maxCoeff();
      blo.array() -= pad;
      bhi.array() += pad;
      S* bx = boxes_.data() + std::size_t(t) * 6;
      for (int d = 0; d < 3; ++d) {
        bx[d] = blo[d];
        bx[3 + d] = bhi[d];
      }
      lo_ = lo_.cwiseMin(blo);
      hi_ = hi_.cwiseMax(bhi);
    }
    mean_extent /= S(num_tets_);
    h_ = S(options_.cell_scale) * mean_extent.mean();
    const Vec3<S> ext = hi_ - lo_;
    const S max_cells = S(8) * S(num_tets_) + S(64);
    if (!(h_ > S(0))) h_ = ext.maxCoeff();
    auto dims = [&] {
      for (int d = 0; d < 3; ++d) n_[std::size_t(d)] = std::max<Index>(1, Index(std::ceil(ext[d] / h_)));
    };
    dims();
    while (S(n_[0]) * S(n_[1]) * S(n_[2]) > max_cells) {
      h_ *= S(1.25);
      dims();
    }
    const std::size_t cells = std::size_t(n_[0] * n_[1] * n_[2]);
    start_.assign(cells + 1, 0);
    auto for_cells = [&](Index t, auto&& f) {
      const S* bx = box(t);
      const Vec3<S> blo(bx[0], bx[1], bx[2]), bhi(bx[3], bx[4], bx[5]);
      const Index i0 = cell_of(blo, 0), i1 = cell_of(bhi, 0), j0 = cell_of(blo, 1), j1 = cell_of(bhi, 1),
                  k0 = cell_of(blo, 2), k1 = cell_of(bhi, 2);
      for (Index k = k0; k <= k1; ++k)
        for (Index j = j0; j <= j1; ++j)
          for (Index i = i0; i <= i1; ++i) f(cell_index(i, j, k));
    };
    for (Index t = 0; t < num_tets_; ++t) for_cells(t, [&](Index c) { ++start_[std::size_t(c) + 1]; });
    for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    items_.resize(std::size_t(start_[cells]));
    std::vector<Index> fill(start_.begin(), start_.end() - 1);
    for (Index t = 0; t < num_tets_; ++t)
      for_cells(t, [&](Index c) { items_[std::size_t(fill[std::size_t(c)]++)] = VIndex(t); });
  }

  TetLocatorOptions options_{};
  Index num_tets_ = 0;
  std::vector<S> data_;
  std::vector<S> boxes_;
  Vec3<S> lo_ = Vec3<S>::Zero(), hi_ = Vec3<S>::Zero();
  S h_ = S(1);
  std::array<Index, 3> n_{1, 1, 1};
  std::vector<Index> start_;
  std::vector<VIndex> items_;
};

}  // namespace simsr
