#pragma once
/// \file
/// The β-VAE baseline of the paper (appendix A.4, SPEC §7): flattened LR displacements in,
/// flattened HR displacements out, through a sampled latent code, trained with L2 reconstruction
/// + β·KL (β = 0.01).
///
///     nn::ParameterStore<float> store;
///     nn::BetaVae<float> vae(store, n_lr, n_hr, rng);           // paper sizes (Config{})
///     nn::Adam<float> opt(store, {.lr = 1e-4});                  // A.4's learning rate
///     store.zero_grad();
///     auto l = vae.loss_and_backward(exec::omp, lr, hr, noise);  // lr: B×3N, hr: B×3M
///     opt.step(exec::omp);
///     vae.predict(exec::omp, lr, hr_pred);                       // eval: z = μ
///
/// Rows are batch items; each row is one frame's displacements flattened vertex-major
/// (x₀ y₀ z₀ x₁ …), i.e. a DisplacementMatrix (N×3, row-major) viewed as one row of 3N.
///
/// The module, as PyTorch would write it (the state-dict names below are this module's):
///
///     class BetaVAE(nn.Module):
///         def __init__(self, n_in, n_out, slope=0.2):
///             super().__init__()
///             self.encoder = nn.Sequential(nn.Linear(n_in, 1024), nn.LeakyReLU(slope),
///                                          nn.Linear(1024, 512), nn.LeakyReLU(slope))
///             self.mu_logvar = nn.Linear(512, 2 * 128)
///             self.decoder = nn.Sequential(nn.Linear(128, 256), nn.LeakyReLU(slope),
///                                          nn.Linear(256, 1024), nn.LeakyReLU(slope),
///                                          nn.Linear(1024, 4096), nn.LeakyReLU(slope),
///                                          nn.Linear(4096, n_out))
///         def forward(self, x):
///             mu, logvar = self.mu_logvar(self.encoder(x)).chunk(2, dim=1)
///             z = mu + torch.exp(0.5 * logvar) * torch.randn_like(mu) if self.training else mu
///             return self.decoder(z), mu, logvar
///
/// so the parameters are `encoder.{0,2}.{weight,bias}`, `mu_logvar.{weight,bias}` and
/// `decoder.{0,2,4,6}.{weight,bias}` (Sequential indices count the LeakyReLUs, which hold no
/// parameters; with other hidden sizes in Config the indices are 0, 2, 4, … likewise).
/// Why one 512→256 head split into halves rather than two 512→128 heads: A.4 describes "the
/// output of the encoder is composed of 256 neurons (128 for the mean and 128 for the variance)",
/// one layer. The "variance" half is read as log σ² (the usual parameterization: any real output
/// is a valid variance, and the KL term is closed-form in it).

#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "activations.hpp"
#include "layer.hpp"
#include "linear.hpp"
#include "losses.hpp"
#include "parameters.hpp"

namespace simsr::nn {

/// Fills data[0..n) with standard normal draws: the Box–Muller transform of pairs of
/// `uniform(rng, 0, 1)` draws (u₁ taken as 1 − u ∈ (0, 1] so its log is finite), both outputs
/// used (the cosine one first), an odd last entry dropping the sine one. Why not
/// std::normal_distribution: its algorithm is implementation-defined (standard libraries give
/// different numbers for one seed); this uses only nn::uniform and libm's log/sqrt/cos/sin, so a
/// seed gives the same noise wherever libm agrees (to the last bit on one platform).
template <class S>
void fill_standard_normal(Rng& rng, S* data, Index n) {
  for (Index i = 0; i < n; i += 2) {
    const double u1 = 1.0 - uniform(rng, 0, 1), u2 = uniform(rng, 0, 1);
    const double r = std::sqrt(-2.0 * std::log(u1)), theta = 2.0 * std::numbers::pi * u2;
    data[i] = static_cast<S>(r * std::cos(theta));
    if (i + 1 < n) data[i + 1] = static_cast<S>(r * std::sin(theta));
  }
}

/// β-VAE of appendix A.4: (B×3·n_lr) LR displacements → (B×3·n_hr) HR displacements.
///
/// Train mode (loss, loss_and_backward with an Rng): z = μ + exp(½·logvar)⊙ε, ε ~ N(0, 1) drawn
/// serially, row-major, B·latent values per forward from the caller's Rng (fill_standard_normal),
/// so a seed gives the same noise under exec::seq and exec::omp and every result is bitwise
/// identical between them. Eval mode (predict): z = μ, no draw.
///
/// Loss = recon + β·KL with
///   recon = mean over all B·3M entries of (ŷ − y)²  (PyTorch's F.mse_loss, reduction "mean");
///   KL    = (1/B)·Σ_b −½·Σ_j (1 + logvar − μ² − exp(logvar))  (per item summed over the latent,
///           averaged over the batch).
/// Why the mean over entries for "L2-norm": it is what nn.MSELoss gives by default and keeps the
/// loss scale independent of the mesh size; with a per-item sum instead, β = 0.01 would weigh the
/// KL term 3M times less. The choice changes the balance, not the architecture: to train as with
/// the per-item sum (the same minimizer; Adam ignores the overall scale), set Config::beta to β/(3M).
///
/// A model object owns its activations and gradient workspaces (reused call after call, nothing
/// allocated once the batch size is warm); its parameters live in the ParameterStore given at
/// construction, which must outlive it. Not thread-safe: one call at a time per object.
template <class S = float>
class BetaVae {
 public:
  using scalar_type = S;

  /// Sizes and weights; the defaults are A.4's. Every size is one change here.
  struct Config {
    std::vector<Index> encoder_hidden{1024, 512};       ///< widths of the encoder's LeakyReLU layers
    Index latent = 128;                                 ///< dim of z (the head outputs 2·latent)
    std::vector<Index> decoder_hidden{256, 1024, 4096}; ///< widths of the decoder's LeakyReLU layers
    double beta = 0.01;                                 ///< KL weight (A.4: 0.01)
    double slope = 0.2;                                 ///< LeakyReLU negative slope
  };

  /// The loss of one batch and its parts: total = recon + β·kl.
  struct Loss {
    double total = 0;
    double recon = 0;
    double kl = 0;
  };

  /// Registers the parameters in `store` in PyTorch's order (encoder.0, encoder.2, …, mu_logvar,
  /// decoder.0, …) and draws PyTorch's default nn.Linear initialization, U(±1/√fan_in) for weight
  /// then bias, from `rng` in that order. n_lr / n_hr are vertex counts (N, M): the input has
  /// 3·n_lr columns, the output 3·n_hr. ArgumentError for a size < 1, β < 0 or a non-finite slope.
  BetaVae(ParameterStore<S>& store, Index n_lr, Index n_hr, Rng& rng, Config config = {})
      : n_lr_(n_lr), n_hr_(n_hr), cfg_(std::move(config)), act_(static_cast<S>(cfg_.slope)) {
    validate(n_lr_, n_hr_, cfg_);
    const Index ne = Index(cfg_.encoder_hidden.size()), nd = Index(cfg_.decoder_hidden.size());
    encoder_.reserve(std::size_t(ne));
    decoder_.reserve(std::size_t(nd + 1));
    Index width = 3 * n_lr_;
    for (Index i = 0; i < ne; ++i) {
      encoder_.emplace_back(store, "encoder." + std::to_string(2 * i), width, cfg_.encoder_hidden[std::size_t(i)], rng);
      width = cfg_.encoder_hidden[std::size_t(i)];
    }
    head_.emplace(store, "mu_logvar", width, 2 * cfg_.latent, rng);
    width = cfg_.latent;
    for (Index i = 0; i <= nd; ++i) {
      const Index out = i < nd ? cfg_.decoder_hidden[std::size_t(i)] : 3 * n_hr_;
      decoder_.emplace_back(store, "decoder." + std::to_string(2 * i), width, out, rng);
      width = out;
    }
    enc_pre_.resize(std::size_t(ne)), enc_act_.resize(std::size_t(ne)), enc_dpre_.resize(std::size_t(ne)), enc_dact_.resize(std::size_t(ne));
    dec_pre_.resize(std::size_t(nd)), dec_act_.resize(std::size_t(nd)), dec_dpre_.resize(std::size_t(nd)), dec_dact_.resize(std::size_t(nd));
  }

  /// Trainable values of a model with these sizes: Σ over its Linear layers of in·out + out.
  static Index parameter_count(Index n_lr, Index n_hr, const Config& config) {
    validate(n_lr, n_hr, config);
    Index total = 0, width = 3 * n_lr;
    auto add = [&](Index out) {
      total += width * out + out;
      width = out;
    };
    for (Index h : config.encoder_hidden) add(h);
    add(2 * config.latent);
    width = config.latent;
    for (Index h : config.decoder_hidden) add(h);
    add(3 * n_hr);
    return total;
  }
  /// This model's trainable values (its share of the store's num_parameters()).
  Index num_parameters() const { return parameter_count(n_lr_, n_hr_, cfg_); }

  const Config& config() const { return cfg_; }
  Index n_lr() const { return n_lr_; }
  Index n_hr() const { return n_hr_; }
  Index in_features() const { return 3 * n_lr_; }
  Index out_features(Index = -1) const { return 3 * n_hr_; }
  Index latent() const { return cfg_.latent; }

  /// The layers, for loading weights or inspection: encoder(i) is `encoder.<2i>`, decoder(i)
  /// `decoder.<2i>` (decoder(num_decoder_layers() − 1) is the linear output layer).
  Index num_encoder_layers() const { return Index(encoder_.size()); }
  Index num_decoder_layers() const { return Index(decoder_.size()); }
  Linear<S>& encoder(Index i) { return encoder_.at(std::size_t(i)); }
  Linear<S>& head() { return *head_; }
  Linear<S>& decoder(Index i) { return decoder_.at(std::size_t(i)); }

  /// Of the last forward (predict, loss, loss_and_backward): μ and log σ² (B×latent column
  /// blocks of the head's output), ε (train mode only; stale after predict) and z.
  auto mu() const { return head_out_.leftCols(cfg_.latent); }
  auto logvar() const { return head_out_.rightCols(cfg_.latent); }
  const Matrix<S>& epsilon() const { return eps_; }
  const Matrix<S>& z() const { return z_; }

  /// Eval mode: out (B×3M) = decoder(μ(lr)). Deterministic, draws nothing. ShapeError unless lr
  /// is B×3N.
  template <exec::HostPolicy Policy>
  void predict(Policy policy, const ConstView<S>& lr, Matrix<S>& out) {
    check_input(lr);
    forward(policy, lr, nullptr, out);
  }

  /// The loss of one batch without backward: train mode (ε drawn from *rng) when rng is given,
  /// eval mode (z = μ) when it is null (e.g. a validation loss). ShapeError unless lr is B×3N and
  /// hr B×3M; ArgumentError for an empty batch.
  template <exec::HostPolicy Policy>
  Loss loss(Policy policy, const ConstView<S>& lr, const ConstView<S>& hr, Rng* rng) {
    check_batch(lr, hr);
    forward(policy, lr, rng, out_);
    return compute_loss(policy, hr, false);
  }

  /// One training pass: forward in train mode (ε from `rng`), the loss, and backward, which ADDS
  /// ∂loss/∂θ into the store's gradients (the caller zero_grads before and steps the optimizer
  /// after). With `d_lr`, also writes ∂loss/∂lr (B×3N). Errors as loss().
  template <exec::HostPolicy Policy>
  Loss loss_and_backward(Policy policy, const ConstView<S>& lr, const ConstView<S>& hr, Rng& rng, Matrix<S>* d_lr = nullptr) {
    check_batch(lr, hr);
    forward(policy, lr, &rng, out_);
    const Loss l = compute_loss(policy, hr, true);
    backward(policy, lr, d_lr);
    return l;
  }

 private:
  static void validate(Index n_lr, Index n_hr, const Config& c) {
    auto bad = [](const std::string& what) { throw ArgumentError("nn::BetaVae: " + what); };
    if (n_lr < 1 || n_hr < 1) bad("the LR and HR vertex counts must be >= 1");
    if (c.latent < 1) bad("the latent size must be >= 1");
    for (Index h : c.encoder_hidden)
      if (h < 1) bad("encoder hidden widths must be >= 1");
    for (Index h : c.decoder_hidden)
      if (h < 1) bad("decoder hidden widths must be >= 1");
    if (!(c.beta >= 0) || !std::isfinite(c.beta)) bad("beta must be finite and >= 0");
    if (!std::isfinite(c.slope)) bad("the LeakyReLU slope must be finite");
  }
  void check_input(const ConstView<S>& lr) const { detail::check_shape("nn::BetaVae", "LR input", lr, -1, 3 * n_lr_); }
  void check_batch(const ConstView<S>& lr, const ConstView<S>& hr) const {
    check_input(lr);
    detail::check_shape("nn::BetaVae", "HR target", hr, lr.rows(), 3 * n_hr_);
    if (lr.rows() == 0) throw ArgumentError("nn::BetaVae: the loss needs a batch of at least one item");
  }

  /// Encoder, head, z (sampled with rng, else μ), decoder into `out`.
  template <class Policy>
  void forward(Policy policy, const ConstView<S>& lr, Rng* rng, Matrix<S>& out) {
    const Index ne = num_encoder_layers(), nd = num_decoder_layers() - 1, L = cfg_.latent, B = lr.rows();
    const Mode mode = rng ? Mode::train : Mode::eval;
    for (Index i = 0; i < ne; ++i) {
      auto& pre = enc_pre_[std::size_t(i)];
      if (i == 0)
        encoder_[0].forward(policy, mode, lr, pre);
      else
        encoder_[std::size_t(i)].forward(policy, mode, enc_act_[std::size_t(i - 1)], pre);
      act_.forward(policy, mode, pre, enc_act_[std::size_t(i)]);
    }
    if (ne == 0)
      head_->forward(policy, mode, lr, head_out_);
    else
      head_->forward(policy, mode, enc_act_.back(), head_out_);
    ensure_shape(z_, B, L);
    sampled_ = rng != nullptr;
    if (sampled_) {
      // Serial draw (the noise must not depend on the policy); B·latent is small.
      ensure_shape(eps_, B, L);
      ensure_shape(sigma_, B, L);
      fill_standard_normal(*rng, eps_.data(), eps_.size());
      for (Index b = 0; b < B; ++b)
        for (Index j = 0; j < L; ++j) {
          sigma_(b, j) = static_cast<S>(std::exp(0.5 * double(head_out_(b, L + j))));
          z_(b, j) = head_out_(b, j) + sigma_(b, j) * eps_(b, j);
        }
    } else {
      z_ = head_out_.leftCols(L);
    }
    for (Index i = 0; i < nd; ++i) {
      auto& pre = dec_pre_[std::size_t(i)];
      decoder_[std::size_t(i)].forward(policy, mode, i == 0 ? z_ : dec_act_[std::size_t(i - 1)], pre);
      act_.forward(policy, mode, pre, dec_act_[std::size_t(i)]);
    }
    decoder_.back().forward(policy, mode, nd == 0 ? z_ : dec_act_.back(), out);
  }

  /// recon (chunked, double sums: policy-independent) and KL (serial, double); with `grad`, the
  /// output gradient d_out_ = ∂recon/∂ŷ and the head gradient's KL part.
  template <class Policy>
  Loss compute_loss(Policy policy, const ConstView<S>& hr, bool grad) {
    const Index B = out_.rows(), C = out_.cols(), L = cfg_.latent;
    Loss l;
    l.recon = detail::mean_and_gradient<Policy, S>(
        policy, B, C, grad ? &d_out_ : nullptr, 1.0,
        [&](Index r, Index c) {
          const double e = double(out_(r, c)) - double(hr(r, c));
          return e * e;
        },
        [&](Index r, Index c) { return S(2) * (out_(r, c) - hr(r, c)); });
    if (grad) ensure_shape(d_head_, B, 2 * L);
    const double beta = cfg_.beta, inv_b = 1.0 / double(B);
    double kl = 0;
    for (Index b = 0; b < B; ++b)
      for (Index j = 0; j < L; ++j) {
        const double mu = head_out_(b, j), lv = head_out_(b, L + j), ev = std::exp(lv);
        kl += -0.5 * (1.0 + lv - mu * mu - ev);
        if (grad) {
          d_head_(b, j) = static_cast<S>(beta * inv_b * mu);
          d_head_(b, L + j) = static_cast<S>(beta * inv_b * 0.5 * (ev - 1.0));
        }
      }
    l.kl = kl * inv_b;
    l.total = l.recon + beta * l.kl;
    return l;
  }

  /// Decoder back to d_z, through the reparameterization into d_head_ (which holds the KL part),
  /// then head and encoder (d_lr when asked).
  template <class Policy>
  void backward(Policy policy, const ConstView<S>& lr, Matrix<S>* d_lr) {
    const Index ne = num_encoder_layers(), nd = num_decoder_layers() - 1, B = lr.rows(), L = cfg_.latent;
    decoder_.back().backward(policy, nd == 0 ? z_ : dec_act_.back(), out_, d_out_, nd == 0 ? &d_z_ : &dec_dact_.back());
    for (Index i = nd - 1; i >= 0; --i) {
      const auto k = std::size_t(i);
      act_.backward(policy, dec_pre_[k], dec_act_[k], dec_dact_[k], &dec_dpre_[k]);
      decoder_[k].backward(policy, i == 0 ? z_ : dec_act_[k - 1], dec_pre_[k], dec_dpre_[k], i == 0 ? &d_z_ : &dec_dact_[k - 1]);
    }
    // z = μ + σ⊙ε, σ = exp(½·logvar): ∂z/∂μ = 1, ∂z/∂logvar = ½·σ⊙ε (eval: z = μ).
    for (Index b = 0; b < B; ++b)
      for (Index j = 0; j < L; ++j) {
        d_head_(b, j) += d_z_(b, j);
        if (sampled_) d_head_(b, L + j) += d_z_(b, j) * S(0.5) * sigma_(b, j) * eps_(b, j);
      }
    Matrix<S>* d_head_in = ne == 0 ? d_lr : &enc_dact_.back();
    if (ne == 0)
      head_->backward(policy, lr, head_out_, d_head_, d_head_in);
    else
      head_->backward(policy, enc_act_.back(), head_out_, d_head_, d_head_in);
    for (Index i = ne - 1; i >= 0; --i) {
      const auto k = std::size_t(i);
      act_.backward(policy, enc_pre_[k], enc_act_[k], enc_dact_[k], &enc_dpre_[k]);
      if (i == 0)
        encoder_[0].backward(policy, lr, enc_pre_[0], enc_dpre_[0], d_lr);
      else
        encoder_[k].backward(policy, enc_act_[k - 1], enc_pre_[k], enc_dpre_[k], &enc_dact_[k - 1]);
    }
  }

  Index n_lr_, n_hr_;
  Config cfg_;
  LeakyReLU<S> act_;  // stateless: one object serves every activation
  std::vector<Linear<S>> encoder_, decoder_;
  std::optional<Linear<S>> head_;  // optional: built after the encoder (registration order)
  // Activations of the last forward and gradient workspaces, one per place in the graph.
  std::vector<Matrix<S>> enc_pre_, enc_act_, enc_dpre_, enc_dact_, dec_pre_, dec_act_, dec_dpre_, dec_dact_;
  Matrix<S> head_out_, eps_, sigma_, z_, out_, d_out_, d_head_, d_z_;
  bool sampled_ = false;
};

}  // namespace simsr::nn
