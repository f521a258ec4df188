#pragma once
/// \file
/// EdgeConv's graph features (DGCNN; paper §3.1, SPEC §7): for every point n and each of its k
/// neighbours j, the edge row cat(h_j − h_n, h_n); and the dynamic feature-space kNN graph of the
/// second embedding block (k nearest other points per batch item, not differentiated).
///
///     nn::GraphFeatures<float> gf;
///     gf.set_graph(lr_graph, N);                         // N×k, shared by every batch item
///     gf.forward(exec::omp, nn::Mode::train, h, e);      // h: (B·N)×C → e: (B·N·k)×2C, row (b·N+n)·k+j
///
///     nn::DynamicKnnGraph<float> dyn;                    // or DynamicKnnGraph<float, MySearch>
///     dyn.build(exec::omp, h, N, k, graph);              // graph: (B·N)×k, indices local to each item
///     gf.set_graph(graph, N);

#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "../neighbors/brute_force_knn.hpp"
#include "../neighbors/concepts.hpp"
#include "layer.hpp"

namespace simsr::nn {

/// Neighbour indices, row-major, one row per point, k columns; values are point indices local to
/// the point's batch item (0 ≤ idx < N).
using GraphIndices = Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

namespace detail {

/// Reverse adjacency of a graph of R rows × k edges over targets [0, R) in CSR form: the edges
/// e = row·k + j pointing to target t are edges[start[t] .. start[t+1]), in ascending e (counting
/// sort, stable). Rebuilt without allocation once the sizes are warm.
struct ReverseAdjacency {
  std::vector<Index> start;
  std::vector<Index> edges;

  /// target(e) gives the target row of edge e (0 ≤ target < R).
  template <class Target>
  void build(Index R, Index E, Target&& target) {
    start.assign(std::size_t(R + 1), 0);
    edges.resize(std::size_t(E));
    for (Index e = 0; e < E; ++e) ++start[std::size_t(target(e) + 1)];
    for (Index t = 0; t < R; ++t) start[std::size_t(t + 1)] += start[std::size_t(t)];
    // fill with a moving cursor kept in `start` shifted by one, then restore.
    for (Index e = 0; e < E; ++e) edges[std::size_t(start[std::size_t(target(e))]++)] = e;
    for (Index t = R; t > 0; --t) start[std::size_t(t)] = start[std::size_t(t - 1)];
    start[0] = 0;
  }
};

}  // namespace detail

/// Edge features of a k-neighbour graph: (P·R_g)×C point features → (P·R_g·k)×2C edge rows,
/// row (p·R_g + r)·k + j = cat(h[base + idx(r, j)] − h[p·R_g + r], h[p·R_g + r]) where
/// base = p·R_g + (r / N)·N is the first row of the point's batch item.
/// The graph has R_g rows: N (one graph shared by all batch items, e.g. the LR geodesic graph;
/// the input may hold any number of items) or B·N (one graph per item, e.g. the dynamic kNN).
/// Backward gathers per target point over a precomputed reverse adjacency (no atomics, fixed
/// summation order: exec::seq and exec::omp agree bitwise).
template <class S = float>
class GraphFeatures {
 public:
  using scalar_type = S;

  GraphFeatures() = default;
  GraphFeatures(const GraphIndices& graph, Index points_per_item) { set_graph(graph, points_per_item); }

  /// Copies `graph` (R_g×k, R_g a multiple of N, entries in [0, N)) and builds its reverse
  /// adjacency. ArgumentError for an empty graph, N < 1, R_g not a multiple of N or an index out
  /// of range. Allocates nothing once the shapes are warm.
  void set_graph(const GraphIndices& graph, Index points_per_item) {
    const Index R = graph.rows(), k = graph.cols(), N = points_per_item;
    if (N < 1 || R < 1 || k < 1 || R % N)
      throw ArgumentError("nn::GraphFeatures: the graph must be R×k with k >= 1 and R a positive multiple of N = " + std::to_string(N) +
                          ", got " + std::to_string(R) + "×" + std::to_string(k));
    for (Index i = 0; i < graph.size(); ++i)
      if (graph.data()[i] < 0 || graph.data()[i] >= N)
        throw ArgumentError("nn::GraphFeatures: neighbour index " + std::to_string(graph.data()[i]) + " (row " + std::to_string(i / k) +
                            ") is outside [0, " + std::to_string(N) + ")");
    if (graph_.rows() != R || graph_.cols() != k) graph_.resize(R, k);
    graph_ = graph;
    n_ = N;
    rev_.build(R, R * k, [&](Index e) { return target(e); });
  }

  const GraphIndices& graph() const { return graph_; }
  Index k() const { return graph_.cols(); }
  Index points_per_item() const { return n_; }
  Index out_features(Index in_cols) const { return 2 * in_cols; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode, const ConstView<S>& in, Matrix<S>& out) {
    const Index reps = check_input(in), R = graph_.rows(), k = graph_.cols(), C = in.cols();
    ensure_shape(out, in.rows() * k, 2 * C);
    const Index rows = reps * R;
    const Index nc = exec::chunk_count(rows, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, rows, nc, workers, [&](Index, Index, Index b, Index e) {
      gather(in, b * k, e * k, out.data() + b * k * out.cols(), out.cols());
    });
  }

  /// Edge rows [e0, e1) of forward's output (row (p·R_g + r)·k + j) written to a row-major block
  /// at `dst` with leading dimension `ld` (≥ 2C): EdgeConv's fused eval path gathers its chunks
  /// with it.
  void gather(const ConstView<S>& in, Index e0, Index e1, S* dst, Index ld) const {
    const Index C = in.cols();
    for (Index er = e0; er < e1; ++er) {
      const auto [row, nbr] = edge_rows(er);
      Eigen::Map<Eigen::Matrix<S, 1, Eigen::Dynamic>> o(dst + (er - e0) * ld, 2 * C);
      o.head(C) = in.row(nbr) - in.row(row);
      o.tail(C) = in.row(row);
    }
  }

  /// The input rows that edge row er of forward's output joins: {its point, the neighbour}.
  std::pair<Index, Index> edge_rows(Index er) const {
    const Index R = graph_.rows(), k = graph_.cols();
    const Index row = er / k, j = er % k, p = row / R, r = row % R, base = p * R + (r / n_) * n_;
    return {row, base + graph_(r, j)};
  }

  /// d_in[t] = Σ_{edges (n, j) → t} d_nbr − Σ_j d_nbr(t, j) + Σ_j d_ctr(t, j), where d_nbr and
  /// d_ctr are the first and second C columns of d_out.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in) {
    const Index reps = check_input(in), R = graph_.rows(), k = graph_.cols(), C = in.cols();
    detail::check_shape("nn::GraphFeatures", "output gradient", d_out, in.rows() * k, 2 * C);
    if (!d_in) return;
    ensure_shape(*d_in, in.rows(), C);
    const Index rows = reps * R;
    const Index nc = exec::chunk_count(rows, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, rows, nc, workers, [&](Index, Index, Index b, Index e) {
      for (Index row = b; row < e; ++row) {
        const Index p = row / R, t = row % R;
        auto g = d_in->row(row);
        g.setZero();
        for (Index j = 0; j < k; ++j) g += d_out.row(row * k + j).tail(C) - d_out.row(row * k + j).head(C);
        for (Index s = rev_.start[std::size_t(t)]; s < rev_.start[std::size_t(t + 1)]; ++s)
          g += d_out.row(p * R * k + rev_.edges[std::size_t(s)]).head(C);
      }
    });
  }

 private:
  Index target(Index e) const {
    const Index k = graph_.cols(), r = e / k;
    return (r / n_) * n_ + graph_(r, e % k);
  }
  Index check_input(const ConstView<S>& in) const {
    if (graph_.size() == 0) throw ArgumentError("nn::GraphFeatures: no graph set (call set_graph first)");
    if (in.rows() % graph_.rows())
      throw ShapeError("nn::GraphFeatures: input rows (a multiple of the graph's " + std::to_string(graph_.rows()) + ")", {-1, in.cols()},
                       {in.rows(), in.cols()});
    return in.rows() / graph_.rows();
  }

  GraphIndices graph_;
  Index n_ = 0;
  detail::ReverseAdjacency rev_;
};
static_assert(assert_layer<GraphFeatures<float>>());

/// Dynamic kNN graph in feature space (DGCNN; SPEC §7 graph 2): for every batch item of N
/// points, the k nearest *other* points by Euclidean distance of their feature rows (self
/// excluded by index, the rest ascending by distance, ties as the search orders them). Not
/// differentiated (the graph is a constant of the backward pass).
///
/// `Search` is any neighbors::NeighborSearch (one type to swap; checked with a sentence): the
/// default, the exact neighbors::BruteForceKnn (any feature width, ties by ascending index), is
/// built on each item's rows in place and asked for the k nearest other points directly
/// (query_self_into); any other search is built on a copy of the item's rows (its point_matrix)
/// and asked for k + 1 neighbours, of which the point itself (or, should exact duplicates crowd it
/// out, the last) is dropped.
///
/// Difference from the official `topk(k+1)` on −squared distance with the first column dropped:
/// the reference drops whatever comes first, which is the point itself unless another point has
/// the same features (distance 0) and wins the tie — then the reference keeps the point itself as a
/// neighbour and drops the duplicate; here the point is never its own neighbour and duplicates
/// are ordinary neighbours. The two agree whenever the features of an item are distinct (and up
/// to the order of exact ties, which topk leaves unspecified).
template <class S = float, class Search = neighbors::BruteForceKnn<S>>
class DynamicKnnGraph {
  static_assert(neighbors::assert_neighbor_search<Search>());

 public:
  using search_type = Search;

  /// graph ((B·N)×k) ← the k nearest other points of every row of h ((B·N)×C) within its item.
  /// ArgumentError when rows are not a multiple of N, k ≥ N, or features are not finite (or do
  /// not fit the search's point_matrix). Allocates nothing once warm (for the default search and
  /// a contiguous h; a column block of a wider matrix is copied).
  template <exec::HostPolicy Policy>
  void build(Policy policy, const ConstView<S>& h, Index points_per_item, Index k, GraphIndices& graph) {
    const Index N = points_per_item, C = h.cols();
    if (N < 1 || h.rows() % N) throw ShapeError("nn::DynamicKnnGraph: features (B·N rows, N = " + std::to_string(N) + ")", {-1, C}, {h.rows(), C});
    if (k < 1 || k >= N) throw ArgumentError("nn::DynamicKnnGraph: k = " + std::to_string(k) + " must be in [1, N-1] with N = " + std::to_string(N));
    const Index B = h.rows() / N;
    if (graph.rows() != B * N || graph.cols() != k) graph.resize(B * N, k);
    if constexpr (searches_rows_in_place) {
      const bool contiguous = h.outerStride() == C;
      if (!contiguous) ensure_shape(copy_, N, C);
      for (Index b = 0; b < B; ++b) {
        const S* data = h.data() + b * N * h.outerStride();
        if (!contiguous) {
          copy_ = h.middleRows(b * N, N);
          data = copy_.data();
        }
        search_.build(Eigen::Map<const PointMatrix>(data, N, C));
        search_.query_self_into(policy, k, result_, true);
        graph.middleRows(b * N, N) = result_.indices;
      }
    } else {
      constexpr int fixed_cols = PointMatrix::ColsAtCompileTime;
      if (fixed_cols != Eigen::Dynamic && fixed_cols != C)
        throw ArgumentError("nn::DynamicKnnGraph: the search's points have " + std::to_string(fixed_cols) + " coordinates, the features " +
                            std::to_string(C) + " columns");
      for (Index b = 0; b < B; ++b) {
        points_ = h.middleRows(b * N, N).template cast<typename PointMatrix::Scalar>();
        search_.build(points_);
        search_.query_into(policy, points_, k + 1, result_);
        for (Index n = 0; n < N; ++n) {
          Index j = 0;
          for (Index c = 0; c <= k && j < k; ++c)  // the point itself skipped, else the (k+1)-th
            if (const Index idx = result_.indices(n, c); idx != n) graph(b * N + n, j++) = VIndex(idx);
        }
      }
    }
  }

 private:
  using PointMatrix = typename Search::point_matrix;
  /// The default search's fast path: built on a Map of the item's rows, self queries excluding the point.
  static constexpr bool searches_rows_in_place =
      std::is_same_v<typename PointMatrix::Scalar, S> && requires(Search& s, Eigen::Map<const PointMatrix> m, Index k,
                                                                  neighbors::KnnResult<typename Search::scalar_type>& r) {
        s.build(m);
        s.query_self_into(exec::seq, k, r, true);
      };

  Search search_;
  neighbors::KnnResult<typename Search::scalar_type> result_;
  Matrix<S> copy_;
  PointMatrix points_;  ///< other searches: the item's rows as the search's points (it borrows them)
};

}  // namespace simsr::nn
