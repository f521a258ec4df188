#pragma once
/// \file
/// The feature encoding network of §3.1 (SPEC §7, the official `FeatEmb`): S = 2 submodules,
/// each an EdgeConv (graph of block 0 = geodesic kNN on the LR mesh, later blocks = dynamic kNN
/// in feature space) whose output e is pooled to global max and mean features, then
/// `fc_out`(cat(h, e, max, mean)); block s feeds block s+1, and the code is z = [h⁰, h¹, …, h^S].
///
///     nn::FeatureEmbedding<float> fe(store, "net_feat_emb", cfg, N, lr_graph, rng);
///     fe.forward(exec::omp, nn::Mode::train, h0, z);   // (B·N)×35 → (B·N)×227

#include <memory>
#include <string>
#include <vector>

#include "concat.hpp"
#include "dropout.hpp"
#include "edge_conv.hpp"
#include "mlp.hpp"
#include "network_config.hpp"
#include "pooling.hpp"

namespace simsr::nn {

/// One submodule (`blocks.<b>`): (B·N)×in → (B·N)×out.
template <class S = float, class Search = neighbors::BruteForceKnn<S>>
class EmbeddingBlock {
 public:
  using scalar_type = S;

  /// `graph`: N×k fixed graph (block 0) or nullptr for a dynamic feature-space graph.
  EmbeddingBlock(ParameterStore<S>& store, const std::string& prefix, const NetworkConfig& cfg, Index in, Index out, Index n_points,
                 const GraphIndices* graph, Rng& rng)
      : in_(in), out_(out), n_(n_points),
        edge_(store, prefix, in, out, cfg.knn, rng, edge_options(cfg)),
        gmax_(PoolKind::max, n_points), gmean_(PoolKind::mean, n_points), cat_({in, out, out, out}),
        fc_out_(store, prefix + ".fc_out", fc_out_stages(cfg, in, out), rng) {
    if (graph)
      edge_.set_graph(*graph, n_points);
    else
      edge_.use_dynamic_graph(n_points);
  }

  Index out_features(Index = -1) const { return out_; }
  EdgeConv<S, Search>& edge_conv() { return edge_; }
  Mlp<S>& fc_out() { return fc_out_; }
  /// The batch split of data-parallel training (nn/batch_split.hpp) for the edge MLP and fc_out.
  void set_batch_split(BatchSplit* split) {
    edge_.set_batch_split(split);
    fc_out_.set_batch_split(split);
  }
  /// The global max over each item's points (of edge_output()); its argmax() says which point.
  GroupPool<S>& global_max() { return gmax_; }
  /// The edge convolution's output of the last forward, (B·N)×out.
  const Matrix<S>& edge_output() const { return e_; }

  /// The eval forward's factorized first layers (EdgeConv's per point, fc_out's on the parts; the
  /// default) or the layers as the stored path computes them (false: those bits, more products;
  /// the benchmarks' baseline).
  void set_factorized_eval(bool on) {
    factorized_ = on;
    edge_.set_point_wise_first_layer(on);
  }

  /// In eval mode fc_out's first Linear reads the parts of cat(h, e, max, mean) in place, the
  /// global max and mean (the same on every point of an item) once per item
  /// (Mlp::forward_eval_parts): a third to a half of its multiply-adds, no concatenation stored.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& h, Matrix<S>& out) {
    edge_.forward(policy, mode, h, e_);
    gmax_.forward(policy, mode, e_, max_);
    gmean_.forward(policy, mode, e_, mean_);
    if (mode == Mode::eval && factorized_ && fc_out_.eval_fusable()) {  // the pools checked the rows: B whole items
      using Items = Eigen::Map<const Matrix<S>, 0, Eigen::OuterStride<>>;  // row b·N of the broadcast pools: item b's value
      const Index B = h.rows() / n_;
      const Items max_items(max_.data(), B, out_, Eigen::OuterStride<>(n_ * out_)), mean_items(mean_.data(), B, out_, Eigen::OuterStride<>(n_ * out_));
      fc_out_.forward_eval_parts(policy, {{h, false}, {e_, false}, {max_items, true}, {mean_items, true}}, n_, out);
      cat_stale_ = true;
      return;
    }
    cat_.forward(policy, {h, e_, max_, mean_}, cat_out_);
    fc_out_.forward(policy, mode, cat_out_, out);
    cat_stale_ = false;
  }

  /// d_h written when not null (the block's input gradient, all paths summed).
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& h, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_h) {
    if (cat_stale_) {  // the eval forward formed no concatenation
      cat_.forward(policy, {h, e_, max_, mean_}, cat_out_);
      cat_stale_ = false;
    }
    fc_out_.backward(policy, cat_out_, out, d_out, &d_cat_);
    cat_.backward(policy, d_cat_, {&d_h_direct_, &d_e_, &d_max_, &d_mean_}, false);
    gmax_.backward(policy, e_, max_, d_max_, &d_e_part_);
    d_e_ += d_e_part_;
    gmean_.backward(policy, e_, mean_, d_mean_, &d_e_part_);
    d_e_ += d_e_part_;
    if (!d_h) {
      edge_.backward(policy, h, e_, d_e_, nullptr);
      return;
    }
    edge_.backward(policy, h, e_, d_e_, d_h);
    *d_h += d_h_direct_;
  }

  static typename EdgeConv<S, Search>::Options edge_options(const NetworkConfig& cfg) {
    typename EdgeConv<S, Search>::Options o;
    o.slope = static_cast<S>(cfg.leaky_relu_slope);
    o.bn.eps = cfg.batchnorm_eps;
    o.bn.momentum = cfg.batchnorm_momentum;
    o.edge_mlp = cfg.edge_batch_norm ? EdgeConv<S, Search>::EdgeMlp::official : EdgeConv<S, Search>::EdgeMlp::single_linear;
    return o;
  }

  /// fc_out: in+3·out → 3·out → 2·out → out (each with LeakyReLU, BatchNorm before it in the
  /// official profile, which has no biases) → out (linear). Official Sequential indices 0,1,3,4,6,7,9;
  /// without BatchNorm 0,2,4,6.
  static std::vector<MlpStage> fc_out_stages(const NetworkConfig& cfg, Index in, Index out) {
    const Index dims[] = {in + 3 * out, 3 * out, 2 * out, out, out};
    const bool bn = cfg.fc_out_batch_norm;
    const typename BatchNorm1d<float>::Options bno{.eps = cfg.batchnorm_eps, .momentum = cfg.batchnorm_momentum};
    std::vector<MlpStage> st;
    int idx = 0;
    for (int l = 0; l < 4; ++l) {
      MlpStage s = MlpStage::linear(dims[l], dims[l + 1], std::to_string(idx++));
      if (bn) s.no_bias();
      if (l < 3) {
        if (bn) s.norm(std::to_string(idx++), bno);
        s.then(Act::leaky_relu, cfg.leaky_relu_slope);
        ++idx;
      }
      st.push_back(s);
    }
    return st;
  }

 private:
  Index in_, out_, n_;
  EdgeConv<S, Search> edge_;
  GroupPool<S> gmax_, gmean_;
  Concat<S> cat_;
  Mlp<S> fc_out_;
  Matrix<S> e_, max_, mean_, cat_out_, d_cat_, d_h_direct_, d_e_, d_max_, d_mean_, d_e_part_;
  bool cat_stale_ = false;  ///< the last forward was the eval one: cat_out_ not formed
  bool factorized_ = true;
};
static_assert(assert_layer<EmbeddingBlock<float>>());

/// The blocks, their dropout and the code z = [h⁰, h¹, …] ((B·N)×latent_dim). The official module
/// also builds `fc_initial` (Linear 3→D, LeakyReLU, Linear D→D) and never calls it; it is
/// registered (cfg.profile == "official") so the state dict loads, and gets no gradient.
template <class S = float, class Search = neighbors::BruteForceKnn<S>>
class FeatureEmbedding {
 public:
  using scalar_type = S;

  FeatureEmbedding(ParameterStore<S>& store, const std::string& prefix, const NetworkConfig& cfg, Index n_points,
                   const GraphIndices& lr_graph, Rng& rng)
      : n_(n_points), dims_(cfg.emb_feat_dims) {
    if (lr_graph.rows() != n_points || lr_graph.cols() < cfg.knn)
      throw ShapeError("nn::FeatureEmbedding: LR graph (N×k, at least k = " + std::to_string(cfg.knn) + " columns)", {n_points, cfg.knn},
                       {lr_graph.rows(), lr_graph.cols()});
    graph_ = lr_graph.leftCols(cfg.knn);
    const Index S_blocks = Index(dims_.size()) - 1;
    for (Index b = 0; b < S_blocks; ++b) {
      blocks_.push_back(std::make_unique<EmbeddingBlock<S, Search>>(store, prefix + ".blocks." + std::to_string(b), cfg,
                                                                    dims_[std::size_t(b)], dims_[std::size_t(b + 1)], n_points,
                                                                    b == 0 ? &graph_ : nullptr, rng));
      drops_.push_back(std::make_unique<Dropout<S>>(cfg.dropout, Rng(rng())));
    }
    if (cfg.profile == "official") fc_initial_ = std::make_unique<Mlp<S>>(store, prefix + ".fc_initial", fc_initial_stages(cfg), rng);
    std::vector<Index> widths(dims_.begin(), dims_.end());
    cat_ = std::make_unique<Concat<S>>(widths);
    h_.resize(std::size_t(S_blocks));
    pre_drop_.resize(std::size_t(S_blocks));
    d_h_.resize(std::size_t(S_blocks));
  }

  /// The official module's unused fc_initial: Linear 3→D, LeakyReLU, Linear D→D.
  static std::vector<MlpStage> fc_initial_stages(const NetworkConfig& cfg) {
    const Index d = cfg.pos_feat_dim;
    return {MlpStage::linear(3, d, "0").dims(0).then(Act::leaky_relu, cfg.leaky_relu_slope), MlpStage::linear(d, d, "2").dims(0)};
  }

  /// The tensors this module registers under `prefix`, in its order (shapes only).
  static void append_state_shapes(std::vector<TensorEntry>& out, const std::string& prefix, const NetworkConfig& cfg) {
    for (std::size_t b = 0; b + 1 < cfg.emb_feat_dims.size(); ++b) {
      const std::string p = prefix + ".blocks." + std::to_string(b);
      const Index in = cfg.emb_feat_dims[b], width = cfg.emb_feat_dims[b + 1];
      nn::append_state_shapes(out, p + ".edge_conv", EdgeConv<S, Search>::stages(in, width, EmbeddingBlock<S, Search>::edge_options(cfg)));
      nn::append_state_shapes(out, p + ".fc_out", EmbeddingBlock<S, Search>::fc_out_stages(cfg, in, width));
    }
    if (cfg.profile == "official") nn::append_state_shapes(out, prefix + ".fc_initial", fc_initial_stages(cfg));
  }

  Index blocks() const { return Index(blocks_.size()); }
  /// The batch split of data-parallel training for every block and dropout (nullptr: none).
  void set_batch_split(BatchSplit* split) {
    for (auto& b : blocks_) b->set_batch_split(split);
    for (auto& d : drops_) d->set_batch_split(split);
  }
  EmbeddingBlock<S, Search>& block(Index b) { return *blocks_.at(std::size_t(b)); }
  /// The dropout after block b (its Rng is reseeded by the trainer at every step).
  Dropout<S>& dropout(Index b) { return *drops_.at(std::size_t(b)); }
  Index out_features(Index = -1) const { return cat_->out_features(); }
  /// h^{s+1}, the output of block s after its dropout, from the last forward.
  const Matrix<S>& block_output(Index s) const { return h_.at(std::size_t(s)); }
  /// EmbeddingBlock::set_factorized_eval for every block.
  void set_factorized_eval(bool on) {
    for (auto& b : blocks_) b->set_factorized_eval(on);
  }

  /// h0: (B·N)×D₀ → z = [h0, h¹, …] (B·N)×Σ D.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& h0, Matrix<S>& z) {
    const ConstView<S>* x = &h0;
    std::optional<ConstView<S>> xv;
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      blocks_[b]->forward(policy, mode, *x, pre_drop_[b]);
      drops_[b]->forward(policy, mode, pre_drop_[b], h_[b]);
      xv.emplace(h_[b]);
      x = &*xv;
    }
    concat_forward(policy, h0, z);
  }

  /// d_z: gradient of z; parameter gradients added (h0 needs none: it is data).
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& h0, const ConstView<S>& d_z) {
    const std::size_t nb = blocks_.size();
    split(policy, d_z);
    for (std::size_t b = nb; b-- > 0;) {
      drops_[b]->backward(policy, pre_drop_[b], h_[b], d_h_[b], &d_pre_);
      const ConstView<S> in = b == 0 ? h0 : ConstView<S>(h_[b - 1]);
      if (b == 0) {
        blocks_[b]->backward(policy, in, pre_drop_[b], d_pre_, nullptr);
      } else {
        blocks_[b]->backward(policy, in, pre_drop_[b], d_pre_, &d_in_);
        d_h_[b - 1] += d_in_;
      }
    }
  }

 private:
  /// z = [h⁰, h¹, …, h^S].
  template <class Policy>
  void concat_forward(Policy policy, const ConstView<S>& h0, Matrix<S>& z) {
    const std::size_t n = blocks_.size() + 1;
    cat_->forward_parts(policy, n, [&](std::size_t i) { return i == 0 ? h0 : ConstView<S>(h_[i - 1]); }, z);
  }
  /// d_h_[s] = the h^{s+1} columns of d_z (h⁰ is data: no gradient).
  template <class Policy>
  void split(Policy policy, const ConstView<S>& d_z) {
    const std::size_t n = blocks_.size() + 1;
    cat_->backward_parts(policy, d_z, n, [&](std::size_t i) { return i == 0 ? nullptr : &d_h_[i - 1]; }, false);
  }

  Index n_;
  std::vector<Index> dims_;
  GraphIndices graph_;
  std::vector<std::unique_ptr<EmbeddingBlock<S, Search>>> blocks_;
  std::vector<std::unique_ptr<Dropout<S>>> drops_;
  std::unique_ptr<Mlp<S>> fc_initial_;
  std::unique_ptr<Concat<S>> cat_;
  std::vector<Matrix<S>> h_, pre_drop_, d_h_;
  Matrix<S> d_pre_, d_in_;
};

}  // namespace simsr::nn
