#pragma once
/// \file
/// Linear layer = 1×1 convolution over points: out = in·Wᵀ + b (SPEC §7: every `1×1 conv` and
/// `nn.Linear` of the network).
///
///     nn::Linear<float> fc(store, "fc_out.0", 323, 384, rng, {.bias = false, .kernel_dims = 1});
///     fc.forward(exec::omp, nn::Mode::train, h, y);  // h: rows×323 → y: rows×384

#include <atomic>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "../core/packed_gemm.hpp"
#include "../core/serial_gemm.hpp"
#include "batch_split.hpp"
#include "layer.hpp"
#include "parameters.hpp"

namespace simsr::nn {

namespace detail {
/// for_chunks over `chunks` plain chunks of [0, n), handed out one at a time to whichever worker
/// is free (for_row_chunks_dynamic, nn/batch_split.hpp).
template <class Policy, class Body>
void for_chunks_dynamic(Policy policy, Index n, Index chunks, Index workers, Body&& body) {
  RowChunks plain;
  plain.rows = n;
  plain.plain = chunks;
  for_row_chunks_dynamic(policy, plain, workers, body);
}
}  // namespace detail

/// Per-row affine map of rows×in activations to rows×out. Parameters `<name>.weight` (out×in,
/// row-major like PyTorch's) and, with `bias`, `<name>.bias` (out).
template <class S = float>
class Linear {
 public:
  using scalar_type = S;

  struct Options {
    bool bias = true;     ///< PyTorch's bias=…
    int kernel_dims = 0;  ///< trailing 1s of the state-dict weight shape: 0 nn.Linear, 1 Conv1d, 2 Conv2d
  };

  /// Registers the parameters in `store` (which must outlive the layer) and draws PyTorch's
  /// default initialization: weight and bias U(±1/√in).
  Linear(ParameterStore<S>& store, std::string name, Index in, Index out, Rng& rng, Options options = {})
      : store_(&store), name_(std::move(name)), where_("nn::Linear '" + name_ + "'"), in_(in), out_(out) {
    if (in < 1 || out < 1) throw ArgumentError("nn::Linear '" + name_ + "': in and out features must be >= 1");
    if (options.kernel_dims < 0 || options.kernel_dims > 3) throw ArgumentError("nn::Linear '" + name_ + "': kernel_dims must be 0..3");
    std::vector<Index> shape{out, in};
    shape.insert(shape.end(), static_cast<std::size_t>(options.kernel_dims), Index(1));
    w_off_ = store.add_parameter(name_ + ".weight", shape);
    if (options.bias) b_off_ = store.add_parameter(name_ + ".bias", {out});
    init_default(rng);
  }

  const std::string& name() const { return name_; }
  Index in_features() const { return in_; }
  Index out_features(Index = -1) const { return out_; }
  bool has_bias() const { return b_off_ >= 0; }

  /// out×in weight and its gradient; bias (out) and its gradient (ArgumentError without bias).
  MatrixMap<S> weight() { return store_->value(w_off_, out_, in_); }
  ConstMatrixMap<S> weight() const { return std::as_const(*store_).value(w_off_, out_, in_); }
  MatrixMap<S> weight_grad() { return store_->gradient(w_off_, out_, in_); }
  VectorMap<S> bias() { return VectorMap<S>(store_->value(bias_offset(), out_, 1).data(), out_); }
  VectorMap<S> bias_grad() { return VectorMap<S>(store_->gradient(bias_offset(), out_, 1).data(), out_); }

  /// PyTorch's reset_parameters(): weight and bias U(±1/√in).
  void init_default(Rng& rng) {
    const double bound = 1.0 / std::sqrt(static_cast<double>(in_));
    init_uniform(rng, bound, bound);
  }
  /// Weight U(±w_bound), then bias U(±b_bound).
  void init_uniform(Rng& rng, double w_bound, double b_bound) {
    auto W = weight();
    for (Index i = 0; i < W.size(); ++i) W.data()[i] = static_cast<S>(uniform(rng, -w_bound, w_bound));
    if (has_bias()) {
      auto b = bias();
      for (Index i = 0; i < out_; ++i) b[i] = static_cast<S>(uniform(rng, -b_bound, b_bound));
    }
  }
  template <class D>
  void set_weight(const Eigen::MatrixBase<D>& W) {
    detail::check_shape(where_, "weight", W, out_, in_);
    weight() = W.template cast<S>();
  }
  template <class D>
  void set_bias(const Eigen::MatrixBase<D>& b) {
    if (b.size() != out_) throw ShapeError(where() + ": bias", {out_}, {b.size()});
    bias() = b.template cast<S>();
  }

  /// The batch split of data-parallel training (nn/batch_split.hpp; nullptr: none): rows are then
  /// chunked per batch item and the weight gradient is summed per item in global item order.
  void set_batch_split(BatchSplit* split) { split_ = split; }

  /// out (rows×out) = in (rows×in)·Wᵀ + b. The mode does not matter here.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode, const ConstView<S>& in, Matrix<S>& out) {
    forward_rows(policy, in, out, true);
  }
  /// forward without the bias: out = in·Wᵀ (a caller that adds the bias after a linear map of the
  /// rows: Mlp::first_linear_products).
  template <exec::HostPolicy Policy>
  void forward_without_bias(Policy policy, const ConstView<S>& in, Matrix<S>& out) {
    forward_rows(policy, in, out, false);
  }

  /// A worker's scratch of forward_block.
  using Workspace = typename PackedGemm<S>::Workspace;
  /// The pieces of forward for callers that run it chunk by chunk (Mlp's fused eval path,
  /// EdgeConv's): prepare_forward packs the current weight (once per forward: the parameters may
  /// have changed since the last), reserve_forward sizes a worker's scratch, forward_block computes
  /// one block of rows (row-major, leading dimensions ld_in, ld_out) with the weight packed last.
  /// Each output entry depends on its row and the parameters only (PackedGemm): any chunking gives
  /// forward's values exactly.
  void prepare_forward() {
    const ParameterStore<S>& store = *store_;
    packed_.pack(store.value(w_off_, out_, in_).data(), out_, in_, in_);
  }
  void reserve_forward(Workspace& ws) const { packed_.reserve(ws); }
  void forward_block(Workspace& ws, Index rows, const S* in, Index ld_in, S* out, Index ld_out) const {
    check_packed();
    packed_.run(ws, rows, in, ld_in, has_bias() ? std::as_const(*store_).values().data() + b_off_ : nullptr, out, ld_out, false);
  }
  /// forward_block without the bias: out = in·Wᵀ, or with `accumulate` out += in·Wᵀ.
  void products_block(Workspace& ws, Index rows, const S* in, Index ld_in, S* out, Index ld_out, bool accumulate) const {
    check_packed();
    packed_.run(ws, rows, in, ld_in, nullptr, out, ld_out, accumulate);
  }

  /// Adds ∂/∂W = d_outᵀ·in and ∂/∂b = column sums of d_out into the store; d_in = d_out·W.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in) {
    detail::check_shape(where_, "input", in, -1, in_);
    detail::check_shape(where_, "output gradient", d_out, in.rows(), out_);
    const Index R = in.rows();
    const auto W = std::as_const(*store_).value(w_off_, out_, in_);
    if (d_in) {
      ensure_shape(*d_in, R, in_);
      const auto chunks = detail::row_chunks(split_, R, product_chunks, where_);
      const Index workers = exec::worker_count(policy, chunks.count());
      reserve(gemm_din_, workers, chunks.max_size(), in_, out_);
      detail::for_row_chunks_dynamic(policy, chunks, workers, [&](Index w, Index, Index b, Index e) {
        gemm_din_[std::size_t(w)].run(e - b, in_, out_, d_out.data() + b * d_out.outerStride(), d_out.outerStride(), false, W.data(),
                                      in_, false, d_in->data() + b * in_, in_, false);
      });
    }
    if (R == 0) return;
    // Weight gradient: one partial product per fixed row chunk (row c of parts_: W's then b's),
    // summed in chunk order; under a batch split folded per item and summed in global item order.
    const auto chunks = detail::row_chunks(split_, R, reduction_chunks, where_);
    const Index nr = chunks.count(), workers = exec::worker_count(policy, nr), wsize = out_ * in_, width = wsize + (has_bias() ? out_ : 0);
    reserve(gemm_dw_, workers, out_, in_, chunks.max_size());
    ensure_shape(parts_, nr, width);
    detail::for_row_chunks_dynamic(policy, chunks, workers, [&](Index w, Index c, Index b, Index e) {
      S* part = parts_.data() + c * width;
      gemm_dw_[std::size_t(w)].run(out_, in_, e - b, d_out.data() + b * d_out.outerStride(), d_out.outerStride(), true,
                                   in.data() + b * in.outerStride(), in.outerStride(), false, part, in_, false);
      if (has_bias()) VectorMap<S>(part + wsize, out_) = d_out.middleRows(b, e - b).colwise().sum().transpose();
    });
    const S* all = parts_.data();
    Index count = nr;
    if (split_) {
      detail::fold_item_partials(chunks, parts_.data(), width);
      all = split_->gather(parts_.data(), width);
      count = split_->items();
    }
    auto gW = weight_grad();
    for (Index c = 0; c < count; ++c) gW += ConstMatrixMap<S>(all + c * width, out_, in_);
    if (has_bias()) {
      auto gb = store_->gradient(b_off_, 1, out_);
      for (Index c = 0; c < count; ++c) gb += ConstMatrixMap<S>(all + c * width + wsize, 1, out_);
    }
  }

 private:
  template <class Policy>
  void forward_rows(Policy policy, const ConstView<S>& in, Matrix<S>& out, bool with_bias) {
    detail::check_shape(where_, "input", in, -1, in_);
    const Index R = in.rows();
    ensure_shape(out, R, out_);
    const auto chunks = detail::row_chunks(split_, R, product_chunks, where_);
    const Index workers = exec::worker_count(policy, chunks.count());
    prepare_forward();
    if (ws_fwd_.size() < std::size_t(workers)) ws_fwd_.resize(std::size_t(workers));
    for (Index w = 0; w < workers; ++w) reserve_forward(ws_fwd_[std::size_t(w)]);
    detail::for_row_chunks_dynamic(policy, chunks, workers, [&](Index w, Index, Index b, Index e) {
      const S* x = in.data() + b * in.outerStride();
      if (with_bias)
        forward_block(ws_fwd_[std::size_t(w)], e - b, x, in.outerStride(), out.data() + b * out_, out_);
      else
        products_block(ws_fwd_[std::size_t(w)], e - b, x, in.outerStride(), out.data() + b * out_, out_, false);
    });
  }

  const std::string& where() const { return where_; }
  Index bias_offset() const {
    if (!has_bias()) throw ArgumentError(where() + " has no bias");
    return b_off_;
  }
  void check_packed() const {
    if (packed_.in_features() != in_ || packed_.out_features() != out_) throw ArgumentError(where() + ": forward_block before prepare_forward");
  }
  static void reserve(std::vector<SerialGemm<S>>& g, Index workers, Index rows, Index cols, Index depth) {
    if (g.size() < std::size_t(workers)) g.resize(std::size_t(workers));
    for (Index w = 0; w < workers; ++w) g[std::size_t(w)].reserve(rows, cols, depth);
  }

  ParameterStore<S>* store_;
  std::string name_, where_;
  Index in_, out_;
  Index w_off_ = -1, b_off_ = -1;
  BatchSplit* split_ = nullptr;
  PackedGemm<S> packed_;           ///< the weight as forward's register panels (prepare_forward)
  std::vector<Workspace> ws_fwd_;  ///< forward's per-worker scratch
  std::vector<SerialGemm<S>> gemm_din_, gemm_dw_;
  Matrix<S> parts_;  ///< weight-gradient partials, one row per chunk (W's out·in, then b's out)
};
static_assert(assert_layer<Linear<float>>());

}  // namespace simsr::nn
