#pragma once
/// \file
/// EdgeConv (DGCNN; paper §3.1, SPEC §7), the official `edge_conv` of each feature-embedding
/// block: graph features cat(h_j − h_i, h_i) → 1×1 Conv2d 2C→2out (no bias) → BatchNorm2d →
/// LeakyReLU(0.2) → 1×1 Conv2d 2out→out (no bias) → max over the k neighbours.
///
///     nn::EdgeConv<float> ec(store, "net_feat_emb.blocks.0", 35, 64, 5, rng);
///     ec.set_graph(lr_graph, N);                     // fixed graph (block 0), or:
///     ec.use_dynamic_graph(N);                       // kNN in feature space per forward (block 1)
///     ec.forward(nn::Mode::train, h, e);             // h: (B·N)×35 → e: (B·N)×64
///
/// State-dict names (official_model.py): `<prefix>.edge_conv.0.weight` (2out×2C×1×1),
/// `<prefix>.edge_conv.1.{weight,bias,running_mean,running_var,num_batches_tracked}`,
/// `<prefix>.edge_conv.3.weight` (out×2out×1×1).

#include <string>

#include "activations.hpp"
#include "batch_norm.hpp"
#include "graph_features.hpp"
#include "linear.hpp"
#include "pooling.hpp"

namespace simsr::nn {

/// One EdgeConv: (B·N)×in → (B·N)×out. A fixed graph (set_graph) serves every batch item; a
/// dynamic graph (use_dynamic_graph) is rebuilt from the input features at every forward (k
/// nearest other points per item, see DynamicKnnGraph) and is not differentiated. Backward must
/// follow the forward of the same input (it reuses the graph and the intermediate activations).
template <class S = float>
class EdgeConv {
 public:
  using scalar_type = S;

  struct Options {
    S slope = S(0.2);                       ///< LeakyReLU negative slope
    typename BatchNorm1d<S>::Options bn{};  ///< eps, momentum of the BatchNorm2d
  };

  EdgeConv(ParameterStore<S>& store, const std::string& prefix, Index in, Index out, Index k, Rng& rng, Options options = {})
      : in_(in), out_(out), k_(k),
        conv0_(store, prefix + ".edge_conv.0", 2 * in, 2 * out, rng, {.bias = false, .kernel_dims = 2}),
        bn_(store, prefix + ".edge_conv.1", 2 * out, options.bn),
        act_(options.slope),
        conv3_(store, prefix + ".edge_conv.3", 2 * out, out, rng, {.bias = false, .kernel_dims = 2}),
        pool_(PoolKind::max, k, false) {
    if (k < 1) throw ArgumentError("nn::EdgeConv '" + prefix + "': k must be >= 1");
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

  Linear<S>& conv0() { return conv0_; }
  BatchNorm1d<S>& batch_norm() { return bn_; }
  Linear<S>& conv3() { return conv3_; }

  template <exec::HostPolicy Policy = exec::seq_t>
  void forward(Mode mode, const ConstView<S>& in, Matrix<S>& out, Policy policy = {}) {
    detail::check_shape("nn::EdgeConv", "input", in, -1, in_);
    if (dynamic_) {
      knn_.build(policy, in, n_, k_, dyn_graph_);
      features_.set_graph(dyn_graph_, n_);
    }
    features_.forward(mode, in, e0_, policy);
    conv0_.forward(mode, e0_, e1_, policy);
    bn_.forward(mode, e1_, e2_, policy);
    act_.forward(mode, e2_, e3_, policy);
    conv3_.forward(mode, e3_, e4_, policy);
    pool_.forward(mode, e4_, out, policy);
  }

  template <exec::HostPolicy Policy = exec::seq_t>
  void backward(const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in, Policy policy = {}) {
    detail::check_shape("nn::EdgeConv", "input", in, e0_.rows() / k_, in_);
    pool_.backward(e4_, out, d_out, &g4_, policy);
    conv3_.backward(e3_, e4_, g4_, &g3_, policy);
    act_.backward(e2_, e3_, g3_, &g2_, policy);
    bn_.backward(e1_, e2_, g2_, &g1_, policy);
    conv0_.backward(e0_, e1_, g1_, d_in ? &g0_ : nullptr, policy);
    if (d_in) features_.backward(in, e0_, g0_, d_in, policy);
  }

 private:
  Index in_, out_, k_, n_ = 0;
  bool dynamic_ = false;
  GraphFeatures<S> features_;
  DynamicKnnGraph<S> knn_;
  GraphIndices dyn_graph_;
  Linear<S> conv0_;
  BatchNorm1d<S> bn_;
  LeakyReLU<S> act_;
  Linear<S> conv3_;
  GroupPool<S> pool_;
  Matrix<S> e0_, e1_, e2_, e3_, e4_, g0_, g1_, g2_, g3_, g4_;
};

}  // namespace simsr::nn
