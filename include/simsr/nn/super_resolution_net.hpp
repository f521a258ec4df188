#pragma once
/// \file
/// The whole super-resolution network (paper §3, Fig. 2; SPEC §7): LR displacements →
/// h⁰ = [Δx, PE] → feature encoding → z (N×Σ D) → coordinate-based upsampling → z^H (M×Σ D) →
/// SIREN reconstruction → HR displacements, all in the official normalized units (Δx/σ).
/// One class serves both profiles and the ablations: NetworkConfig says which parts exist.
///
///     nn::SuperResolutionNet<float> net(nn::NetworkConfig::official(), geometry, rng);
///     net.forward(exec::omp, nn::Mode::train, ldx, pred);   // ldx (B·N)×3 → pred (B·M)×3
///     net.backward(exec::omp, d_pred, &d_z_reg);            // gradients into net.store()
///     net.prepare_inference(exec::omp);                      // upsampling weights, once
///     net.infer(exec::omp, ldx, pred);                       // eval mode, sparse upsampling
///
/// The dynamic feature-space graph of the embedding's later blocks searches with the second
/// template parameter, any neighbors::NeighborSearch (neighbors::BruteForceKnn by default):
/// `SuperResolutionNet<float, MySearch>` swaps it for the whole network (EdgeConv, FeatureEmbedding
/// and Trainer take it the same way).
///
/// State-dict names are the official ones (`net_feat_emb.*`, `net_upscale.*`, `net_decoder.*`),
/// registered in PyTorch's order, so ParameterStore::entries() is the official state dict.

#include <memory>
#include <optional>
#include <string>

#include <Eigen/SparseCore>

#include "coordinate_upsampling.hpp"
#include "feature_embedding.hpp"
#include "positional_encoding.hpp"
#include "siren_decoder.hpp"

namespace simsr::nn {

/// What the network needs of the two meshes (raw units; nothing normalized yet).
struct NetworkGeometry {
  Points<double> lr_rest;      ///< N×3 LR rest positions
  Points<double> hr_rest;      ///< M×3 HR rest positions
  GraphIndices lr_graph;       ///< N×(≥ knn) LR geodesic neighbours, self first (EdgeConv graph 1)
  GraphIndices up_indices;     ///< M×(≥ upK) LR neighbours of each HR vertex, nearest first
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> up_distances;  ///< M×(≥ upK), raw units
  /// M×N embedding (barycentric) matrix: needed only with cfg.residual over Embedded (the network
  /// then starts at the Embedded interpolation: its output layer is initialized to zero).
  Eigen::SparseMatrix<double, Eigen::RowMajor> embedding;
  /// 3M×3N linear map on displacements flattened by vertex (interp::LocalLinear::linear_map): the
  /// base of cfg.residual with ResidualBase::local_linear. May be empty at construction (it is
  /// fitted on the training frames: SuperResolutionNet::set_residual_map before the first forward).
  Eigen::SparseMatrix<double, Eigen::RowMajor> residual_map;
};

template <class S = float, class Search = neighbors::BruteForceKnn<S>>
class SuperResolutionNet {
 public:
  using scalar_type = S;
  using search_type = Search;  ///< the dynamic feature graph's neighbors::NeighborSearch

  SuperResolutionNet(NetworkConfig cfg, const NetworkGeometry& geo, Rng& rng) : cfg_(std::move(cfg)) {
    cfg_.validate();
    const Index N = geo.lr_rest.rows(), M = geo.hr_rest.rows();
    if (N < 2 || M < 1) throw ArgumentError("nn::SuperResolutionNet: needs N >= 2 LR and M >= 1 HR vertices");
    if (geo.up_indices.rows() != M || geo.up_indices.cols() < cfg_.up_k)
      throw ShapeError("nn::SuperResolutionNet: up_indices (M×≥upK)", {M, cfg_.up_k}, {geo.up_indices.rows(), geo.up_indices.cols()});
    if (geo.up_distances.rows() != M || geo.up_distances.cols() < cfg_.up_k)
      throw ShapeError("nn::SuperResolutionNet: up_distances (M×≥upK)", {M, cfg_.up_k}, {geo.up_distances.rows(), geo.up_distances.cols()});
    if (cfg_.feature_embedding && cfg_.knn >= N) throw ArgumentError("nn::SuperResolutionNet: knn must be < N");
    for (Index i = 0; i < geo.lr_rest.size(); ++i)
      if (!std::isfinite(geo.lr_rest.data()[i])) throw ArgumentError("nn::SuperResolutionNet: LR rest position " + std::to_string(i / 3) + " is not finite");
    for (Index i = 0; i < geo.hr_rest.size(); ++i)
      if (!std::isfinite(geo.hr_rest.data()[i])) throw ArgumentError("nn::SuperResolutionNet: HR rest position " + std::to_string(i / 3) + " is not finite");
    n_ = N;
    m_ = M;
    lr_n_ = normalize_positions<S>(geo.lr_rest, cfg_.norm_mean, cfg_.norm_std);
    hr_n_ = normalize_positions<S>(geo.hr_rest, cfg_.norm_mean, cfg_.norm_std);
    pe_ = std::make_unique<PositionalEncoding<S>>(N, cfg_.pos_feat_dim);
    if (cfg_.feature_embedding) fe_ = std::make_unique<FeatureEmbedding<S, Search>>(store_, "net_feat_emb", cfg_, N, geo.lr_graph, rng);
    const GraphIndices idx = geo.up_indices.leftCols(cfg_.up_k);
    up_ = std::make_unique<CoordinateUpsampling<S>>(store_, "net_upscale", cfg_,
                                                    upsampling_query<S>(hr_n_, lr_n_, idx, geo.up_distances.leftCols(cfg_.up_k)), idx, N, rng);
    decoder_ = std::make_unique<SirenDecoder<S>>(store_, "net_decoder.decoder", cfg_, rng);
    if (cfg_.residual) {
      if (cfg_.residual_base == ResidualBase::embedded) {
        if (geo.embedding.rows() != M || geo.embedding.cols() != N)
          throw ShapeError("nn::SuperResolutionNet: residual needs the M×N embedding matrix", {M, N}, {geo.embedding.rows(), geo.embedding.cols()});
        embedding_ = geo.embedding.template cast<S>();
      } else if (geo.residual_map.rows() > 0 || geo.residual_map.cols() > 0) {
        set_residual_map(geo.residual_map);
      }
      decoder_->zero_output_layer();
    }
  }

  /// The residual base's 3M×3N map (ResidualBase::local_linear; see NetworkGeometry::residual_map).
  /// ArgumentError for another base, ShapeError for another size, ArgumentError for a non-finite entry.
  void set_residual_map(const Eigen::SparseMatrix<double, Eigen::RowMajor>& map) {
    if (!cfg_.residual || cfg_.residual_base != ResidualBase::local_linear)
      throw ArgumentError("nn::SuperResolutionNet: a residual map is the base of residual = true with residual_base = local_linear only");
    if (map.rows() != 3 * m_ || map.cols() != 3 * n_)
      throw ShapeError("nn::SuperResolutionNet: residual map (3M×3N)", {3 * m_, 3 * n_}, {map.rows(), map.cols()});
    for (Index k = 0; k < map.outerSize(); ++k)
      for (typename Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(map, k); it; ++it)
        if (!std::isfinite(it.value())) throw ArgumentError("nn::SuperResolutionNet: residual map entry in row " + std::to_string(k) + " is not finite");
    residual_map_ = map.template cast<S>();
    residual_map_.makeCompressed();
  }
  bool has_residual_map() const { return residual_map_.rows() > 0; }

  /// The state dict this network registers for `cfg` and M HR vertices, in order (names, shapes,
  /// kinds; no weight allocated): a model file's tensors are checked against it before a network
  /// is built (nn::model_data), so a small file cannot ask for a huge network.
  static std::vector<TensorEntry> state_shapes(const NetworkConfig& cfg, Index M) {
    cfg.validate();
    std::vector<TensorEntry> out;
    if (cfg.feature_embedding) FeatureEmbedding<S, Search>::append_state_shapes(out, "net_feat_emb", cfg);
    CoordinateUpsampling<S>::append_state_shapes(out, "net_upscale", cfg, M);
    SirenDecoder<S>::append_state_shapes(out, "net_decoder.decoder", cfg);
    return out;
  }

  SuperResolutionNet(const SuperResolutionNet&) = delete;
  SuperResolutionNet& operator=(const SuperResolutionNet&) = delete;

  const NetworkConfig& config() const { return cfg_; }
  /// Zeroes the decoder's output layer, so the network starts by predicting 0: a correction
  /// added to another predictor starts exactly at that predictor (done for cfg.residual at
  /// construction). Call before training.
  void zero_output_layer() {
    decoder_->zero_output_layer();
    parameters_changed();
  }
  ParameterStore<S>& store() { return store_; }
  const ParameterStore<S>& store() const { return store_; }
  Index lr_points() const { return n_; }
  Index hr_points() const { return m_; }
  Index latent_dim() const { return cfg_.latent_dim(); }
  const Matrix<S>& lr_rest_normalized() const { return lr_n_; }
  const Matrix<S>& hr_rest_normalized() const { return hr_n_; }
  CoordinateUpsampling<S>& upsampling() { return *up_; }
  const CoordinateUpsampling<S>& upsampling() const { return *up_; }
  /// The feature embedding (ArgumentError in the w/o-FE ablation).
  FeatureEmbedding<S, Search>& feature_embedding() {
    if (!fe_) throw ArgumentError("nn::SuperResolutionNet: this network has no feature embedding (w/o FE)");
    return *fe_;
  }
  bool has_feature_embedding() const { return bool(fe_); }
  SirenDecoder<S>& decoder() { return *decoder_; }
  const PositionalEncoding<S>& positional_encoding() const { return *pe_; }
  /// The residual base's M×N embedding (cfg.residual over Embedded; empty otherwise) and 3M×3N
  /// local-linear map (empty until fitted).
  const Eigen::SparseMatrix<S, Eigen::RowMajor>& residual_embedding() const { return embedding_; }
  const Eigen::SparseMatrix<S, Eigen::RowMajor>& residual_map() const { return residual_map_; }
  /// The LR code z = [h⁰, h¹, …] of the last forward ((B·N)×latent_dim) and its upsampling z^H.
  /// An infer that moved the decoder's first layer before the upsampling formed no z^H:
  /// hr_code() then throws ArgumentError (forward(…, Mode::eval) forms it; its outputs are the same
  /// up to rounding).
  const Matrix<S>& code() const { return fe_ ? z_ : h0_; }
  const Matrix<S>& hr_code() const {
    if (last_ == LastCall::infer_first_layer_on_lr)
      throw ArgumentError("nn::SuperResolutionNet::hr_code: the last infer moved the decoder's first layer before the upsampling and formed no z^H "
                          "(run forward(policy, Mode::eval, …), or set_decoder_first_layer_on_lr(false) before infer)");
    return zh_;
  }

  /// Inference (infer) takes the decoder's first Linear before the upsampling when that needs
  /// fewer multiply-adds: W₁·z^H_j = W₁·Σ_i w_ji z_i = Σ_i w_ji·(W₁z_i), so the products run on
  /// the B·N LR rows and the gather on their H₁ columns, instead of the products on the B·M HR
  /// rows (official paper size: N·227·256 + M·20·256 against M·227·256 + M·20·227, 1.1 G fewer
  /// per frame). The same values up to rounding (the products summed in another order). On by
  /// default; false keeps infer bitwise equal to forward(policy, Mode::eval, …) (the benchmark's
  /// baseline).
  void set_decoder_first_layer_on_lr(bool on) { first_layer_on_lr_ = on; }
  bool decoder_first_layer_on_lr() const { return first_layer_on_lr_; }
  /// Whether infer moves the first layer: switched on and fewer multiply-adds per batch item.
  bool infer_moves_decoder_first_layer() const {
    if (!first_layer_on_lr_) return false;
    const double D = double(cfg_.latent_dim()), H = double(decoder_->first_layer_width()), K = double(cfg_.up_k);
    return double(n_) * D * H + double(m_) * K * H < double(m_) * D * H + double(m_) * K * D;
  }

  /// Training (or eval-mode) forward: ldx (B·N)×3 normalized LR displacements → pred (B·M)×3
  /// normalized HR displacements. f_θ runs once per call, whatever B.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& ldx, Matrix<S>& pred) {
    last_ = LastCall::none;  // until it has finished
    encode(policy, mode, ldx);
    up_->forward(policy, mode, code(), zh_);
    decode(policy, mode, ldx, pred);
    last_ = LastCall::forward;
  }

  /// After forward: d_pred (B·M)×3 → parameter gradients (added to the store; zero_grad first).
  /// `d_code`, when given, is an extra gradient on z (the latent regularizer's).
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& d_pred, const Matrix<S>* d_code = nullptr) {
    if (last_ != LastCall::forward)
      throw ArgumentError("nn::SuperResolutionNet::backward: needs a finished forward(policy, mode, …) just before it (not infer)");
    detail::check_shape("nn::SuperResolutionNet", "prediction gradient", d_pred, zh_.rows(), 3);
    decoder_->backward(policy, zh_, pred_ref(), d_pred, &d_zh_);
    up_->backward(policy, code(), d_zh_, &d_z_);
    if (d_code) {
      detail::check_shape("nn::SuperResolutionNet", "code gradient", *d_code, d_z_.rows(), d_z_.cols());
      d_z_ += *d_code;
    }
    if (fe_) fe_->backward(policy, h0_, d_z_);
    up_->invalidate();
  }

  /// Computes the upsampling weights from the rest shapes (eval mode) for infer(policy, …).
  template <exec::HostPolicy Policy>
  void prepare_inference(Policy policy) {
    up_->precompute_weights(policy);
  }

  /// Inference: eval mode with the precomputed upsampling (prepare_inference first).
  template <exec::HostPolicy Policy>
  void infer(Policy policy, const ConstView<S>& ldx, Matrix<S>& pred) {
    last_ = LastCall::none;  // until it has finished
    if (!up_->has_precomputed_weights()) prepare_inference(policy);
    encode(policy, Mode::eval, ldx);
    if (!infer_moves_decoder_first_layer()) {
      up_->apply(policy, code(), zh_);
      decode(policy, Mode::eval, ldx, pred);
      last_ = LastCall::infer;
      return;
    }
    decoder_->first_layer_products(policy, code(), lr_products_);
    const ConstView<S> products(lr_products_);
    decoder_->forward_eval_from_products(
        policy, ldx.rows() / n_ * m_, [&](Index b, Index e, S* y, Index ld) { up_->apply_rows(products, b, e, y, ld); }, pred);
    add_residual_base(policy, ldx, pred);
    last_ = LastCall::infer_first_layer_on_lr;
  }

  /// The batch split of data-parallel training (nn/batch_split.hpp; nullptr: none) for every part
  /// whose rows are batch rows: a forward and backward on this rank's items of the global batch
  /// then give the whole batch's BatchNorm statistics and parameter gradients on every rank, in
  /// bits that do not depend on how many ranks share the batch. Set it for training steps only.
  void set_batch_split(BatchSplit* split) {
    up_->set_batch_split(split);  // first: it refuses more ranks than f_θ's groups, before anything is set
    if (fe_) fe_->set_batch_split(split);
    decoder_->set_batch_split(split);
  }

  /// Drops precomputed upsampling weights (after loading or changing parameters).
  void parameters_changed() { up_->invalidate(); }

 private:
  template <class Policy>
  void encode(Policy policy, Mode mode, const ConstView<S>& ldx) {
    detail::check_shape("nn::SuperResolutionNet", "LR displacements ((B·N)×3)", ldx, -1, 3);
    if (ldx.rows() == 0 || ldx.rows() % n_)
      throw ShapeError("nn::SuperResolutionNet: LR displacements (B·" + std::to_string(n_) + " rows)", {-1, 3}, {ldx.rows(), ldx.cols()});
    pe_->forward(policy, mode, ldx, h0_);
    if (fe_) fe_->forward(policy, mode, h0_, z_);
  }
  template <class Policy>
  void decode(Policy policy, Mode mode, const ConstView<S>& ldx, Matrix<S>& pred) {
    decoder_->forward(policy, mode, zh_, pred);
    pred_ = &pred;
    add_residual_base(policy, ldx, pred);
  }
  /// pred += the residual base's prediction from ldx (cfg.residual; nothing otherwise).
  template <class Policy>
  void add_residual_base(Policy policy, const ConstView<S>& ldx, Matrix<S>& pred) {
    if (!cfg_.residual) return;
    // Row by row under the policy: Eigen's sparse × dense product may start its own OpenMP
    // threads, and exec::seq must start none (tests/threads).
    const Index B = ldx.rows() / n_;
    if (cfg_.residual_base == ResidualBase::embedded) {
      exec::parallel_for(policy, B * m_, [&](Index r) {
        const Index b = r / m_;
        auto out = pred.row(r);
        for (typename decltype(embedding_)::InnerIterator it(embedding_, r - b * m_); it; ++it)
          out += it.value() * ldx.row(b * n_ + it.index());
      });
      return;
    }
    if (!has_residual_map())
      throw ArgumentError("nn::SuperResolutionNet: the local-linear residual base is not fitted yet (set_residual_map, or interp::Learned::train)");
    exec::parallel_for(policy, B * m_, [&](Index r) {
      const Index b = r / m_, v = r - b * m_;
      for (Index c = 0; c < 3; ++c) {  // column 3j + a: LR vertex j of this item, coordinate a
        S acc = 0;
        for (typename decltype(residual_map_)::InnerIterator it(residual_map_, 3 * v + c); it; ++it)
          acc += it.value() * ldx(b * n_ + it.index() / 3, it.index() % 3);
        pred(r, c) += acc;
      }
    });
  }
  ConstView<S> pred_ref() const {
    if (!pred_) throw ArgumentError("nn::SuperResolutionNet::backward: needs a forward first");
    return *pred_;
  }

  NetworkConfig cfg_;
  ParameterStore<S> store_;
  Index n_ = 0, m_ = 0;
  Matrix<S> lr_n_, hr_n_;
  std::unique_ptr<PositionalEncoding<S>> pe_;
  std::unique_ptr<FeatureEmbedding<S, Search>> fe_;
  std::unique_ptr<CoordinateUpsampling<S>> up_;
  std::unique_ptr<SirenDecoder<S>> decoder_;
  Eigen::SparseMatrix<S, Eigen::RowMajor> embedding_, residual_map_;
  Matrix<S> h0_, z_, zh_, d_zh_, d_z_;
  Matrix<S> lr_products_;  ///< infer with the decoder's first layer moved: z·W₁ᵀ on the LR rows
  const Matrix<S>* pred_ = nullptr;
  bool first_layer_on_lr_ = true;
  /// What ran last (and finished): backward needs a forward, hr_code a z^H.
  enum class LastCall { none, forward, infer, infer_first_layer_on_lr };
  LastCall last_ = LastCall::none;
};

}  // namespace simsr::nn
