#pragma once
/// \file
/// The training loss of the network (paper Eq. 4–7; SPEC §7 "training"), as the config says:
///   official: 10·mean|Δx̂ − Δx|/B + 2·mean|z| + 0.001·mean(1 − cos(n̂, n))   (model.py)
///   paper:    Σ|Δx̂ − Δx| + 0.001·Σ(1 − cos) + β(step)·Σ_s Σ_i ‖h^s_i‖₂, sums per item averaged
///             over the batch, β ramped 0.001 → 20.
/// Face normals are those of rest + displacement in normalized units (as the official code).
/// simsr adds an optional contact term (config w_contact > 0, patches by set_contact):
///   + w_contact·(1/B)·Σ (m − s)² over the penetrating or too-close lip pairs (contact_loss.hpp),
/// with distances in network units (mesh units / NetworkConfig::displacement_unit()).
///
///     nn::SuperResolutionLoss<float> loss(cfg, net.hr_rest_normalized(), hr_faces);
///     auto t = loss.evaluate(exec::omp, pred, target, net.code(), step, &d_pred, &d_code);
///     net.backward(exec::omp, d_pred, &d_code);

#include <optional>
#include <string>

#include "batch_split.hpp"
#include "contact_loss.hpp"
#include "face_normal_loss.hpp"
#include "latent_norm_loss.hpp"
#include "losses.hpp"
#include "network_config.hpp"

namespace simsr::nn {

template <class S = float>
class SuperResolutionLoss {
 public:
  /// The weighted terms (each already multiplied by its weight) and their sum.
  struct Terms {
    double total = 0, recon = 0, z_reg = 0, face_normals = 0, contact = 0;
    Index penetrating = 0;  ///< contact pairs with the vertex behind the other patch (0 without the term)
    double beta = 0;  ///< the latent weight used (w_zreg, or the ramp's value)
  };

  /// `total_steps`: the run's optimizer steps (the ramp's length when zreg_ramp_steps is 0).
  template <class DR, class DF>
  SuperResolutionLoss(const NetworkConfig& cfg, const Eigen::MatrixBase<DR>& hr_rest_normalized, const Eigen::MatrixBase<DF>& faces,
                      long total_steps = 1)
      : cfg_(cfg), fn_(hr_rest_normalized, faces, cfg.sum_reductions ? Reduction::sum : Reduction::mean) {
    if (cfg.zreg == LatentRegularizer::ramped_norm) {
      ramp_.start = cfg.zreg_start;
      ramp_.end = cfg.zreg_end;
      ramp_.ramp_steps = cfg.zreg_ramp_steps > 0 ? long(cfg.zreg_ramp_steps) : std::max(1L, total_steps);
      ramp_.check();
    }
    // the columns of z that hold h¹, h², … (the paper's z̄_s; h⁰ is data)
    Index off = 0;
    for (std::size_t s = 0; s < cfg.emb_feat_dims.size(); ++s) {
      if (s > 0 && cfg.feature_embedding) blocks_.push_back({off, cfg.emb_feat_dims[s]});
      off += cfg.emb_feat_dims[s];
    }
  }

  /// The contact term's patches (rows of the HR surface, whose normalized rest shape the
  /// constructor took): ArgumentError unless the config's w_contact > 0 (patches without a weight
  /// would be silently ignored).
  template <class DR>
  void set_contact(const Eigen::MatrixBase<DR>& hr_rest_normalized, const ContactPatches& patches) {
    if (!(cfg_.w_contact > 0)) throw ArgumentError("nn::SuperResolutionLoss: contact patches given but the config's w_contact is 0");
    if (hr_rest_normalized.rows() != fn_.vertices())
      throw ShapeError("nn::SuperResolutionLoss::set_contact: HR rest shape", {fn_.vertices(), 3}, {hr_rest_normalized.rows(), hr_rest_normalized.cols()});
    const double unit = cfg_.displacement_unit();  // distances in network units: normalized positions × displacement_scale
    contact_.emplace(hr_rest_normalized.template cast<double>() * cfg_.displacement_scale, patches, cfg_.contact_radius / unit,
                     cfg_.contact_margin / unit);
  }
  bool has_contact() const { return contact_.has_value(); }
  const ContactLoss<S>* contact() const { return contact_ ? &*contact_ : nullptr; }

  /// The batch split of data-parallel training (nullptr: none): pred, target and z then hold this
  /// rank's items of the global batch; every term is taken item by item with the global batch's
  /// normalization, and the items' values are added in global item order, so the terms are the
  /// whole batch's on every rank (the gradients are this rank's rows of the whole batch's).
  void set_batch_split(BatchSplit* split) { split_ = split; }

  /// Loss of `pred` ((B·M)×3) against `target` with code z ((B·N)×latent) at optimizer step
  /// `step`; with d_pred / d_z, writes the gradients of the total (overwritten).
  template <exec::HostPolicy Policy>
  Terms evaluate(Policy policy, const ConstView<S>& pred, const ConstView<S>& target, const ConstView<S>& z, long step, Matrix<S>* d_pred,
                 Matrix<S>* d_z) {
    detail::check_shape("nn::SuperResolutionLoss", "target", target, pred.rows(), 3);
    const Index M = fn_.vertices();
    if (pred.rows() == 0 || pred.rows() % M)
      throw ShapeError("nn::SuperResolutionLoss: prediction (B·" + std::to_string(M) + " rows)", {-1, 3}, {pred.rows(), pred.cols()});
    if (split_) return evaluate_split(policy, pred, target, z, step, d_pred, d_z);
    const double B = double(pred.rows() / M);
    const Index N_rows = z.rows();
    Terms t;
    // reconstruction (Eq. 4): official mean/B; paper sum per item averaged over items
    double recon_scale = cfg_.w_recon;
    if (cfg_.recon_divide_by_batch) recon_scale /= B;
    if (cfg_.sum_reductions) recon_scale *= double(pred.size()) / B;
    t.recon = recon_scale * double(l1_loss(policy, pred, target, d_pred, recon_scale));
    // face normals (Eq. 5)
    const double fn_scale = cfg_.sum_reductions ? cfg_.w_fn / B : cfg_.w_fn;
    if (cfg_.w_fn > 0) {
      t.face_normals = fn_scale * fn_.value_and_gradient(policy, pred, target, d_pred ? &d_fn_ : nullptr, fn_scale);
      if (d_pred) *d_pred += d_fn_;
    }
    // latent regularizer (Eq. 6 or the official mean|z|)
    if (d_z) {
      ensure_shape(*d_z, N_rows, z.cols());
      d_z->setZero();
    }
    switch (cfg_.zreg) {
      case LatentRegularizer::mean_abs:
        t.beta = cfg_.w_zreg;
        t.z_reg = t.beta * double(mean_abs(policy, z, d_z, t.beta));
        break;
      case LatentRegularizer::mean_square:
        t.beta = cfg_.w_zreg;
        t.z_reg = t.beta * double(mean_square(policy, z, d_z, t.beta));
        break;
      case LatentRegularizer::ramped_norm: {
        t.beta = ramp_.at(step);
        const double scale = t.beta / B;
        for (const auto& [off, width] : blocks_) {
          const auto block = z.middleCols(off, width);
          t.z_reg += scale * row_norm_sum(policy, block, d_z ? &d_block_ : nullptr, scale);
          if (d_z) d_z->middleCols(off, width) = d_block_;
        }
        break;
      }
    }
    if (cfg_.w_contact > 0) {
      if (!contact_) throw ArgumentError("nn::SuperResolutionLoss: w_contact > 0 but no contact patches (set_contact)");
      t.contact = cfg_.w_contact * contact_->value_and_gradient(policy, pred, d_pred, cfg_.w_contact);
      t.penetrating = contact_->penetrating();
    }
    t.total = t.recon + t.z_reg + t.face_normals + t.contact;
    return t;
  }

 private:
  /// evaluate under a batch split: each local item alone (B = 1 inside each term) with the terms'
  /// weights scaled as the global batch of B items gives them; the per-item values gathered and
  /// added in global item order.
  template <class Policy>
  Terms evaluate_split(Policy policy, const ConstView<S>& pred, const ConstView<S>& target, const ConstView<S>& z, long step, Matrix<S>* d_pred,
                       Matrix<S>* d_z) {
    const Index M = fn_.vertices(), L = split_->count();
    split_->rows_per_item(pred.rows(), "nn::SuperResolutionLoss: prediction");
    const Index N = split_->rows_per_item(z.rows(), "nn::SuperResolutionLoss: code");
    const double B = double(split_->items());
    if (d_pred) ensure_shape(*d_pred, pred.rows(), 3);
    if (d_z) {
      ensure_shape(*d_z, z.rows(), z.cols());
      d_z->setZero();
    }
    // per item: recon, face normals, z_reg, contact (each already weighted), penetrating pairs
    constexpr Index width = 5;
    item_terms_.assign(std::size_t(L * width), 0.0);
    double recon_scale = cfg_.w_recon;
    if (cfg_.recon_divide_by_batch) recon_scale /= B;
    if (cfg_.sum_reductions) recon_scale *= double(M * 3);
    const double fn_scale = cfg_.w_fn / B;  // sum: w_fn/B · Σ items; mean: w_fn · (1/B) Σ item means
    double beta = 0;
    for (Index item = 0; item < L; ++item) {
      double* v = item_terms_.data() + item * width;
      const ConstView<S> p = pred.middleRows(item * M, M), y = target.middleRows(item * M, M), zi = z.middleRows(item * N, N);
      // reconstruction: the batch mean of the item means (mean over all entries), its gradient /B
      v[0] = recon_scale / B * double(l1_loss(policy, p, y, d_pred ? &d_item_ : nullptr, recon_scale / B));
      if (d_pred) d_pred->middleRows(item * M, M) = d_item_;
      if (cfg_.w_fn > 0) {
        v[1] = fn_scale * fn_.value_and_gradient(policy, p, y, d_pred ? &d_fn_ : nullptr, fn_scale);
        if (d_pred) d_pred->middleRows(item * M, M) += d_fn_;
      }
      switch (cfg_.zreg) {
        case LatentRegularizer::mean_abs:
        case LatentRegularizer::mean_square: {
          beta = cfg_.w_zreg;
          const double s = beta / B;
          const bool abs = cfg_.zreg == LatentRegularizer::mean_abs;
          v[2] = s * double(abs ? mean_abs(policy, zi, d_z ? &d_item_ : nullptr, s) : mean_square(policy, zi, d_z ? &d_item_ : nullptr, s));
          if (d_z) d_z->middleRows(item * N, N) = d_item_;
          break;
        }
        case LatentRegularizer::ramped_norm: {
          beta = ramp_.at(step);
          const double scale = beta / B;
          for (const auto& [off, width_s] : blocks_) {
            const auto block = zi.middleCols(off, width_s);
            v[2] += scale * row_norm_sum(policy, block, d_z ? &d_block_ : nullptr, scale);
            if (d_z) d_z->middleRows(item * N, N).middleCols(off, width_s) = d_block_;
          }
          break;
        }
      }
      if (cfg_.w_contact > 0) {
        if (!contact_) throw ArgumentError("nn::SuperResolutionLoss: w_contact > 0 but no contact patches (set_contact)");
        if (d_pred) d_item_ = d_pred->middleRows(item * M, M);
        v[3] = cfg_.w_contact / B * contact_->value_and_gradient(policy, p, d_pred ? &d_item_ : nullptr, cfg_.w_contact / B);
        if (d_pred) d_pred->middleRows(item * M, M) = d_item_;
        v[4] = double(contact_->penetrating());
      }
    }
    double sums[width] = {0, 0, 0, 0, 0};
    split_->sum_items(item_terms_.data(), width, sums);
    Terms t;
    t.recon = sums[0], t.face_normals = sums[1], t.z_reg = sums[2], t.contact = sums[3];
    t.penetrating = Index(sums[4]);
    t.beta = beta;
    t.total = t.recon + t.z_reg + t.face_normals + t.contact;
    return t;
  }

  NetworkConfig cfg_;
  BatchSplit* split_ = nullptr;
  std::vector<double> item_terms_;
  Matrix<S> d_item_;
  FaceNormalLoss<S> fn_;
  RampedWeight ramp_;
  std::vector<std::pair<Index, Index>> blocks_;
  std::optional<ContactLoss<S>> contact_;
  Matrix<S> d_fn_, d_block_;
};

}  // namespace simsr::nn
