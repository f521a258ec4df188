#pragma once
/// \file
/// Coordinate-based upsampling (paper §3.2, Eq. 1–3; SPEC §7 `upsampling`): the weight network
/// f_θ maps the query u_ij = [x_j^H, x_i^L (normalized), d_ij] of each HR vertex j and each of
/// its upK LR neighbours i to a logit; a softmax over the neighbours gives w_ij and
/// z_j^H = Σ_i w_ij z_i^L. The query depends on rest shapes only, so in inference the weights
/// are computed once (precompute_weights) and every frame is a sparse M×N product (apply).
///
///     nn::CoordinateUpsampling<float> up(store, "net_upscale", cfg, query, up_indices, N, rng);
///     up.forward(exec::omp, nn::Mode::train, z, zH);                    // training: f_θ once per step, not per item
///     up.precompute_weights(exec::omp); up.apply(exec::omp, z, zH);     // inference
///
/// Official names: `conv_weights.<3l>` (Conv2d, no bias), `conv_weights.<3l+1>` (BatchNorm2d),
/// sin, …, `conv_weights.<3L>` (Conv2d →1 with bias); without BatchNorm the indices step by 2.
/// The w/o-CU ablation (UpsamplingKind::table) replaces f_θ by one free logit per (j, i):
/// `logits` (M×upK, initialized to 0 = equal weights).

#include <memory>
#include <string>
#include <vector>

#include <Eigen/SparseCore>

#include "mlp.hpp"
#include "neighbor_upsample.hpp"
#include "network_config.hpp"
#include "normalization.hpp"

namespace simsr::nn {

/// The (M·upK)×7 query of Eq. 2, row j·upK + i = [hr_n(j), lr_n(idx(j,i)), dist(j,i)] where the
/// positions are normalized (normalize_positions) and the distance is in raw mesh units (as
/// the official code feeds its geodesic distances).
template <class S, class DH, class DL, class DD>
Matrix<S> upsampling_query(const Eigen::MatrixBase<DH>& hr_normalized, const Eigen::MatrixBase<DL>& lr_normalized,
                           const GraphIndices& indices, const Eigen::MatrixBase<DD>& distances) {
  const Index M = indices.rows(), K = indices.cols();
  detail::check_shape("nn::upsampling_query", "HR positions", hr_normalized, M, 3);
  detail::check_shape("nn::upsampling_query", "LR positions", lr_normalized, -1, 3);
  detail::check_shape("nn::upsampling_query", "distances", distances, M, K);
  Matrix<S> q(M * K, 7);
  for (Index j = 0; j < M; ++j)
    for (Index i = 0; i < K; ++i) {
      const Index n = indices(j, i);
      if (n < 0 || n >= lr_normalized.rows())
        throw ArgumentError("nn::upsampling_query: neighbour " + std::to_string(n) + " of HR vertex " + std::to_string(j) + " is outside [0, " +
                            std::to_string(lr_normalized.rows()) + ")");
      const double d = double(distances(j, i));
      if (!std::isfinite(d) || d < 0)
        throw ArgumentError("nn::upsampling_query: distance of HR vertex " + std::to_string(j) + " to neighbour " + std::to_string(i) +
                            " is not a finite non-negative number");
      auto row = q.row(j * K + i);
      for (int c = 0; c < 3; ++c) {
        row[c] = static_cast<S>(hr_normalized(j, c));
        row[3 + c] = static_cast<S>(lr_normalized(n, c));
      }
      row[6] = static_cast<S>(d);
    }
  return q;
}

template <class S = float>
class CoordinateUpsampling {
 public:
  using scalar_type = S;
  using SparseMatrix = Eigen::SparseMatrix<S, Eigen::RowMajor>;

  /// query: (M·upK)×7 (upsampling_query); indices: M×upK into [0, n_lr).
  CoordinateUpsampling(ParameterStore<S>& store, const std::string& prefix, const NetworkConfig& cfg, Matrix<S> query,
                       const GraphIndices& indices, Index n_lr, Rng& rng)
      : kind_(cfg.upsampling), query_(std::move(query)), up_(indices, n_lr), store_(&store) {
    const Index M = indices.rows(), K = indices.cols();
    if (kind_ == UpsamplingKind::table) {
      logits_off_ = store.add_parameter(prefix + ".logits", {M, K});
      return;
    }
    detail::check_shape("nn::CoordinateUpsampling", "query ((M·upK)×7)", query_, M * K, 7);
    mlp_ = std::make_unique<Mlp<S>>(store, prefix + ".conv_weights", stages(cfg), rng);
  }

  /// The tensors this module registers under `prefix` for M HR vertices and K = upK (shapes only).
  static void append_state_shapes(std::vector<TensorEntry>& out, const std::string& prefix, const NetworkConfig& cfg, Index M) {
    if (cfg.upsampling == UpsamplingKind::table)
      out.push_back(TensorEntry{prefix + ".logits", {M, cfg.up_k}, TensorEntry::Kind::parameter, 0, M * cfg.up_k});
    else
      nn::append_state_shapes(out, prefix + ".conv_weights", stages(cfg));
  }

  /// f_θ: hidden layers (Conv2d [no bias + BatchNorm2d] then sin(ω₀·)), then Conv2d → 1 with bias.
  static std::vector<MlpStage> stages(const NetworkConfig& cfg) {
    std::vector<MlpStage> st;
    const typename BatchNorm1d<float>::Options bno{.eps = cfg.batchnorm_eps, .momentum = cfg.batchnorm_momentum};
    Index in = 7;
    int idx = 0;
    for (std::size_t l = 0; l < cfg.up_hidden.size(); ++l) {
      const double w0 = l == 0 ? cfg.up_w0_initial : cfg.up_w0;
      MlpStage s = MlpStage::linear(in, cfg.up_hidden[l], std::to_string(idx++)).dims(2);
      if (cfg.up_siren_init) s.siren(l == 0, w0);
      if (cfg.up_batch_norm) s.no_bias().norm(std::to_string(idx++), bno);
      s.then(Act::sine, w0);
      ++idx;
      st.push_back(s);
      in = cfg.up_hidden[l];
    }
    MlpStage last = MlpStage::linear(in, 1, std::to_string(idx)).dims(2);
    if (cfg.up_siren_init && !cfg.up_hidden.empty()) last.siren(false, cfg.up_w0);
    st.push_back(last);
    return st;
  }

  Index hr_points() const { return up_.hr_points(); }
  Index lr_points() const { return up_.lr_points(); }
  Index neighbors() const { return up_.neighbors(); }
  const GraphIndices& indices() const { return up_.indices(); }
  const Matrix<S>& query() const { return query_; }
  UpsamplingKind kind() const { return kind_; }
  /// Softmax weights of the last forward / precompute_weights (M×upK).
  const Matrix<S>& weights() const { return kind_ == UpsamplingKind::table || !precomputed_ ? up_.weights() : weights_; }

  /// Training path: logits from f_θ (mode: BatchNorm statistics), softmax, gather. z: (B·N)×C.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& z, Matrix<S>& zH) {
    compute_logits(policy, mode);
    up_.forward(policy, logits_view(), z, zH);
  }

  /// After forward: d_z written (overwritten), f_θ's (or the table's) gradients added.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& z, const ConstView<S>& d_zH, Matrix<S>* d_z) {
    up_.backward(policy, z, d_zH, &d_logits_, d_z);
    if (kind_ == UpsamplingKind::table) {
      auto g = store_->gradient(logits_off_, up_.hr_points(), up_.neighbors());
      g += d_logits_;
      return;
    }
    const Index MK = up_.hr_points() * up_.neighbors();
    const ConstView<S> d_col(Eigen::Map<const Matrix<S>>(d_logits_.data(), MK, 1));
    if (split_queries_) {  // this rank's groups of query rows (d_logits is the whole batch's on every rank)
      const Index r0 = query_split_->local_row_begin(), n = query_split_->local_rows();
      mlp_->backward(policy, query_.middleRows(r0, n), local_logits_, d_col.middleRows(r0, n), nullptr);
      return;
    }
    mlp_->backward(policy, query_, logits_, d_col, nullptr);
  }

  /// Inference: weights from f_θ in eval mode (running BatchNorm statistics), once.
  template <exec::HostPolicy Policy>
  void precompute_weights(Policy policy) {
    compute_logits(policy, Mode::eval);
    NeighborUpsample<S>::softmax_rows(policy, logits_view(), weights_);
    precomputed_ = true;
  }
  bool has_precomputed_weights() const { return precomputed_; }
  /// The weights apply gathers with (M×upK; ArgumentError before precompute_weights).
  const Matrix<S>& inference_weights() const {
    if (!precomputed_) throw ArgumentError("nn::CoordinateUpsampling::inference_weights: call precompute_weights(policy) first");
    return weights_;
  }
  /// The batch split of data-parallel training: the gather over the batch items takes part, and
  /// f_θ's rows (the queries of the rest shapes, the same for every item) are split too, in
  /// `query_groups` fixed groups of HR vertices (WorkShard's partition of M, each group its upK
  /// rows per vertex) shared among the ranks: each rank runs f_θ on its groups, the logits are
  /// gathered, and f_θ's weight gradients and BatchNorm statistics are summed per group in group
  /// order — the same bits on any number of ranks (at most query_groups of them), one process too.
  void set_batch_split(BatchSplit* split) {
    if (kind_ == UpsamplingKind::table) return up_.set_batch_split(split);
    if (split && (!query_split_ || query_split_->group() != split->group())) {
      query_split_ = std::make_unique<BatchSplit>(split->group());
      const Index M = up_.hr_points(), K = up_.neighbors(), groups = std::min(query_groups, M);
      if (split->size() > groups)
        throw ArgumentError("nn::CoordinateUpsampling: f_θ's query rows are split in " + std::to_string(groups) + " groups of HR vertices, at most " +
                            std::to_string(groups) + " ranks; got " + std::to_string(split->size()));
      std::vector<Index> rows(static_cast<std::size_t>(groups));
      for (Index g = 0; g < groups; ++g) {
        const auto [b, e] = WorkShard{g, groups}.range(M);
        rows[std::size_t(g)] = (e - b) * K;
      }
      query_split_->set_items(rows);
    }
    up_.set_batch_split(split);
    split_queries_ = split != nullptr;
    mlp_->set_batch_split(split ? query_split_.get() : nullptr);
  }
  /// f_θ's row split (nullptr before the first batch split): its collectives and bytes received.
  const BatchSplit* query_split() const { return query_split_.get(); }
  /// The fixed number of f_θ's row groups under a batch split (see set_batch_split).
  static constexpr Index query_groups = 32;
  /// Forgets the precomputed weights (call after the parameters change).
  void invalidate() { precomputed_ = false; }

  /// Inference gather with the precomputed weights: zH = W·z per batch item.
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstView<S>& z, Matrix<S>& zH) const {
    if (!precomputed_) throw ArgumentError("nn::CoordinateUpsampling::apply: call precompute_weights(policy) first");
    up_.apply(policy, weights_, z, zH);
  }

  /// apply's rows [begin, end) into `out` (leading dimension ld_out), the same arithmetic: for a
  /// caller that consumes them chunk by chunk (NeighborUpsample::apply_rows).
  void apply_rows(const ConstView<S>& z, Index begin, Index end, S* out, Index ld_out) const {
    if (!precomputed_) throw ArgumentError("nn::CoordinateUpsampling::apply_rows: call precompute_weights(policy) first");
    up_.apply_rows(weights_, z, begin, end, out, ld_out);
  }

  /// The precomputed upsampling as an M×N sparse matrix (duplicate neighbours summed).
  SparseMatrix sparse_matrix() const {
    if (!precomputed_) throw ArgumentError("nn::CoordinateUpsampling::sparse_matrix: call precompute_weights(policy) first");
    std::vector<Eigen::Triplet<S>> t;
    const Index M = up_.hr_points(), K = up_.neighbors();
    t.reserve(std::size_t(M * K));
    for (Index j = 0; j < M; ++j)
      for (Index i = 0; i < K; ++i) t.emplace_back(j, up_.indices()(j, i), weights_(j, i));
    SparseMatrix W(M, up_.lr_points());
    W.setFromTriplets(t.begin(), t.end());
    return W;
  }

 private:
  template <class Policy>
  void compute_logits(Policy policy, Mode mode) {
    if (kind_ == UpsamplingKind::table) {
      const Index M = up_.hr_points(), K = up_.neighbors();
      ensure_shape(logits_, M * K, 1);
      Eigen::Map<Matrix<S>>(logits_.data(), M, K) = std::as_const(*store_).value(logits_off_, M, K);
      return;
    }
    if (split_queries_) {  // this rank's groups of query rows, then every rank's logits
      const Index r0 = query_split_->local_row_begin(), n = query_split_->local_rows(), MK = up_.hr_points() * up_.neighbors();
      mlp_->forward(policy, mode, query_.middleRows(r0, n), local_logits_);
      const S* all = query_split_->gather_rows(local_logits_.data(), 1);
      ensure_shape(logits_, MK, 1);
      std::copy(all, all + MK, logits_.data());
      return;
    }
    mlp_->forward(policy, mode, query_, logits_);
  }
  /// The (M·upK)×1 logits seen as M×upK (row-major: the same memory).
  ConstView<S> logits_view() const { return Eigen::Map<const Matrix<S>>(logits_.data(), up_.hr_points(), up_.neighbors()); }

  UpsamplingKind kind_;
  Matrix<S> query_;
  NeighborUpsample<S> up_;
  ParameterStore<S>* store_;
  Index logits_off_ = -1;
  std::unique_ptr<Mlp<S>> mlp_;
  std::unique_ptr<BatchSplit> query_split_;  ///< f_θ's row groups under a batch split
  bool split_queries_ = false;
  Matrix<S> logits_, d_logits_, weights_, local_logits_;
  bool precomputed_ = false;
};

}  // namespace simsr::nn
