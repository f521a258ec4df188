#pragma once
/// \file
/// Surface self-contact of designated regions (SPEC §3: HR only, the lips; the LR mesh skips
/// collisions as in Park et al. 2023 §4): a vertex–triangle penalty between a set of surface
/// vertices and a set of surface triangles. For each pair (p, t) closer than the contact
/// thickness d̂, with d the unsigned point–triangle distance:
///
///     E(x) = Σ_{(p,t): d < d̂_p} k/2 (d̂_p − d)²               (J; k in N/m, d̂ in m)
///
/// d̂_p is one thickness for every vertex, or one per vertex: surfaces that nearly touch at rest
/// (the corners of the mouth) take d̂_p below each vertex's rest distance, so contact is off at
/// rest and still stops the surfaces crossing there, where a uniform d̂ would press them apart
/// from the start and leaving those vertices out lets them pass through.
///
///     physics::SelfContact<> lips(lip_vertices, lip_triangles, V.rows(), 1e3, 1e-3);
///     for (const auto& c : lips.pairs(x)) ...                // active pairs, for inspection
///
/// Pairs are found at each call with a spatial hash (uniform grid of cell size h ≥ d̂, integer
/// cells hashed into buckets; triangles inserted by their bounding box inflated by d̂, so a vertex
/// only looks in its own cell): no O(V·T) loop. (A triangle spanning more than 2¹⁶ cells, which
/// only a wild configuration makes, is checked against every vertex instead.) A vertex never pairs with a triangle it is a
/// corner of and, by default, not with one whose corner it shares an edge with.
///
/// Derivatives: with q = Σ β_i x_{t_i} the exact closest point (Ericson's 7 regions: face, 3
/// edges, 3 vertices) and n = (p − q)/d, ∂d/∂p = n and ∂d/∂x_{t_i} = −β_i n (the gradient is
/// exact). The Hessian is the Gauss–Newton part k ∇d ∇dᵀ over the 4 vertices; the dropped term
/// −k (d̂ − d) ∇²d is negative semi-definite (d is convex in p), so dropping it is a PSD projection.
/// Unsigned distance: a vertex that has crossed a triangle is pushed on through it, and one near
/// an edge shared by two designated triangles is pushed by both. The energy is C¹ except at d = 0.
///
/// Thread safety: the const methods reuse mutable hash buffers (no reallocations once warm), so
/// one object must not be evaluated from two threads at once; copies are independent.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../../core/types.hpp"
#include "../../discretize/detail/embedding_geometry.hpp"
#include "../energy_term.hpp"
#include "detail/checks.hpp"

namespace simsr::physics {

/// Options of SelfContact.
struct SelfContactOptions {
  /// Also skip a vertex and a triangle when the vertex shares an edge (of the designated
  /// triangles) with one of its corners: at rest such a pair sits about one edge length apart,
  /// and with d̂ near the edge length it would repel permanently.
  bool exclude_adjacent = true;
  /// Hash cell size h (m); 0: max(d̂, mean longest edge of the designated triangles at x), so a
  /// triangle spans few cells. Any positive h is correct; it only changes the speed.
  double cell_size = 0;
};

/// An active contact: vertex (index into x), triangle (row of the designated triangles), the
/// point–triangle distance (m) and the barycentric weights of the closest point (≥ 0, sum 1).
template <class S = Scalar>
struct SelfContactPair {
  VIndex vertex;
  Index triangle;
  S distance;
  Vec3<S> barycentric;
  S thickness;  ///< the vertex's d̂
};

/// Exact closest point of triangle (a, b, c) to p: barycentric weights (≥ 0, sum 1; all 7 regions).
template <class S>
Vec3<S> closest_point_barycentric(const Vec3<S>& p, const Vec3<S>& a, const Vec3<S>& b, const Vec3<S>& c) {
  return simsr::detail::closest_on_triangle(p, a, b, c);
}

/// Vertex–triangle penalty self-contact (see the file comment).
template <class S = Scalar>
class SelfContact {
 public:
  using scalar_type = S;

  /// vertices (#P, indices into x), triangles (#F×3, indices into x), k (N/m, finite, ≥ 0),
  /// thickness d̂ (m, finite, > 0). ArgumentError for an index out of range, a bad k, d̂ or cell size.
  SelfContact(const IndexVector& vertices, const Tris& triangles, Index num_vertices, S stiffness, S thickness, SelfContactOptions options = {})
      : SelfContact(vertices, triangles, num_vertices, stiffness, VecX<S>::Constant(vertices.size(), thickness), options) {}

  /// As above with one thickness per vertex (thicknesses[i] is vertices[i]'s d̂, each finite and
  /// > 0); ShapeError when the counts differ.
  SelfContact(const IndexVector& vertices, const Tris& triangles, Index num_vertices, S stiffness, const VecX<S>& thicknesses,
              SelfContactOptions options = {})
      : v_(vertices), F_(triangles), n_(num_vertices), k_(stiffness), dhat_v_(thicknesses), opt_(options) {
    detail::require_vertex_indices("SelfContact: vertices", v_, n_);
    detail::require_vertex_indices("SelfContact: triangles", F_, n_);
    detail::require_nonnegative("SelfContact: stiffness", k_);
    if (dhat_v_.size() != v_.size()) throw ShapeError("SelfContact: thicknesses", {v_.size(), 1}, {dhat_v_.size(), 1});
    for (Index i = 0; i < dhat_v_.size(); ++i) detail::require_positive("SelfContact: thickness of vertex " + std::to_string(v_[i]), dhat_v_[i]);
    dhat_ = dhat_v_.size() ? dhat_v_.maxCoeff() : S(1);
    detail::require_nonnegative("SelfContact: cell size", opt_.cell_size);
    if (opt_.exclude_adjacent) build_adjacency();
  }

  const IndexVector& vertices() const { return v_; }
  const Tris& triangles() const { return F_; }
  Index num_vertices() const { return n_; }
  S stiffness() const { return k_; }
  /// The largest d̂ (the only one when it is uniform).
  S thickness() const { return dhat_; }
  /// Each vertex's d̂, in the order of vertices().
  const VecX<S>& thicknesses() const { return dhat_v_; }
  const SelfContactOptions& options() const { return opt_; }

  /// The active pairs (d < the vertex's d̂) at x, grouped by vertex in the order of vertices().
  std::vector<SelfContactPair<S>> pairs(const Points<S>& x) const {
    detail::require_positions("SelfContact: x", x, n_);
    std::vector<SelfContactPair<S>> out;
    for_each_pair(x, [&](const SelfContactPair<S>& c, const Vec3<S>&) { out.push_back(c); });
    return out;
  }

  template <exec::HostPolicy P>
  S energy(P, const Points<S>& x) const {
    detail::require_positions("SelfContact: x", x, n_);
    S e = S(0);
    for_each_pair(x, [&](const SelfContactPair<S>& c, const Vec3<S>&) { e += k_ / S(2) * (c.thickness - c.distance) * (c.thickness - c.distance); });
    return e;
  }

  template <exec::HostPolicy P>
  void add_gradient(P, const Points<S>& x, Points<S>& g) const {
    detail::require_positions("SelfContact: x", x, n_);
    detail::require_positions("SelfContact: gradient", g, n_);
    for_each_pair(x, [&](const SelfContactPair<S>& c, const Vec3<S>& n) {
      const Vec3<S> f = k_ * (c.thickness - c.distance) * n;  // −∂E/∂d · n
      g.row(c.vertex) -= f.transpose();
      for (int i = 0; i < 3; ++i) g.row(F_(c.triangle, i)) += c.barycentric[i] * f.transpose();
    });
  }

  /// Gauss–Newton blocks k c_a c_b n nᵀ, c = (1, −β₀, −β₁, −β₂) over (vertex, corners), for both
  /// Definiteness values (PSD; see the file comment).
  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>& H, Definiteness) const {
    detail::require_positions("SelfContact: x", x, n_);
    for_each_pair(x, [&](const SelfContactPair<S>& c, const Vec3<S>& n) {
      const VIndex idx[4] = {c.vertex, F_(c.triangle, 0), F_(c.triangle, 1), F_(c.triangle, 2)};
      const S w[4] = {S(1), -c.barycentric[0], -c.barycentric[1], -c.barycentric[2]};
      const Mat3<S> nn = k_ * n * n.transpose();
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
          if (w[a] != S(0) && w[b] != S(0)) H.add(idx[a], idx[b], (w[a] * w[b]) * nn);
    });
  }

 private:
  struct Cell {
    std::int64_t x, y, z;
    bool operator==(const Cell&) const = default;
  };
  struct Entry {
    Cell cell;
    VIndex tri;
  };

  /// Visits every active pair once: f(pair, n) with n the unit direction from the closest point
  /// to the vertex (the triangle's normal when d = 0; zero for a degenerate triangle then).
  template <class F>
  void for_each_pair(const Points<S>& x, F&& f) const {
    if (v_.size() == 0 || F_.rows() == 0) return;
    build_hash(x);
    const Index nb = Index(start_.size()) - 1;
    for (Index i = 0; i < v_.size(); ++i) {
      const VIndex v = v_[i];
      const Vec3<S> p = x.row(v).transpose();
      Cell c;
      if (!cell_of(p, c)) continue;
      const std::size_t b = bucket(c, nb);
      for (Index e = start_[b]; e < start_[b + 1]; ++e) {
        const Entry& en = sorted_[std::size_t(e)];
        if (en.cell == c) visit(x, v, p, dhat_v_[i], en.tri, f);
      }
      for (VIndex t : oversized_) visit(x, v, p, dhat_v_[i], t, f);
    }
  }

  template <class F>
  void visit(const Points<S>& x, VIndex v, const Vec3<S>& p, S dhat, VIndex t, F& f) const {
    if (excluded(v, t)) return;
    const Vec3<S> a = x.row(F_(t, 0)).transpose(), b = x.row(F_(t, 1)).transpose(), c = x.row(F_(t, 2)).transpose();
    const Vec3<S> beta = closest_point_barycentric(p, a, b, c);
    const Vec3<S> r = p - (beta[0] * a + beta[1] * b + beta[2] * c);
    const S d = r.norm();
    if (!(d < dhat)) return;
    Vec3<S> n;
    if (d > S(0)) {
      n = r / d;
    } else {
      const Vec3<S> m = (b - a).cross(c - a);
      n = m.norm() > S(0) ? Vec3<S>(m.normalized()) : Vec3<S>::Zero();
    }
    f(SelfContactPair<S>{v, Index(t), d, beta, dhat}, n);
  }

  bool excluded(VIndex v, VIndex t) const {
    for (int i = 0; i < 3; ++i) {
      const VIndex c = F_(t, i);
      if (c == v) return true;
      if (opt_.exclude_adjacent &&
          std::binary_search(nbr_.begin() + nbr_start_[std::size_t(c)], nbr_.begin() + nbr_start_[std::size_t(c) + 1], v))
        return true;
    }
    return false;
  }

  /// Vertex adjacency (CSR, sorted lists) of the edges of the designated triangles.
  void build_adjacency() {
    std::vector<std::pair<VIndex, VIndex>> e;
    e.reserve(std::size_t(6 * F_.rows()));
    for (Index t = 0; t < F_.rows(); ++t)
      for (int i = 0; i < 3; ++i) {
        const VIndex a = F_(t, i), b = F_(t, (i + 1) % 3);
        e.push_back({a, b});
        e.push_back({b, a});
      }
    std::sort(e.begin(), e.end());
    e.erase(std::unique(e.begin(), e.end()), e.end());
    nbr_start_.assign(std::size_t(n_) + 1, 0);
    for (const auto& [a, b] : e) ++nbr_start_[std::size_t(a) + 1];
    for (std::size_t i = 0; i < std::size_t(n_); ++i) nbr_start_[i + 1] += nbr_start_[i];
    nbr_.resize(e.size());
    for (std::size_t k = 0; k < e.size(); ++k) nbr_[k] = e[k].second;  // e is sorted by (a, b)
  }

  S cell_size(const Points<S>& x) const {
    if (opt_.cell_size > 0) return S(opt_.cell_size);
    S sum = S(0);
    Index n = 0;
    for (Index t = 0; t < F_.rows(); ++t) {
      S longest = S(0);
      for (int i = 0; i < 3; ++i) longest = std::max(longest, (x.row(F_(t, i)) - x.row(F_(t, (i + 1) % 3))).norm());
      if (std::isfinite(double(longest))) sum += longest, ++n;
    }
    return std::max(dhat_, n ? sum / S(n) : S(0));
  }

  /// Integer cell of p (coordinates clamped to ±2⁵⁰ cells); false for a non-finite p.
  bool cell_of(const Vec3<S>& p, Cell& c) const {
    std::int64_t k[3];
    for (int a = 0; a < 3; ++a) {
      const double s = std::floor(double(p[a]) * inv_h_);
      if (!std::isfinite(s)) return false;
      k[a] = std::int64_t(std::clamp(s, -1125899906842624.0, 1125899906842624.0));
    }
    c = {k[0], k[1], k[2]};
    return true;
  }

  static std::size_t bucket(const Cell& c, Index nb) {
    const std::uint64_t h = (std::uint64_t(c.x) * 73856093ull) ^ (std::uint64_t(c.y) * 19349663ull) ^ (std::uint64_t(c.z) * 83492791ull);
    return std::size_t((h ^ (h >> 29)) & std::uint64_t(nb - 1));
  }

  void build_hash(const Points<S>& x) const {
    inv_h_ = 1.0 / double(cell_size(x));
    entries_.clear();
    oversized_.clear();
    for (Index t = 0; t < F_.rows(); ++t) {
      Vec3<S> lo = x.row(F_(t, 0)).transpose(), hi = lo;
      for (int i = 1; i < 3; ++i) {
        lo = lo.cwiseMin(x.row(F_(t, i)).transpose());
        hi = hi.cwiseMax(x.row(F_(t, i)).transpose());
      }
      Cell a, b;
      if (!cell_of(Vec3<S>(lo.array() - dhat_), a) || !cell_of(Vec3<S>(hi.array() + dhat_), b)) continue;
      if (double(b.x - a.x + 1) * double(b.y - a.y + 1) * double(b.z - a.z + 1) > double(max_cells_per_triangle)) {
        oversized_.push_back(VIndex(t));  // a wild configuration: checked against every vertex instead
        continue;
      }
      for (std::int64_t cz = a.z; cz <= b.z; ++cz)
        for (std::int64_t cy = a.y; cy <= b.y; ++cy)
          for (std::int64_t cx = a.x; cx <= b.x; ++cx) entries_.push_back({{cx, cy, cz}, VIndex(t)});
    }
    std::size_t nb = 1;
    while (nb < entries_.size()) nb <<= 1;
    start_.assign(nb + 1, 0);
    bucket_of_.resize(entries_.size());
    for (std::size_t e = 0; e < entries_.size(); ++e) ++start_[(bucket_of_[e] = bucket(entries_[e].cell, Index(nb))) + 1];
    for (std::size_t b = 0; b < nb; ++b) start_[b + 1] += start_[b];
    sorted_.resize(entries_.size());
    fill_.assign(start_.begin(), start_.end() - 1);
    for (std::size_t e = 0; e < entries_.size(); ++e) sorted_[std::size_t(fill_[bucket_of_[e]]++)] = entries_[e];
  }

  IndexVector v_;
  Tris F_;
  Index n_;
  S k_;
  VecX<S> dhat_v_;
  S dhat_ = S(1);  ///< the largest d̂: the hash cells and the triangles' inflation
  SelfContactOptions opt_;
  std::vector<Index> nbr_start_;
  std::vector<VIndex> nbr_;
  // hash scratch (see the file comment on thread safety)
  mutable double inv_h_ = 1;
  static constexpr Index max_cells_per_triangle = 1 << 16;
  mutable std::vector<Entry> entries_, sorted_;
  mutable std::vector<VIndex> oversized_;
  mutable std::vector<std::size_t> bucket_of_;
  mutable std::vector<Index> start_, fill_;
};

static_assert(assert_energy_term<SelfContact<double>, double>());

}  // namespace simsr::physics
