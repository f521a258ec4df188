#pragma once
/// \file
/// Exhaustive k-nearest neighbours for high-dimensional features (EdgeConv's dynamic graph in
/// DGCNN, §3.1): squared distances ‖a‖² + ‖b‖² − 2a·b on blocks of queries × blocks of points, a
/// bounded sorted buffer per query row, never an N×N matrix. Self queries (the dynamic graph's)
/// run a fused distance-and-select kernel over symmetric tile pairs (detail/distance_tile.hpp);
/// other queries run Eigen GEMM blocks.
///
///     simsr::neighbors::BruteForceKnn<float> knn(F);            // F: N×D row-major, borrowed
///     knn.query_self_into(simsr::exec::omp, 5, r);              // 5 nearest other points per row
///     knn.query_self_into(simsr::exec::omp, 5, r, false);       // self included (first, distance 0)
///     simsr::neighbors::BruteForceKnn<float, simsr::neighbors::SelfKernel::blocked_gemm> old(F);  // the earlier kernel

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "../core/parallel.hpp"
#include "../core/serial_gemm.hpp"
#include "detail/distance_tile.hpp"
#include "knn_result.hpp"

namespace simsr::neighbors {

/// How BruteForceKnn's self queries form and select the tile distances. Both give the same
/// result (the exact kNN, ties by index: see BruteForceKnn), computed with different roundings
/// of the candidate filter.
enum class SelfKernel {
  /// Distances formed and filtered in registers, never stored (detail::DistanceTile): the default.
  fused,
  /// Each tile product G_IJ written by a single-threaded Eigen GEMM, then read back row by row:
  /// the kernel before issue #17, kept as the benchmarks' baseline.
  blocked_gemm
};

/// Block sizes of BruteForceKnn (any scalar, any SelfKernel).
struct BruteForceKnnParams {
  Index query_block = 256;     ///< queries per GEMM block (rows of the block product; self queries: the tile size)
  Index point_block = 1024;    ///< points per GEMM block (columns)
  Index extra_candidates = 8;  ///< candidates kept beyond k for the exact re-ranking
  /// Self queries with several workers: between phases of tile offsets, each row's threshold
  /// becomes the smallest any worker holds (the same result; false: each worker filters with its
  /// own lists alone, the benchmark's baseline).
  bool share_thresholds = true;
};

/// Exact brute-force kNN over N points of dimension D (row-major N×D, float by default).
///
/// Exactness: the GEMM form loses relative accuracy to cancellation, so it only *selects*
/// k + `extra_candidates` candidates per query; their distances are then recomputed directly
/// (Σ(a−b)², accumulated in double) and the k best of them returned. The result is the exact kNN
/// unless more than `extra_candidates` points lie within the GEMM's rounding error of the k-th
/// distance. Reported distances are the direct ones (self = exactly 0).
///
/// Ties: equal distances come by ascending index. Under exec::seq and exec::omp the blocks are the
/// same (fixed sizes, not the thread count) and every block product runs single-threaded through
/// the same kernel, so the results are bitwise identical for any thread count.
///
/// Self queries (query_self_into) use the symmetry of the distance: the points are cut into tiles
/// of `query_block` rows (SelfKernel::fused rounds it up to a whole number of its register panels)
/// and only the tile pairs (I, J) with I ≤ J are computed (half the flops); each entry is offered
/// to both of its rows. A row keeps the `cap` smallest (approximate
/// squared distance, index) pairs in lexicographic order, a set that does not depend on the order
/// in which the pairs arrive: each worker keeps its own lists over the tiles it took, and the
/// lists are merged per row before the re-ranking, so the result is the same for any thread
/// count and any assignment of tiles to threads (they are handed out dynamically).
///
/// Lifetime and threads: the points are borrowed and must outlive the object. The object owns
/// its scratch buffers (sized on the first query, reused after), so a query allocates nothing once
/// `out` has its shape; the price is that one object must not run two queries at once (use one
/// object per thread, or exec::omp inside one query).
template <class S = float, SelfKernel Kernel = SelfKernel::fused>
class BruteForceKnn {
  static_assert(std::is_same_v<S, float> || std::is_same_v<S, double>, "simsr::neighbors::BruteForceKnn works on float or double features");

 public:
  using scalar_type = S;
  using point_matrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;  ///< N×D
  static constexpr SelfKernel self_kernel = Kernel;

  using Params = BruteForceKnnParams;  ///< one type for every kernel

  BruteForceKnn() = default;
  explicit BruteForceKnn(const point_matrix& P, Params params = {}) { build(P, params); }
  explicit BruteForceKnn(Eigen::Map<const point_matrix> P, Params params = {}) { build(P, params); }
  BruteForceKnn(point_matrix&&, Params = {}) = delete;  // would dangle

  /// Borrows P (N×D) and precomputes its squared norms. ArgumentError for non-finite values, a
  /// squared norm that overflows S (the distances would be NaN and select nothing) or
  /// non-positive block sizes.
  void build(const point_matrix& P, Params params = {}) { build_view(P.data(), P.rows(), P.cols(), params); }
  void build(Eigen::Map<const point_matrix> P, Params params = {}) { build_view(P.data(), P.rows(), P.cols(), params); }
  void build(point_matrix&&, Params = {}) = delete;

  Index size() const { return n_; }
  Index dim() const { return d_; }

  /// k nearest points of every row of Q (#Q×D, any scalar type) into `out` (#Q×k).
  /// ArgumentError when k < 1, k > N or a query is not finite; ShapeError when Q has ≠ D columns.
  template <exec::HostPolicy Policy, class DQ>
  void query_into(Policy policy, const Eigen::MatrixBase<DQ>& Q, Index k, KnnResult<S>& out) {
    constexpr const char* where = "neighbors::BruteForceKnn::query";
    detail::check_cols(where, "queries", Q, d_);
    detail::check_k(where, k, n_);
    run(policy, Q, k, false, out, where);
  }

  /// k nearest points of every point (queries = the points themselves) into `out` (N×k). With
  /// `exclude_self` a point is not its own neighbour (k ≤ N−1); otherwise it comes first at 0.
  template <exec::HostPolicy Policy>
  void query_self_into(Policy policy, Index k, KnnResult<S>& out, bool exclude_self = true) {
    constexpr const char* where = "neighbors::BruteForceKnn::query_self";
    detail::check_k(where, k, exclude_self ? n_ - 1 : n_, exclude_self ? "other points" : "points");
    run_self(policy, k, exclude_self, out);
  }

  template <exec::HostPolicy Policy, class DQ>
  KnnResult<S> query(Policy policy, const Eigen::MatrixBase<DQ>& Q, Index k) {
    KnnResult<S> r;
    query_into(policy, Q, k, r);
    return r;
  }

  template <exec::HostPolicy Policy>
  KnnResult<S> query_self(Policy policy, Index k, bool exclude_self = true) {
    KnnResult<S> r;
    query_self_into(policy, k, r, exclude_self);
    return r;
  }

 private:
  using PointMap = Eigen::Map<const point_matrix>;

  struct alignas(64) Workspace {  // one cache line apart: workers push to their own vectors
    point_matrix Qb;             // query block, converted to S
    point_matrix G;              // query block × point block products
    VecX<S> qn;                  // squared norms of the query block
    std::vector<S> cand_d2;      // per query row: `cap` approximate squared distances, ascending
    std::vector<VIndex> cand_i;  // matching indices
    std::vector<Index> count;
    std::vector<S> exact;        // re-ranking scratch: direct distances
    std::vector<VIndex> order;
    std::vector<S> d2;           // self queries: one tile row of approximate squared distances
    std::vector<S> self_d2;      // self queries: per point, this worker's `cap` best pairs (lexicographic)
    std::vector<VIndex> self_i;
    std::vector<Index> self_count;
    std::vector<S> self_worst;   // the cap-th approximate squared distance (+inf until the list is full)
    SerialGemm<S> gemm;

    void reserve(Index qb, Index pb, Index d, Index cap) {
      gemm.reserve(qb, pb, d);
      if (Qb.rows() != qb || Qb.cols() != d) Qb.resize(qb, d);
      if (G.rows() != qb || G.cols() != pb) G.resize(qb, pb);
      if (qn.size() != qb) qn.resize(qb);
      const auto c = static_cast<std::size_t>(qb * cap);
      if (cand_d2.size() < c) cand_d2.resize(c), cand_i.resize(c);
      if (count.size() < static_cast<std::size_t>(qb)) count.resize(static_cast<std::size_t>(qb));
      if (d2.size() < static_cast<std::size_t>(pb)) d2.resize(static_cast<std::size_t>(pb));
      reserve_rerank(cap);
    }
    /// The re-ranking's scratch for `cap` candidates.
    void reserve_rerank(Index cap) {
      if (exact.size() < static_cast<std::size_t>(cap)) exact.resize(static_cast<std::size_t>(cap)), order.resize(static_cast<std::size_t>(cap));
    }
    /// Empty candidate lists for n points.
    void reserve_lists(Index n, Index cap) {
      const auto c = static_cast<std::size_t>(n * cap);
      if (self_d2.size() < c) self_d2.resize(c), self_i.resize(c);
      if (self_count.size() < static_cast<std::size_t>(n)) self_count.resize(static_cast<std::size_t>(n)), self_worst.resize(static_cast<std::size_t>(n));
      std::fill(self_count.begin(), self_count.begin() + n, Index(0));
      std::fill(self_worst.begin(), self_worst.begin() + n, std::numeric_limits<S>::infinity());
    }
  };

  PointMap points() const { return PointMap(data_, n_, d_); }

  void build_view(const S* data, Index n, Index d, Params params) {
    constexpr const char* where = "neighbors::BruteForceKnn::build";
    if (params.query_block < 1 || params.point_block < 1 || params.extra_candidates < 0)
      throw ArgumentError(std::string(where) + ": query_block and point_block must be >= 1 and extra_candidates >= 0");
    if (n > Index(std::numeric_limits<VIndex>::max()))
      throw ArgumentError(std::string(where) + ": " + std::to_string(n) + " points exceed the 32-bit index range");
    if (d < 1) throw ShapeError(std::string(where) + ": points", {n, -1}, {n, d});
    detail::check_finite_rows(where, "points", PointMap(data, n, d));
    norms_ = PointMap(data, n, d).rowwise().squaredNorm();
    for (Index i = 0; i < n; ++i)
      if (!std::isfinite(norms_[i])) {
        data_ = nullptr, n_ = 0;
        throw ArgumentError(std::string(where) + ": points row " + std::to_string(i) + " has a squared norm that overflows " +
                            (std::is_same_v<S, float> ? "float" : "double") + " (scale the features down)");
      }
    data_ = data, n_ = n, d_ = d, params_ = params;
  }

  template <class Policy, class DQ>
  void run(Policy policy, const Eigen::MatrixBase<DQ>& Q, Index k, bool exclude_self, KnnResult<S>& out, const char* where) {
    const Index nq = Q.rows();
    out.resize(nq, k);
    if (nq == 0) return;
    const Index qb = std::min(params_.query_block, nq);
    const Index pb = std::min(params_.point_block, n_);
    const Index cap = std::min(k + params_.extra_candidates, exclude_self ? n_ - 1 : n_);
    const Index blocks = (nq + qb - 1) / qb;
    Index workers = 1;
    if constexpr (std::is_same_v<Policy, exec::omp_t>) workers = std::min<Index>(blocks, exec::omp_max_threads());
    if (static_cast<Index>(ws_.size()) < workers) ws_.resize(static_cast<std::size_t>(workers));
    for (Index w = 0; w < workers; ++w) ws_[static_cast<std::size_t>(w)].reserve(qb, pb, d_, cap);
    exec::parallel_for(policy, workers, [&](Index w) {
      Workspace& ws = ws_[static_cast<std::size_t>(w)];
      const auto [b0, b1] = exec::chunk_range(blocks, workers, w);
      for (Index b = b0; b < b1; ++b) block(Q, b * qb, std::min(qb, nq - b * qb), k, cap, exclude_self, ws, out, where);
    });
  }

  /// Self queries over tiles of T points: the tile pairs (I, I + d), d ≥ 0, nearest offsets
  /// first, handed out one at a time to the workers; each worker offers every entry of its tiles
  /// to both rows in its own candidate lists (no sharing, no barriers), and the lists of the
  /// workers are merged per row before the re-ranking. The cap smallest (d2, index) pairs of a row
  /// are the same set whichever worker saw which tile.
  template <class Policy>
  void run_self(Policy policy, Index k, bool exclude_self, KnnResult<S>& out) {
    const Index n = n_;
    out.resize(n, k);
    if (n == 0) return;
    constexpr bool fused = Kernel == SelfKernel::fused;
    constexpr Index NR = Tile::NR;
    // fused: tiles start on panel boundaries of the packed points
    const Index T = fused ? (std::min(params_.query_block, n) + NR - 1) / NR * NR : std::min(params_.query_block, n);
    const Index cap = std::min(k + params_.extra_candidates, exclude_self ? n - 1 : n);
    const Index nb = (n + T - 1) / T, pairs = nb * (nb + 1) / 2;
    const Index max_workers = std::is_same_v<Policy, exec::omp_t> ? Index(exec::omp_max_threads()) : Index(1);
    const Index workers = std::max<Index>(1, std::min(pairs, max_workers));
    if (static_cast<Index>(ws_.size()) < workers) ws_.resize(static_cast<std::size_t>(workers));
    if constexpr (fused) Tile::pack(data_, n, d_, norms_.data(), packed_, packed_norms_);
    for (Index w = 0; w < workers; ++w) {
      Workspace& ws = ws_[static_cast<std::size_t>(w)];
      if constexpr (fused)
        ws.reserve_rerank(cap);  // no tile is stored
      else
        ws.reserve(T, T, d_, cap);
      ws.reserve_lists(fused ? n + NR : n, cap);  // fused: the column thresholds are read a whole panel at a time
    }
    // The offsets in phases; after each phase but the last, every worker's row thresholds become
    // the smallest any worker holds. Each worker sees only its share of the tiles, so its own
    // thresholds tighten more slowly than one worker's would (with two workers, twice the offers
    // of one); a threshold from another worker is safe: that worker's list already holds cap
    // candidates at or below it, so anything strictly farther cannot be among the row's cap
    // nearest, and the merged lists are the same set as before.
    const Index phase_end[] = {1, 3, nb};
    Index d_begin = 0;
    for (Index d_end : phase_end) {
      d_end = std::min(d_end, nb);
      if (d_end <= d_begin) continue;
      Index phase_pairs = 0;
      for (Index d = d_begin; d < d_end; ++d) phase_pairs += nb - d;
      std::atomic<Index> next{0};
      exec::parallel_for(policy, workers, [&](Index w) {
        Workspace& ws = ws_[static_cast<std::size_t>(w)];
        // pair number p → offset d and first tile I: offsets d_begin, d_begin + 1, … each with nb − d pairs
        Index d = d_begin, first = 0;  // pairs of this phase before offset d
        for (Index p; (p = next.fetch_add(1, std::memory_order_relaxed)) < phase_pairs;) {
          while (p >= first + (nb - d)) first += nb - d, ++d;
          const Index I = p - first, J = I + d;
          if constexpr (fused)
            fused_tile(I * T, std::min(T, n - I * T), J * T, std::min(T, n - J * T), cap, exclude_self, ws);
          else
            tile(I * T, std::min(T, n - I * T), J * T, std::min(T, n - J * T), cap, exclude_self, ws);
        }
      });
      if (params_.share_thresholds && workers > 1 && d_end < nb) {
        const Index chunks = exec::chunk_count(n, workers);
        exec::for_chunks(policy, n, chunks, workers, [&](Index, Index, Index b, Index e) {
          for (Index q = b; q < e; ++q) {
            S m = ws_[0].self_worst[static_cast<std::size_t>(q)];
            for (Index o = 1; o < workers; ++o) m = std::min(m, ws_[static_cast<std::size_t>(o)].self_worst[static_cast<std::size_t>(q)]);
            for (Index o = 0; o < workers; ++o) ws_[static_cast<std::size_t>(o)].self_worst[static_cast<std::size_t>(q)] = m;
          }
        });
      }
      d_begin = d_end;
    }
    // merge the workers' lists into worker 0's, then re-rank (chunks of T rows)
    const Index wk = std::min(workers, nb);
    exec::parallel_for(policy, wk, [&](Index w) {
      Workspace& ws = ws_[static_cast<std::size_t>(w)];
      Workspace& w0 = ws_[0];
      for (Index c = w; c < nb; c += wk)
        for (Index q = c * T; q < std::min(n, (c + 1) * T); ++q) {
          for (Index o = 1; o < workers; ++o) {
            const Workspace& wo = ws_[static_cast<std::size_t>(o)];
            const Index cnt = wo.self_count[static_cast<std::size_t>(q)];
            for (Index t = 0; t < cnt; ++t) offer(w0, q, wo.self_d2[static_cast<std::size_t>(q * cap + t)], wo.self_i[static_cast<std::size_t>(q * cap + t)], cap);
          }
          rerank(points().row(q), w0.self_i.data() + q * cap, cap, k, ws, out, q);
        }
    });
  }

  /// Offers (d2, idx) to row `row`'s candidate list in `ws` (the cap smallest pairs, lexicographic).
  static void offer(Workspace& ws, Index row, S d2, VIndex idx, Index cap) {
    S* cd = ws.self_d2.data() + row * cap;
    VIndex* ci = ws.self_i.data() + row * cap;
    Index& cnt = ws.self_count[static_cast<std::size_t>(row)];
    Index t;
    if (cnt == cap) {
      if (!detail::closer(d2, idx, cd[cap - 1], ci[cap - 1])) return;
      t = cap - 1;
    } else {
      t = cnt++;
    }
    for (; t > 0 && detail::closer(d2, idx, cd[t - 1], ci[t - 1]); --t) cd[t] = cd[t - 1], ci[t] = ci[t - 1];
    cd[t] = d2;
    ci[t] = idx;
    if (cnt == cap) {  // never above a threshold shared by another worker (run_self's phases)
      S& worst = ws.self_worst[static_cast<std::size_t>(row)];
      worst = std::min(worst, cd[cap - 1]);
    }
  }

  /// The tile of rows [q0, q0 + m) × columns [p0, p0 + pn) (q0 ≤ p0): every entry is offered to
  /// its row and, off the diagonal, to its column's row. A vectorized filter against the rows'
  /// current worst candidates skips the rows of the tile that offer nothing.
  void tile(Index q0, Index m, Index p0, Index pn, Index cap, bool exclude_self, Workspace& ws) const {
    ws.gemm.run(m, pn, d_, data_ + q0 * d_, d_, false, data_ + p0 * d_, d_, true, ws.G.data(), ws.G.cols(), false);
    const bool diagonal = q0 == p0;
    const S* pnorm = norms_.data() + p0;
    const S* wcol = ws.self_worst.data() + p0;
    S* d2 = ws.d2.data();
    for (Index r = 0; r < m; ++r) {
      const Index q = q0 + r;
      const S qn = norms_[q];
      const S* g = ws.G.row(r).data();
      const S wq = ws.self_worst[static_cast<std::size_t>(q)];
      unsigned hit = 0;
      if (diagonal) {
        for (Index j = 0; j < pn; ++j) {
          const S v = qn + pnorm[j] - S(2) * g[j];
          d2[j] = v;
          hit |= unsigned(v <= wq);
        }
      } else {
        for (Index j = 0; j < pn; ++j) {
          const S v = qn + pnorm[j] - S(2) * g[j];
          d2[j] = v;
          hit |= unsigned(v <= wq) | unsigned(v <= wcol[j]);
        }
      }
      if (!hit) continue;
      for (Index j = 0; j < pn; ++j) {
        const Index p = p0 + j;
        if (diagonal && p == q && exclude_self) continue;
        if (d2[j] <= ws.self_worst[static_cast<std::size_t>(q)]) offer(ws, q, d2[j], static_cast<VIndex>(p), cap);
        if (!diagonal && d2[j] <= wcol[j]) offer(ws, p, d2[j], static_cast<VIndex>(q), cap);
      }
    }
  }

  /// SelfKernel::fused's tile of rows [q0, q0 + m) × columns [p0, p0 + pn) (q0 ≤ p0, p0 on a panel
  /// boundary): micro-tiles of MR rows × one panel, each entry offered as in tile(), the same
  /// entries offered whenever the approximate distances agree (the thresholds are the same
  /// lists' worst; the filter only skips what offer would reject).
  void fused_tile(Index q0, Index m, Index p0, Index pn, Index cap, bool exclude_self, Workspace& ws) const {
    const bool diagonal = q0 == p0;
    S* worst = ws.self_worst.data();
    for (Index r0 = 0; r0 < m; r0 += Tile::MR) {
      const int mr = static_cast<int>(std::min<Index>(Tile::MR, m - r0));
      const Index q = q0 + r0;  // its panel: rows past n are the panel's zero padding
      const S* rows = packed_.data() + (q / Tile::NR) * Tile::NR * d_ + q % Tile::NR;
      for (Index c0 = 0; c0 < pn; c0 += Tile::NR) {
        const Index cols = std::min<Index>(Tile::NR, pn - c0);
        Tile::run(rows, packed_.data() + (p0 + c0) * d_, d_, norms_.data() + q0 + r0, packed_norms_.data() + p0 + c0, worst + q0 + r0,
                  worst + p0 + c0, mr, !diagonal, [&](int r, int l, S d2) {
                    if (l >= cols) return;
                    const Index q = q0 + r0 + r, p = p0 + c0 + l;
                    if (diagonal && p == q && exclude_self) return;
                    if (d2 <= worst[q]) offer(ws, q, d2, static_cast<VIndex>(p), cap);
                    if (!diagonal && d2 <= worst[p]) offer(ws, p, d2, static_cast<VIndex>(q), cap);
                  });
      }
    }
  }

  /// One block of m queries starting at q0: candidates from all point blocks, then re-ranking.
  template <class DQ>
  void block(const Eigen::MatrixBase<DQ>& Q, Index q0, Index m, Index k, Index cap, bool exclude_self, Workspace& ws,
             KnnResult<S>& out, const char* where) const {
    auto Qb = ws.Qb.topRows(m);
    Qb = Q.middleRows(q0, m).template cast<S>();
    for (Index r = 0; r < m; ++r)
      if (!Qb.row(r).allFinite()) throw ArgumentError(std::string(where) + ": query row " + std::to_string(q0 + r) + " holds a non-finite value");
    ws.qn.head(m) = Qb.rowwise().squaredNorm();
    std::fill(ws.count.begin(), ws.count.begin() + m, Index(0));
    const PointMap P = points();
    const S inf = std::numeric_limits<S>::infinity();
    for (Index p0 = 0; p0 < n_; p0 += params_.point_block) {
      const Index pn = std::min(params_.point_block, n_ - p0);
      ws.gemm.run(m, pn, d_, ws.Qb.data(), d_, false, P.data() + p0 * d_, d_, true, ws.G.data(), ws.G.cols(), false);
      for (Index r = 0; r < m; ++r) {
        S* cd = ws.cand_d2.data() + r * cap;
        VIndex* ci = ws.cand_i.data() + r * cap;
        Index& cnt = ws.count[static_cast<std::size_t>(r)];
        const S qn = ws.qn[r];
        const S* g = ws.G.row(r).data();
        const S* pnorm = norms_.data() + p0;
        const Index self = exclude_self ? q0 + r - p0 : -1;  // column of the query itself, if any
        S worst = cnt == cap ? cd[cap - 1] : inf;
        for (Index j = 0; j < pn; ++j) {
          const S d2 = qn + pnorm[j] - S(2) * g[j];
          if (!(d2 < worst) || j == self) continue;  // later indices never win ties
          Index t = cnt < cap ? cnt++ : cap - 1;
          for (; t > 0 && cd[t - 1] > d2; --t) cd[t] = cd[t - 1], ci[t] = ci[t - 1];
          cd[t] = d2;
          ci[t] = static_cast<VIndex>(p0 + j);
          if (cnt == cap) worst = cd[cap - 1];
        }
      }
    }
    for (Index r = 0; r < m; ++r) rerank(Qb.row(r), ws.cand_i.data() + r * cap, cap, k, ws, out, q0 + r);
  }

  /// Direct distances of the cap candidates, rounded to S as reported; the k best by (distance,
  /// index) go to row `row`.
  template <class Row>
  void rerank(const Row& q, const VIndex* ci, Index cap, Index k, Workspace& ws, KnnResult<S>& out, Index row) const {
    // W candidates at a time: each sum keeps its order (the same distances as one at a time), the
    // W independent additions overlap instead of waiting on one chain's latency.
    constexpr Index W = 4;
    for (Index c0 = 0; c0 < cap; c0 += W) {
      const Index w = std::min(W, cap - c0);
      const S* p[W];
      double acc[W] = {};
      for (Index t = 0; t < W; ++t) p[t] = data_ + static_cast<Index>(ci[c0 + std::min(t, w - 1)]) * d_;
      for (Index j = 0; j < d_; ++j) {
        const double qj = static_cast<double>(q[j]);
        for (Index t = 0; t < W; ++t) {
          const double diff = qj - static_cast<double>(p[t][j]);
          acc[t] += diff * diff;
        }
      }
      for (Index t = 0; t < w; ++t) {
        ws.exact[static_cast<std::size_t>(c0 + t)] = static_cast<S>(std::sqrt(acc[t]));
        ws.order[static_cast<std::size_t>(c0 + t)] = static_cast<VIndex>(c0 + t);
      }
    }
    auto first = ws.order.begin(), last = ws.order.begin() + cap;
    std::partial_sort(first, first + k, last, [&](VIndex a, VIndex b) {
      return detail::closer(ws.exact[static_cast<std::size_t>(a)], ci[a], ws.exact[static_cast<std::size_t>(b)], ci[b]);
    });
    for (Index j = 0; j < k; ++j) {
      const VIndex c = ws.order[static_cast<std::size_t>(j)];
      out.indices(row, j) = ci[c];
      out.distances(row, j) = ws.exact[static_cast<std::size_t>(c)];
    }
  }

  using Tile = detail::DistanceTile<S>;

  const S* data_ = nullptr;
  Index n_ = 0, d_ = 0;
  Params params_{};
  VecX<S> norms_;
  std::vector<S> packed_, packed_norms_;  ///< SelfKernel::fused: the points in register panels (Tile::pack)
  std::vector<Workspace> ws_;
};

}  // namespace simsr::neighbors
