#pragma once
/// \file
/// Exact 3-D k-nearest neighbours on a uniform grid of cells (a cell list): the 3-D kNN of the
/// upsampling neighbourhoods (k = 20 of 35,637 HR vertices among 15,872 LR ones) without a tree.
///
///     simsr::neighbors::GridKnn<double> grid(P);                // copies P in cell order
///     grid.query_into(simsr::exec::omp, Q, 20, r);              // r.indices, r.distances: #Q×20
///
/// Why a grid: for k = 20 in 3-D the answer lies within a few cells of the query, so a query reads
/// a few contiguous runs of points (the points are stored cell by cell) instead of descending a
/// tree, and the queries are taken in cell order, so consecutive queries read the same cells from
/// cache. Same answers as KdTree, bitwise: the same squared distances (the same expression as
/// nanoflann's L2 metric on the same coordinates, in S), the same (distance, index) order, the
/// same square roots (detail::finish_knn_row).

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "../core/parallel.hpp"
#include "kd_tree.hpp"
#include "knn_result.hpp"

namespace simsr::neighbors {

/// Exact Euclidean kNN in 3-D over points binned into cubic cells (S = float or double).
///
/// Exactness: a query visits cells ring by ring (Chebyshev rings around its cell) and skips a cell
/// whose box is farther than its current k-th distance; it stops once the k-th squared distance is
/// below the squared distance to the outside of the rings visited. Both tests keep a margin far
/// above the rounding of the cell boxes (1e-9 of the grid's extent), so no point that could enter
/// the k nearest, or tie with the k-th, is left unvisited. Ties: ascending index, as KdTree.
///
/// Lifetime and threads: the points are copied (cell order), so P need not outlive the grid. A
/// query keeps the query order in the object's scratch: one object must not run two queries at
/// once (exec::omp inside one query is fine). The result of a row never depends on the thread.
template <class S = Scalar>
class GridKnn {
  static_assert(std::is_same_v<S, float> || std::is_same_v<S, double>, "simsr::neighbors::GridKnn works on float or double points");

 public:
  using scalar_type = S;
  using point_matrix = Points<S>;  ///< #P×3, row-major
  static constexpr Index dimension = 3;

  struct Params {
    double points_per_cell = 2.0;  ///< mean occupancy the cell size aims at (1–4 are all close for k = 20)
  };

  GridKnn() = default;
  explicit GridKnn(const point_matrix& P, Params params = {}) { build(P, params); }

  /// Bins P (#P×3; copied). ArgumentError for a non-finite coordinate or points_per_cell ≤ 0.
  void build(const point_matrix& P, Params params = {}) {
    constexpr const char* where = "neighbors::GridKnn::build";
    if (!(params.points_per_cell > 0) || !std::isfinite(params.points_per_cell))
      throw ArgumentError(std::string(where) + ": points_per_cell must be finite and > 0");
    if (P.rows() > Index(std::numeric_limits<VIndex>::max()))
      throw ArgumentError(std::string(where) + ": " + std::to_string(P.rows()) + " points exceed the 32-bit index range");
    detail::check_finite_rows(where, "points", P);
    const Index n = P.rows();
    n_ = n;
    if (n == 0) return;
    layout(P, params.points_per_cell);
    // counting sort of the points by cell
    std::vector<Index> cell(static_cast<std::size_t>(n));
    start_.assign(static_cast<std::size_t>(cells_ + 1), 0);
    for (Index i = 0; i < n; ++i) {
      cell[static_cast<std::size_t>(i)] = cell_of(P(i, 0), P(i, 1), P(i, 2));
      ++start_[static_cast<std::size_t>(cell[static_cast<std::size_t>(i)] + 1)];
    }
    for (Index c = 0; c < cells_; ++c) start_[static_cast<std::size_t>(c + 1)] += start_[static_cast<std::size_t>(c)];
    std::vector<Index> fill(start_.begin(), start_.end() - 1);
    xyz_.resize(static_cast<std::size_t>(3 * n));
    id_.resize(static_cast<std::size_t>(n));
    for (Index i = 0; i < n; ++i) {  // ascending i within a cell
      const Index at = fill[static_cast<std::size_t>(cell[static_cast<std::size_t>(i)])]++;
      for (int d = 0; d < 3; ++d) xyz_[static_cast<std::size_t>(3 * at + d)] = P(i, d);
      id_[static_cast<std::size_t>(at)] = static_cast<VIndex>(i);
    }
  }

  Index size() const { return n_; }
  Index dim() const { return dimension; }

  /// k nearest points of every row of Q (#Q×3, any scalar type) into `out` (#Q×k). ArgumentError
  /// when k < 1, k > #P or a query is not finite; ShapeError when Q is not #Q×3.
  template <exec::HostPolicy Policy, class DQ>
  void query_into(Policy policy, const Eigen::MatrixBase<DQ>& Q, Index k, KnnResult<S>& out) {
    constexpr const char* where = "neighbors::GridKnn::query";
    detail::check_cols(where, "queries", Q, 3);
    detail::check_k(where, k, n_, "indexed points");
    const Index nq = Q.rows();
    out.resize(nq, k);
    // the queries in cell order (counting sort): neighbouring queries share cells and cache lines
    qpts_.resize(static_cast<std::size_t>(3 * nq));
    qcell_.resize(static_cast<std::size_t>(nq));
    order_.resize(static_cast<std::size_t>(nq));
    qstart_.assign(static_cast<std::size_t>(cells_ + 1), 0);
    for (Index i = 0; i < nq; ++i) {
      S* q = qpts_.data() + 3 * i;
      for (int d = 0; d < 3; ++d) {
        q[d] = static_cast<S>(Q(i, d));
        if (!std::isfinite(q[d])) throw ArgumentError(std::string(where) + ": query row " + std::to_string(i) + " holds a non-finite coordinate");
      }
      qcell_[static_cast<std::size_t>(i)] = cell_of(q[0], q[1], q[2]);
      ++qstart_[static_cast<std::size_t>(qcell_[static_cast<std::size_t>(i)] + 1)];
    }
    for (Index c = 0; c < cells_; ++c) qstart_[static_cast<std::size_t>(c + 1)] += qstart_[static_cast<std::size_t>(c)];
    for (Index i = 0; i < nq; ++i) order_[static_cast<std::size_t>(qstart_[static_cast<std::size_t>(qcell_[static_cast<std::size_t>(i)])]++)] = i;
    exec::parallel_for(policy, nq, [&](Index t) {
      const Index i = order_[static_cast<std::size_t>(t)];
      VIndex* idx = out.indices.row(i).data();
      S* dist = out.distances.row(i).data();
      search(qpts_.data() + 3 * i, qcell_[static_cast<std::size_t>(i)], k, idx, dist);
      detail::finish_knn_row(idx, dist, k);
    });
  }

  template <exec::HostPolicy Policy, class DQ>
  KnnResult<S> query(Policy policy, const Eigen::MatrixBase<DQ>& Q, Index k) {
    KnnResult<S> r;
    query_into(policy, Q, k, r);
    return r;
  }

 private:
  /// Cell size h from the bounding box: about n / points_per_cell cells (a flat or thin set gets
  /// one cell across its thin axes), at most 2^20 per axis.
  void layout(const point_matrix& P, double per_cell) {
    double lo[3], ext[3], emax = 0, amax = 0;
    for (int d = 0; d < 3; ++d) {
      const double a = double(P.col(d).minCoeff()), b = double(P.col(d).maxCoeff());
      lo[d] = a, ext[d] = b - a;
      emax = std::max(emax, ext[d]);
      amax = std::max({amax, std::abs(a), std::abs(b)});
    }
    const double target = std::max(1.0, double(n_) / per_cell);
    double h = emax > 0 ? emax / std::cbrt(target) : 1.0;
    auto count = [&](double hh) {
      double c = 1;
      for (int d = 0; d < 3; ++d) c *= std::floor(ext[d] / hh) + 1;
      return c;
    };
    for (int it = 0; it < 8 && emax > 0; ++it) h *= std::cbrt(count(h) / target);  // flat sets: fewer cells than the cube root says
    h = std::max(h, emax / double(1 << 20));
    h_ = h, inv_h_ = 1 / h;
    cells_ = 1;
    for (int d = 0; d < 3; ++d) {
      origin_[d] = lo[d];
      dims_[d] = static_cast<Index>(std::floor(ext[d] * inv_h_)) + 1;
      cells_ *= dims_[d];
    }
    margin_ = 1e-9 * (emax + amax + h);
  }

  Index axis_cell(double x, int d) const {
    const double c = std::floor((x - origin_[d]) * inv_h_);
    return c < 0 ? 0 : c >= double(dims_[d]) ? dims_[d] - 1 : static_cast<Index>(c);
  }
  Index cell_of(double x, double y, double z) const { return axis_cell(x, 0) + dims_[0] * (axis_cell(y, 1) + dims_[1] * axis_cell(z, 2)); }

  /// Squared distance along axis d from coordinate x to the slab of cells i, less the margin (so
  /// the sum over the axes bounds the distance to any point of a cell from below).
  double gap2(double x, Index i, int d) const {
    const double lo = origin_[d] + double(i) * h_, hi = lo + h_;
    const double g = std::max({0.0, lo - x - margin_, x - hi - margin_});
    return g * g;
  }

  /// The k best candidates of one query, ascending: (d2, index) keys in a sorted array. A squared
  /// distance is never negative (nor NaN), so its bit pattern orders as an unsigned integer, and
  /// (d2, index) in lexicographic order is one integer comparison of the key bits(d2)·2³² +
  /// index, with no floating-point branch. Keeps exactly the k smallest keys offered, as KdTree's
  /// sorted insertion does (a max-heap with a final sort, or selecting from a larger buffer, was
  /// slower at k = 20).
  struct Candidates {
    using Bits = std::conditional_t<std::is_same_v<S, float>, std::uint32_t, std::uint64_t>;
    using Key = std::conditional_t<std::is_same_v<S, float>, std::uint64_t, unsigned __int128>;
    std::vector<Key> keys;
    std::size_t k = 0, m = 0;

    static Key key(S d2, VIndex id) { return (Key(std::bit_cast<Bits>(d2)) << 32) | Key(static_cast<std::uint32_t>(id)); }
    static S d2_of(Key key) { return std::bit_cast<S>(static_cast<Bits>(key >> 32)); }

    void reset(Index k_) {
      k = static_cast<std::size_t>(k_), m = 0;
      if (keys.size() < k) keys.resize(k);
    }
    bool full() const { return m == k; }
    S bound() const { return d2_of(keys[k - 1]); }  ///< the k-th squared distance (when full)
    void add(S d2, VIndex id) {
      const Key x = key(d2, id);
      if (m == k && !(x < keys[k - 1])) return;
      std::size_t j = m < k ? m++ : k - 1;
      for (; j > 0 && x < keys[j - 1]; --j) keys[j] = keys[j - 1];
      keys[j] = x;
    }
    void write(VIndex* idx, S* dist2) const {
      for (std::size_t j = 0; j < m; ++j) dist2[j] = d2_of(keys[j]), idx[j] = static_cast<VIndex>(static_cast<std::uint32_t>(keys[j]));
    }
  };

  /// The k nearest of q (its cell `qc`) into idx/dist2, ascending (d2, index).
  void search(const S* q, Index qc, Index k, VIndex* idx, S* dist2) const {
    thread_local Candidates cand;
    cand.reset(k);
    const Index c[3] = {qc % dims_[0], (qc / dims_[0]) % dims_[1], qc / (dims_[0] * dims_[1])};
    const Index rmax = std::max({c[0], dims_[0] - 1 - c[0], c[1], dims_[1] - 1 - c[1], c[2], dims_[2] - 1 - c[2]});
    for (Index r = 0; r <= rmax; ++r) {
      Index b0[3], b1[3];  // the ring's box, clipped to the grid
      for (int d = 0; d < 3; ++d) b0[d] = std::max<Index>(0, c[d] - r), b1[d] = std::min<Index>(dims_[d] - 1, c[d] + r);
      double gz2 = 0, gy2 = 0;
      auto visit = [&](Index x, Index y, Index z) {  // cells farther than the k-th are skipped whole
        if (cand.full() && gz2 + gy2 + gap2(double(q[0]), x, 0) > double(cand.bound())) return;
        scan(q, x + dims_[0] * (y + dims_[1] * z), cand);
      };
      for (Index z = b0[2]; z <= b1[2]; ++z) {
        gz2 = gap2(double(q[2]), z, 2);
        if (cand.full() && gz2 > double(cand.bound())) continue;
        for (Index y = b0[1]; y <= b1[1]; ++y) {
          gy2 = gap2(double(q[1]), y, 1);
          if (cand.full() && gz2 + gy2 > double(cand.bound())) continue;
          if (std::abs(z - c[2]) == r || std::abs(y - c[1]) == r) {  // a face row of the ring: every x
            for (Index x = b0[0]; x <= b1[0]; ++x) visit(x, y, z);
          } else {  // inside the ring's faces: its two x ends
            if (c[0] - r >= 0) visit(c[0] - r, y, z);
            if (c[0] + r < dims_[0]) visit(c[0] + r, y, z);
          }
        }
      }
      if (!cand.full()) continue;
      // the points outside the ring's box are at least this far (sides at the grid's edge: none)
      double out = std::numeric_limits<double>::infinity();
      for (int d = 0; d < 3; ++d) {
        const double x = double(q[d]);
        if (c[d] - r > 0) out = std::min(out, x - (origin_[d] + double(c[d] - r) * h_) - margin_);
        if (c[d] + r < dims_[d] - 1) out = std::min(out, origin_[d] + double(c[d] + r + 1) * h_ - x - margin_);
      }
      if (out > 0 && out * out > double(cand.bound())) break;
    }
    cand.write(idx, dist2);
  }

  /// Offers the points of cell `cell`: the squared distance as nanoflann's L2 metric forms it
  /// (Σ over the coordinates in order of diff², in S), so the distances are KdTree's bitwise.
  void scan(const S* q, Index cell, Candidates& cand) const {
    for (Index at = start_[static_cast<std::size_t>(cell)]; at < start_[static_cast<std::size_t>(cell + 1)]; ++at) {
      const S* p = xyz_.data() + 3 * at;
      S result = S();
      for (int d = 0; d < 3; ++d) {
        const S diff = q[d] - p[d];
        result += diff * diff;
      }
      cand.add(result, id_[static_cast<std::size_t>(at)]);
    }
  }

  Index n_ = 0, cells_ = 0;
  std::array<Index, 3> dims_{};
  std::array<double, 3> origin_{};
  double h_ = 1, inv_h_ = 1, margin_ = 0;
  std::vector<Index> start_;  ///< cell c's points: [start_[c], start_[c+1]) in xyz_/id_
  std::vector<S> xyz_;        ///< the points, cell by cell (ascending index within a cell)
  std::vector<VIndex> id_;
  std::vector<S> qpts_;       ///< query scratch: the queries in S, their cells, their cell order
  std::vector<Index> qcell_, order_, qstart_;
};

}  // namespace simsr::neighbors
