#pragma once
/// \file
/// BatchNorm over channels (PyTorch's BatchNorm1d on B×C×N, and BatchNorm2d on B×C×N×K: in the
/// points × channels layout both normalize each column over all rows). SPEC §7: between the 1×1
/// convolutions of the edge MLP, of `fc_out` and of the upsampling weight network.
///
///     nn::BatchNorm1d<float> bn(store, "fc_out.1", 384);
///     bn.forward(exec::omp, nn::Mode::train, y, z);  // batch statistics, running averages updated

#include <cmath>
#include <string>
#include <vector>

#include "batch_split.hpp"
#include "layer.hpp"
#include "parameters.hpp"

namespace simsr::nn {

/// y = (x − μ_c)/√(σ²_c + eps)·γ_c + β_c per channel c.
/// - train: μ, σ² are the batch mean and *biased* variance over all rows (two passes, summed in
///   double over fixed row chunks); running_mean/var ← (1 − momentum)·running + momentum·batch
///   with the *unbiased* variance σ²·R/(R − 1); num_batches_tracked += 1 (all as PyTorch).
/// - eval: μ, σ² are running_mean, running_var (unless track_running_stats is off).
/// Tensors: `<name>.weight` γ (1s), `<name>.bias` β (0s) when affine; buffers `<name>.running_mean`
/// (0s), `<name>.running_var` (1s), `<name>.num_batches_tracked` (shape {}) when tracking.
template <class S = float>
class BatchNorm1d {
 public:
  using scalar_type = S;

  struct Options {
    double eps = 1e-5;
    double momentum = 0.1;
    bool affine = true;
    bool track_running_stats = true;
  };

  BatchNorm1d(ParameterStore<S>& store, std::string name, Index channels, Options options = {})
      : store_(&store), name_(std::move(name)), where_("nn::BatchNorm1d '" + name_ + "'"), c_(channels), opt_(options) {
    if (channels < 1) throw ArgumentError(where() + ": channels must be >= 1");
    if (!(options.eps > 0)) throw ArgumentError(where() + ": eps must be > 0");
    if (!(options.momentum >= 0 && options.momentum <= 1)) throw ArgumentError(where() + ": momentum must be in [0, 1]");
    if (options.affine) {
      w_off_ = store.add_parameter(name_ + ".weight", {channels});
      b_off_ = store.add_parameter(name_ + ".bias", {channels});
      store.value(w_off_, 1, channels).setOnes();
    }
    if (options.track_running_stats) {
      rm_off_ = store.add_buffer(name_ + ".running_mean", {channels}, S(0));
      rv_off_ = store.add_buffer(name_ + ".running_var", {channels}, S(1));
      nbt_off_ = store.add_buffer(name_ + ".num_batches_tracked", {}, S(0));
    }
  }

  const std::string& name() const { return name_; }
  Index channels() const { return c_; }
  Index out_features(Index = -1) const { return c_; }
  const Options& options() const { return opt_; }

  /// γ, β and their gradients (ArgumentError when not affine).
  VectorMap<S> weight() { return param(w_off_, false); }
  VectorMap<S> bias() { return param(b_off_, false); }
  VectorMap<S> weight_grad() { return param(w_off_, true); }
  VectorMap<S> bias_grad() { return param(b_off_, true); }
  /// Running statistics (ArgumentError when not tracked).
  VectorMap<S> running_mean() { return buf(rm_off_, c_); }
  VectorMap<S> running_var() { return buf(rv_off_, c_); }
  S num_batches_tracked() { return buf(nbt_off_, 1)[0]; }

  /// The batch split of data-parallel training (nullptr: none): the statistics are then those of the
  /// whole global batch (per-item partial sums added in global item order), the same on every rank.
  void set_batch_split(BatchSplit* split) { split_ = split; }

  /// The normalized input x̂ of the last forward (rows×C); kept for backward.
  const Matrix<S>& normalized() const { return xhat_; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& in, Matrix<S>& out) {
    detail::check_shape(where_, "input", in, -1, c_);
    const Index R = in.rows();
    batch_stats_ = mode == Mode::train || !opt_.track_running_stats;
    ensure_shape(xhat_, R, c_);
    ensure_shape(out, R, c_);
    ensure_size(mean_, c_);
    ensure_size(inv_std_, c_);
    if (batch_stats_) {
      const Index rows = batch_rows(R);
      if (rows < 2) throw ArgumentError(where() + ": batch statistics need more than 1 row per channel, got " + std::to_string(rows));
      column_sums(policy, R, [&](Index r, auto acc) { acc += in.row(r).template cast<double>(); });
      mean_ = total_ / double(rows);
      column_sums(policy, R, [&](Index r, auto acc) { acc += (in.row(r).template cast<double>() - mean_.transpose()).cwiseAbs2(); });
      ensure_size(var_, c_);
      var_ = total_ / double(rows);
      inv_std_ = (var_.array() + opt_.eps).rsqrt();
      if (mode == Mode::train && opt_.track_running_stats) {
        const double m = opt_.momentum, unbias = double(rows) / double(rows - 1);
        auto rm = running_mean(), rv = running_var();
        for (Index c = 0; c < c_; ++c) {
          rm[c] = static_cast<S>((1 - m) * double(rm[c]) + m * mean_[c]);
          rv[c] = static_cast<S>((1 - m) * double(rv[c]) + m * var_[c] * unbias);
        }
        buf(nbt_off_, 1)[0] += S(1);
      }
    } else {
      load_running_stats();
    }
    load_transform();
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
      for (Index r = b; r < e; ++r) {
        xhat_.row(r) = (in.row(r) - shift_.transpose()).cwiseProduct(scale_.transpose());
        out.row(r) = xhat_.row(r).cwiseProduct(gamma_.transpose()) + beta_.transpose();
      }
    });
  }

  /// True when eval-mode forward uses the running statistics (a per-channel affine map that
  /// apply_eval can run in place, e.g. fused into the preceding Linear's chunks).
  bool eval_uses_running_stats() const { return opt_.track_running_stats; }

  /// The eval-mode transform without the layer's own buffers: prepare_eval() once per forward,
  /// then apply_eval(x, ld, rows) on a row-major block in place, with the arithmetic of forward(eval)
  /// (x̂ = (x − μ)·(1/σ), then x̂·γ + β), so the values are those forward would give. It leaves
  /// normalized() and the backward state alone (Mlp recomputes them before an eval backward).
  void prepare_eval() {
    if (!opt_.track_running_stats) throw ArgumentError(where() + ": apply_eval needs running statistics");
    load_running_stats();
    load_transform();
  }
  /// The eval transform's per-channel values in S, as apply_eval uses them: rows μ, 1/σ, γ, β
  /// (4×C; nn::InferenceNet copies them to its kernels). ArgumentError without running statistics.
  Matrix<S> eval_transform() {
    prepare_eval();
    Matrix<S> t(4, c_);
    t.row(0) = shift_.transpose();
    t.row(1) = scale_.transpose();
    t.row(2) = gamma_.transpose();
    t.row(3) = beta_.transpose();
    return t;
  }
  void apply_eval(S* x, Index ld, Index rows) const {
    for (Index r = 0; r < rows; ++r) {
      Eigen::Map<Eigen::Matrix<S, 1, Eigen::Dynamic>> row(x + r * ld, c_);
      row = (row - shift_.transpose()).cwiseProduct(scale_.transpose());
      row = row.cwiseProduct(gamma_.transpose()) + beta_.transpose();
    }
  }

  /// With batch statistics: d_in = γ/σ·(d_out − mean(d_out) − x̂·mean(d_out ⊙ x̂)) per channel
  /// (every output depends on every row); with running statistics: d_in = γ/σ·d_out.
  /// Adds ∂/∂γ = Σ d_out ⊙ x̂ and ∂/∂β = Σ d_out.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in) {
    detail::check_shape(where_, "input", in, xhat_.rows(), c_);
    detail::check_shape(where_, "output gradient", d_out, xhat_.rows(), c_);
    const Index R = in.rows();
    column_sums(policy, R, [&](Index r, auto acc) { acc += d_out.row(r).template cast<double>(); });
    ensure_size(dsum_, c_);
    dsum_ = total_;
    column_sums(policy, R, [&](Index r, auto acc) { acc += d_out.row(r).template cast<double>().cwiseProduct(xhat_.row(r).template cast<double>()); });
    ensure_size(dxsum_, c_);
    dxsum_ = total_;
    if (opt_.affine) {
      auto gw = weight_grad(), gb = bias_grad();
      for (Index c = 0; c < c_; ++c) gw[c] += static_cast<S>(dxsum_[c]), gb[c] += static_cast<S>(dsum_[c]);
    }
    if (!d_in) return;
    ensure_shape(*d_in, R, c_);
    for (Index c = 0; c < c_; ++c) scale_[c] = static_cast<S>(double(gamma_[c]) * inv_std_[c]);
    ensure_size(dmean_, c_);
    ensure_size(dxmean_, c_);
    if (batch_stats_) {
      const Index rows = batch_rows(R);
      dmean_ = (dsum_ / double(rows)).template cast<S>();
      dxmean_ = (dxsum_ / double(rows)).template cast<S>();
    } else {
      dmean_.setZero(), dxmean_.setZero();
    }
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
      for (Index r = b; r < e; ++r)
        d_in->row(r) = (d_out.row(r) - dmean_.transpose() - xhat_.row(r).cwiseProduct(dxmean_.transpose())).cwiseProduct(scale_.transpose());
    });
  }

 private:
  const std::string& where() const { return where_; }
  /// μ, 1/σ from the running statistics (eval mode).
  void load_running_stats() {
    ensure_size(mean_, c_);
    ensure_size(inv_std_, c_);
    mean_ = running_mean().template cast<double>();
    inv_std_ = (running_var().template cast<double>().array() + opt_.eps).rsqrt();
  }
  /// The per-channel transform in S from μ, 1/σ, γ, β: shared by forward and apply_eval, so the
  /// fused eval path rounds exactly as forward does.
  void load_transform() {
    shift_ = mean_.template cast<S>();
    scale_ = inv_std_.template cast<S>();
    ensure_size(gamma_, c_);
    ensure_size(beta_, c_);
    if (opt_.affine)
      gamma_ = weight(), beta_ = bias();
    else
      gamma_.setOnes(), beta_.setZero();
  }
  VectorMap<S> param(Index off, bool grad) {
    if (off < 0) throw ArgumentError(where() + " is not affine: it has no weight or bias");
    return VectorMap<S>((grad ? store_->gradients() : store_->values()).data() + off, c_);
  }
  VectorMap<S> buf(Index off, Index n) {
    if (off < 0) throw ArgumentError(where() + " does not track running statistics");
    return store_->buffer(off, n);
  }
  /// Rows of the whole batch: R, or under a batch split R's rows per item × the global items.
  Index batch_rows(Index R) const { return split_ ? split_->total_rows(R, where_) : R; }

  /// total_ (C) = Σ_rows of the per-row contributions, in double, summed per fixed row chunk and
  /// then over chunks in order (so seq and omp agree bit for bit); under a batch split, per item
  /// and then over the global batch's items in order (so any number of ranks agrees too).
  template <class Policy, class Add>
  void column_sums(Policy policy, Index R, Add&& add) {
    const auto chunks = detail::row_chunks(split_, R, reduction_chunks, where_);
    const Index nr = chunks.count(), workers = exec::worker_count(policy, nr);
    ensure_shape(parts_, nr, c_);
    detail::for_row_chunks(policy, chunks, workers, [&](Index, Index c, Index b, Index e) {
      parts_.row(c).setZero();
      for (Index r = b; r < e; ++r) add(r, parts_.row(c));
    });
    ensure_size(total_, c_);
    total_.setZero();
    if (!split_) {
      for (Index c = 0; c < nr; ++c) total_ += parts_.row(c).transpose();
      return;
    }
    detail::fold_item_partials(chunks, parts_.data(), c_);
    split_->sum_items(parts_.data(), c_, total_.data());
  }

  ParameterStore<S>* store_;
  BatchSplit* split_ = nullptr;
  std::string name_, where_;
  Index c_;
  Options opt_;
  Index w_off_ = -1, b_off_ = -1, rm_off_ = -1, rv_off_ = -1, nbt_off_ = -1;
  bool batch_stats_ = true;
  Matrix<S> xhat_;
  Matrix<double> parts_;
  Vector<double> total_, mean_, inv_std_, var_, dsum_, dxsum_;
  Vector<S> shift_, scale_, gamma_, beta_, dmean_, dxmean_;
};
static_assert(assert_layer<BatchNorm1d<float>>());

}  // namespace simsr::nn
