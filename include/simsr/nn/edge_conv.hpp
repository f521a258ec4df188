#pragma once
/// \file
/// EdgeConv (DGCNN; paper §3.1, SPEC §7), the official `edge_conv` of each feature-embedding
/// block: graph features cat(h_j − h_i, h_i) → 1×1 Conv2d 2C→2out (no bias) → BatchNorm2d →
/// LeakyReLU(0.2) → 1×1 Conv2d 2out→out (no bias) → max over the k neighbours.
///
///     nn::EdgeConv<float> ec(store, "net_feat_emb.blocks.0", 35, 64, 5, rng);
///     ec.set_graph(lr_graph, N);                     // fixed graph (block 0), or:
///     ec.use_dynamic_graph(N);                       // kNN in feature space per forward (block 1)
///     ec.forward(exec::omp, nn::Mode::train, h, e);  // h: (B·N)×35 → e: (B·N)×64
///
/// State-dict names (official_model.py): `<prefix>.edge_conv.0.weight` (2out×2C×1×1),
/// `<prefix>.edge_conv.1.{weight,bias,running_mean,running_var,num_batches_tracked}`,
/// `<prefix>.edge_conv.3.weight` (out×2out×1×1).
/// The `paper` profile's edge function (SPEC §7: "EdgeConv as one linear layer, no BatchNorm")
/// is `EdgeMlp::single_linear`: Conv2d 2C→out with bias, LeakyReLU, `<prefix>.edge_conv.0.*`.

#include <string>

#include "graph_features.hpp"
#include "mlp.hpp"
#include "pooling.hpp"

namespace simsr::nn {

/// One EdgeConv: (B·N)×in → (B·N)×out. A fixed graph (set_graph) serves every batch item; a
/// dynamic graph (use_dynamic_graph) is rebuilt from the input features at every forward (k
/// nearest other points per item, found by `Search`, any neighbors::NeighborSearch; see
/// DynamicKnnGraph) and is not differentiated. Backward must follow the forward of the same input
/// (it reuses the graph and the intermediate activations).
template <class S = float, class Search = neighbors::BruteForceKnn<S>>
class EdgeConv {
 public:
  using scalar_type = S;

  /// The edge function h(e): official (two 1×1 convs with BatchNorm) or the paper's single layer.
  enum class EdgeMlp { official, single_linear };

  struct Options {
    S slope = S(0.2);                       ///< LeakyReLU negative slope
    typename BatchNorm1d<S>::Options bn{};  ///< eps, momentum of the BatchNorm2d
    EdgeMlp edge_mlp = EdgeMlp::official;
  };

  EdgeConv(ParameterStore<S>& store, const std::string& prefix, Index in, Index out, Index k, Rng& rng, Options options = {})
      : in_(in), out_(out), k_(k), kind_(options.edge_mlp),
        mlp_(store, prefix + ".edge_conv", stages(in, out, options), rng),
        pool_(PoolKind::max, k, false) {
    if (k < 1) throw ArgumentError("nn::EdgeConv '" + prefix + "': k must be >= 1");
  }

  /// The stages of the edge function for `options.edge_mlp`.
  static std::vector<MlpStage> stages(Index in, Index out, const Options& o) {
    const typename BatchNorm1d<float>::Options bn{.eps = o.bn.eps, .momentum = o.bn.momentum, .affine = o.bn.affine,
                                                  .track_running_stats = o.bn.track_running_stats};
    if (o.edge_mlp == EdgeMlp::single_linear) return {MlpStage::linear(2 * in, out, "0").dims(2).then(Act::leaky_relu, double(o.slope))};
    return {MlpStage::linear(2 * in, 2 * out, "0").no_bias().dims(2).norm("1", bn).then(Act::leaky_relu, double(o.slope)),
            MlpStage::linear(2 * out, out, "3").no_bias().dims(2)};
  }

  Index in_features() const { return in_; }
  Index out_features(Index = -1) const { return out_; }
  Index k() const { return k_; }
  bool dynamic() const { return dynamic_; }

  /// Fixed graph: N×k (shared by all items) or (B·N)×k (per item), indices local to each item.
  void set_graph(const GraphIndices& graph, Index points_per_item) {
    if (graph.cols() != k_) throw ArgumentError("nn::EdgeConv: the graph has " + std::to_string(graph.cols()) + " columns, k = " + std::to_string(k_));
    features_.set_graph(graph, points_per_item);
    dynamic_ = false;
  }
  /// Dynamic kNN graph in feature space over items of N points, rebuilt at every forward.
  void use_dynamic_graph(Index points_per_item) {
    if (points_per_item <= k_) throw ArgumentError("nn::EdgeConv: a dynamic graph needs more than k points per item");
    n_ = points_per_item;
    dynamic_ = true;
  }
  /// The graph of the last forward (or the fixed one).
  const GraphIndices& graph() const { return features_.graph(); }

  EdgeMlp edge_mlp() const { return kind_; }
  /// The official edge MLP's layers (conv3 and batch_norm: ArgumentError for single_linear).
  Linear<S>& conv0() { return mlp_.linear(0); }
  BatchNorm1d<S>& batch_norm() { return mlp_.batch_norm(0); }
  Linear<S>& conv3() {
    if (kind_ != EdgeMlp::official) throw ArgumentError("nn::EdgeConv: the single-linear edge function has no conv3");
    return mlp_.linear(1);
  }
  Mlp<S>& edge_function() { return mlp_; }
  /// The batch split of data-parallel training (the edge rows are batch rows: k per point).
  void set_batch_split(BatchSplit* split) { mlp_.set_batch_split(split); }
  /// The max over each point's k edges; its argmax() says which edge each channel took.
  GroupPool<S>& max_pool() { return pool_; }
  /// The edge function's output of the last forward, (B·N·k)×out: what max_pool() pooled.
  const Matrix<S>& edge_values() const { return e4_; }

  /// Eval forward with the first Linear per point (the default) or per edge (false: the values of
  /// the stored path bit for bit, k times the first layer's products; the benchmarks' baseline).
  void set_point_wise_first_layer(bool on) { point_wise_ = on; }
  bool point_wise_first_layer() const { return point_wise_; }

  /// In eval mode (BatchNorm on running statistics) no edge row is stored. The first Linear is
  /// applied per point, not per edge: on cat(h_j − h_i, h_i) its weight [W_d | W_s] gives
  /// W_d·h_j + (W_s − W_d)·h_i, so the products P = h·[W_d; W_s − W_d]ᵀ (two numbers per point and
  /// channel) serve every edge, k times fewer multiply-adds than per edge; each chunk of edge rows
  /// then sums its two rows of P into per-worker scratch and runs the rest of the edge MLP there
  /// (Mlp::eval_block_after_first_linear). The values are those of the stored path up to rounding
  /// (the same sums in another order); seq == omp bitwise. A backward after it recomputes the
  /// stored path.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& in, Matrix<S>& out) {
    detail::check_shape("nn::EdgeConv", "input", in, -1, in_);
    if (dynamic_) {
      knn_.build(policy, in, n_, k_, dyn_graph_);
      features_.set_graph(dyn_graph_, n_);
    }
    lean_ = mode == Mode::eval && mlp_.eval_fusable();
    if (lean_ && point_wise_) {
      forward_point_wise(policy, in);
    } else if (lean_) {
      forward_fused(policy, in);
    } else {
      features_.forward(policy, mode, in, e0_);
      mlp_.forward(policy, mode, e0_, e4_);
    }
    pool_.forward(policy, mode, e4_, out);
  }

  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in) {
    if (lean_) {  // the fused eval forward stored no edge features: make them (the MLP recomputes its own)
      detail::check_shape("nn::EdgeConv", "input", in, e4_.rows() / k_, in_);
      features_.forward(policy, Mode::eval, in, e0_);
      lean_ = false;
    }
    detail::check_shape("nn::EdgeConv", "input", in, e0_.rows() / k_, in_);
    pool_.backward(policy, e4_, out, d_out, &g4_);
    mlp_.backward(policy, e0_, e4_, g4_, d_in ? &g0_ : nullptr);
    if (d_in) features_.backward(policy, in, e0_, g0_, d_in);
  }

 private:
  void check_fused_input(const ConstView<S>& in) const {
    if (features_.graph().size() == 0) throw ArgumentError("nn::GraphFeatures: no graph set (call set_graph first)");
    if (in.rows() % features_.graph().rows())
      throw ShapeError("nn::GraphFeatures: input rows (a multiple of the graph's " + std::to_string(features_.graph().rows()) + ")",
                       {-1, in.cols()}, {in.rows(), in.cols()});
  }

  /// The eval path with the first Linear per edge: each chunk of edge rows gathered into
  /// per-worker scratch and run through the whole edge MLP there (Mlp::eval_block).
  template <class Policy>
  void forward_fused(Policy policy, const ConstView<S>& in) {
    check_fused_input(in);
    const Index C2 = 2 * in_;
    for_edge_chunks(policy, in.rows() * k_, C2, [&](Index w, Index b, Index e, S* g) {
      features_.gather(in, b, e, g, C2);
      mlp_.eval_block(w, e - b, g, C2, e4_.data() + b * e4_.cols(), e4_.cols());
    });
  }

  /// The eval paths' loop over chunks of the R edge rows: e4_ and the edge MLP's scratch sized,
  /// body(worker, begin, end, scratch) with a per-worker scratch block of `width` columns.
  template <class Policy, class Body>
  void for_edge_chunks(Policy policy, Index R, Index width, Body&& body) {
    ensure_shape(e4_, R, mlp_.out_features());
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    mlp_.prepare_eval_blocks(R, workers);
    if (gathered_.size() < std::size_t(workers)) gathered_.resize(std::size_t(workers));
    for (auto& g : gathered_) ensure_shape(g, exec::max_chunk_size(R, nc), width);
    detail::for_chunks_dynamic(policy, R, nc, workers, [&](Index w, Index, Index b, Index e) { body(w, b, e, gathered_[std::size_t(w)].data()); });
  }

  template <class Policy>
  void forward_point_wise(Policy policy, const ConstView<S>& in) {
    check_fused_input(in);
    // the point-wise first layer: point_w_ = [W_d; W_s − W_d] (2H × C), P = in·point_wᵀ (+ bias on the point's half)
    Linear<S>& first = mlp_.linear(0);
    const Index C = in_, H = first.out_features(), P = in.rows(), R = P * k_;
    const auto W = first.weight();
    ensure_shape(point_w_, 2 * H, C);
    point_w_.topRows(H) = W.leftCols(C);
    point_w_.bottomRows(H) = W.rightCols(C) - W.leftCols(C);
    point_packed_.pack(point_w_.data(), 2 * H, C, C);
    ensure_shape(point_bias_, 1, 2 * H);  // the bias on the point's half only
    point_bias_.leftCols(H).setZero();
    if (first.has_bias())
      point_bias_.rightCols(H) = first.bias().transpose();
    else
      point_bias_.rightCols(H).setZero();
    ensure_shape(point_terms_, P, 2 * H);
    const Index pc = exec::chunk_count(P, product_chunks), pw = exec::worker_count(policy, pc);
    if (point_ws_.size() < std::size_t(pw)) point_ws_.resize(std::size_t(pw));
    for (Index w = 0; w < pw; ++w) point_packed_.reserve(point_ws_[std::size_t(w)]);
    detail::for_chunks_dynamic(policy, P, pc, pw, [&](Index w, Index, Index b, Index e) {
      point_packed_.run(point_ws_[std::size_t(w)], e - b, in.data() + b * in.outerStride(), in.outerStride(), point_bias_.data(),
                        point_terms_.data() + b * 2 * H, 2 * H, false);
    });
    // the edges: row (point, j) = P[neighbour, :H] + P[point, H:], then the rest of the edge MLP
    for_edge_chunks(policy, R, H, [&](Index w, Index b, Index e, S* y0) {  // y0: the first Linear's output of the chunk
      for (Index er = b; er < e; ++er) {
        const auto [row, nbr] = features_.edge_rows(er);
        const S* pn = point_terms_.data() + nbr * 2 * H;
        const S* pr = point_terms_.data() + row * 2 * H + H;
        S* y = y0 + (er - b) * H;
        for (Index c = 0; c < H; ++c) y[c] = pn[c] + pr[c];
      }
      mlp_.eval_block_after_first_linear(w, e - b, y0, H, e4_.data() + b * e4_.cols(), e4_.cols());
    });
  }

  Index in_, out_, k_, n_ = 0;
  EdgeMlp kind_;
  bool dynamic_ = false;
  GraphFeatures<S> features_;
  DynamicKnnGraph<S, Search> knn_;
  GraphIndices dyn_graph_;
  Mlp<S> mlp_;
  GroupPool<S> pool_;
  Matrix<S> e0_, e4_, g0_, g4_;
  std::vector<Matrix<S>> gathered_;  ///< eval paths: per worker, one chunk's edge rows (per edge) or first Linear output (point-wise)
  Matrix<S> point_w_, point_terms_;  ///< point-wise eval path: [W_d; W_s − W_d] and the per-point products
  Matrix<S> point_bias_;  ///< [0, b]: the first Linear's bias on the point's half of P
  PackedGemm<S> point_packed_;
  std::vector<typename PackedGemm<S>::Workspace> point_ws_;
  bool lean_ = false;                ///< the last forward was an eval one (e0_ not made)
  bool point_wise_ = true;           ///< eval: the first Linear per point
};
static_assert(assert_layer<EdgeConv<float>>());

}  // namespace simsr::nn
