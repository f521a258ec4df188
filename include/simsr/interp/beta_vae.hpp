#pragma once
/// \file
/// The β-VAE baseline of appendix A.4 as an interpolator: nn::BetaVae (A.4's sizes:
/// 3N→1024→512→2·128, 128→256→1024→4096→3M, β = 0.01) maps one frame's LR displacements,
/// flattened vertex-major (3N), to its HR displacements (3M). It needs no neighbourhoods and learns
/// everything from the training frames.
///
///     interp::BetaVaeBaseline<> vae;
///     vae.fit(exec::omp, problem);                                   // sizes only
///     vae.train(exec::omp, data::displacements(train, lr.V, hr.V), {.epochs = 4});
///     vae.apply(exec::omp, lr_displacement, hr_displacement);        // eval mode: z = μ
///
/// Normalization: inputs and targets are both divided by one scalar s, the RMS of every entry of
/// the training frames' LR and HR displacements pooled, and predictions multiplied back by s. Why
/// not the official σ = ½(0.04998 + 0.05092): that constant normalizes bunny *positions*; applied
/// to displacements it leaves them at ≈ 0.13 RMS on the bunny (and at an arbitrary scale on any
/// other data), and since the loss is MSE + β·KL the target scale sets how much β = 0.01 weighs: at
/// RMS 0.13 the reconstruction term starts ≈ 55 times smaller than at unit RMS, so the KL term
/// weighs ≈ 55 times more (a push towards posterior collapse). Unit-RMS data makes β = 0.01 mean
/// the same on every data set. s is a statistic of the training frames only.
///
/// Training: Adam (lr 1e-4, A.4), batches of 8 (the last of an epoch may be smaller), each epoch
/// a fresh Fisher–Yates permutation (as nn::Trainer). One nn::Rng seeded with `seed` draws, in
/// order, the initial weights (PyTorch's default init), per epoch the permutation and per step the
/// reparameterization noise; BetaVae's kernels give the same bits under every policy, so a seed
/// fixes the run. A non-finite loss or gradient stops training with a NumericalError naming the
/// step (and the tensor) before Adam moves anything.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../data/paired_frames.hpp"
#include "../nn/adam.hpp"
#include "../nn/beta_vae.hpp"
#include "../nn/finite_checks.hpp"
#include "../nn/shuffle.hpp"
#include "concepts.hpp"
#include "problem.hpp"

namespace simsr::interp {

/// One epoch of β-VAE training, as reported to `on_epoch`.
struct BetaVaeEpoch {
  Index epoch = 0;  ///< 1-based
  double loss = 0, recon = 0, kl = 0;  ///< means over the epoch's batches
  double seconds = 0;
};

/// How BetaVaeBaseline::train runs.
struct BetaVaeTrainOptions {
  Index epochs = 4;  ///< ~25–45 s each on the bunny (192 frames, 2 threads)
  Index batch_size = 8;
  double lr = 1e-4;  ///< A.4
  /// The network's widths, latent size, β and LeakyReLU slope; A.4's by default (β = 0.01). Every
  /// size is one change here (ablations; the tests train a small one).
  nn::BetaVae<float>::Config network{};
  std::uint64_t seed = 0;
  bool progress = false;  ///< one line per epoch on stderr
  std::function<void(const BetaVaeEpoch&)> on_epoch;
};

/// The A.4 β-VAE as an interp::TrainableInterpolator (S = double: displacements in mesh units;
/// the network runs in float32 as A.4's). apply is const but works in the object's buffers: one
/// call at a time per object.
template <class S = Scalar>
class BetaVaeBaseline {
 public:
  using scalar_type = S;
  using train_options = BetaVaeTrainOptions;
  static constexpr bool needs_neighborhoods = false;

  BetaVaeBaseline() = default;
  BetaVaeBaseline(const BetaVaeBaseline&) = delete;  // the model points into its own store
  BetaVaeBaseline& operator=(const BetaVaeBaseline&) = delete;
  BetaVaeBaseline(BetaVaeBaseline&&) = delete;

  /// Records the sizes N and M; the weights come with train().
  template <exec::HostPolicy Policy>
  void fit(Policy, UpsamplingProblem<S>& problem) {
    if (problem.num_lr() < 1 || problem.num_hr() < 1) throw ArgumentError("BetaVaeBaseline::fit: empty rest shapes");
    n_ = problem.num_lr();
    m_ = problem.num_hr();
    vae_.reset();
  }

  /// Trains a fresh model on F paired frames of displacements (data::displacements).
  template <exec::HostPolicy Policy>
  void train(Policy policy, const data::PairedFrames<S>& frames, const BetaVaeTrainOptions& o) {
    if (n_ == 0) throw ArgumentError("BetaVaeBaseline::train before fit");
    const Index f = frames.num_frames();
    if (f < 1) throw ArgumentError("BetaVaeBaseline::train: no training frames");
    if (frames.num_lr() != n_ || frames.num_hr() != m_)
      throw ShapeError("BetaVaeBaseline::train: frames (N, M)", {n_, m_}, {frames.num_lr(), frames.num_hr()});
    if (o.epochs < 0 || o.batch_size < 1 || !(o.lr > 0) || !(o.network.beta >= 0))
      throw ArgumentError("BetaVaeBaseline::train: epochs ≥ 0, batch_size ≥ 1, lr > 0 and beta ≥ 0 needed");
    require_finite(frames.lowres, frames.ids, "LR");
    require_finite(frames.highres, frames.ids, "HR");
    const double sq = frames.lowres.template cast<double>().squaredNorm() + frames.highres.template cast<double>().squaredNorm();
    scale_ = std::sqrt(sq / double(frames.lowres.size() + frames.highres.size()));
    if (!std::isfinite(scale_)) throw NumericalError("BetaVaeBaseline::train", "the training displacements' RMS", -1, scale_);
    if (scale_ == 0) scale_ = 1;  // no motion at all: any scale will do
    const nn::Matrix<float> X = narrow(frames.lowres, "LR training displacements");
    const nn::Matrix<float> Y = narrow(frames.highres, "HR training displacements");

    nn::Rng rng(o.seed);
    const typename nn::BetaVae<float>::Config& cfg = o.network;
    vae_.reset();
    store_ = nn::ParameterStore<float>();
    vae_.emplace(store_, n_, m_, rng, cfg);
    nn::Adam<float> adam(store_, {.lr = o.lr});
    const Index bs = std::min(o.batch_size, f), nb = (f + bs - 1) / bs;
    if (o.progress)
      std::fprintf(stderr, "simsr: beta_vae: %lld parameters, %lld training frames, batch %lld, lr %g, beta %g, scale %.6g, seed %llu\n",
                   (long long)vae_->num_parameters(), (long long)f, (long long)bs, o.lr, o.network.beta, scale_, (unsigned long long)o.seed);
    std::vector<Index> order;
    nn::Matrix<float> xb, yb;
    history_.clear();
    for (Index e = 0; e < o.epochs; ++e) {
      const auto t0 = std::chrono::steady_clock::now();
      nn::shuffled_order(rng, f, order);
      BetaVaeEpoch rep;
      rep.epoch = e + 1;
      for (Index b = 0; b < nb; ++b) {
        const Index first = b * bs, count = std::min(bs, f - first);
        nn::ensure_shape(xb, count, X.cols());
        nn::ensure_shape(yb, count, Y.cols());
        for (Index i = 0; i < count; ++i) {
          xb.row(i) = X.row(order[std::size_t(first + i)]);
          yb.row(i) = Y.row(order[std::size_t(first + i)]);
        }
        store_.zero_grad();
        const auto l = vae_->loss_and_backward(policy, xb, yb, rng);
        const std::int64_t step = adam.steps() + 1;
        nn::require_finite_loss("β-VAE training", l.total, step);
        nn::require_finite_gradients("β-VAE training", store_, step);
        adam.step(policy);
        nn::require_finite_parameters("β-VAE training", store_, step);
        rep.loss += l.total / double(nb), rep.recon += l.recon / double(nb), rep.kl += l.kl / double(nb);
      }
      rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (o.progress)
        std::fprintf(stderr, "simsr: beta_vae epoch %lld/%lld  loss %.6f (recon %.6f  kl %.4f)  %.2f s\n", (long long)rep.epoch,
                     (long long)o.epochs, rep.loss, rep.recon, rep.kl, rep.seconds);
      history_.push_back(rep);
      if (o.on_epoch) o.on_epoch(rep);
    }
  }

  /// Eval mode (z = μ): hr (M×3) = s · decoder(μ(lr / s)). ShapeError for other sizes,
  /// ArgumentError for a non-finite input or one beyond float's range, NumericalError for a
  /// non-finite prediction.
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstPointsRef<S>& lr_displacement, PointsRef<S> hr_displacement) const {
    if (!vae_) throw ArgumentError("BetaVaeBaseline::apply before train");
    if (lr_displacement.rows() != n_) throw ShapeError("BetaVaeBaseline::apply: LR displacement", {n_, 3}, {lr_displacement.rows(), 3});
    if (hr_displacement.rows() != m_) throw ShapeError("BetaVaeBaseline::apply: HR displacement", {m_, 3}, {hr_displacement.rows(), 3});
    nn::ensure_shape(in_, 1, 3 * n_);
    for (Index i = 0; i < 3 * n_; ++i) in_(0, i) = narrow_one(lr_displacement.data()[i] / scale_, "LR displacement", i / 3);
    vae_->predict(policy, in_, out_);
    for (Index i = 0; i < 3 * m_; ++i) {
      const double v = double(out_(0, i)) * scale_;
      if (!std::isfinite(v)) throw NumericalError("BetaVaeBaseline::apply", "HR vertex " + std::to_string(i / 3), -1, v);
      hr_displacement.data()[i] = S(v);
    }
  }

  Index num_lr() const { return n_; }
  Index num_hr() const { return m_; }
  /// s, the training frames' displacement RMS (1 before train).
  double scale() const { return scale_; }
  /// The trained model's parameter count (0 before train).
  Index num_parameters() const { return vae_ ? vae_->num_parameters() : 0; }
  const std::vector<BetaVaeEpoch>& history() const { return history_; }

 private:
  static void require_finite(const data::FrameMatrix<S>& m, const std::vector<std::int64_t>& ids, const char* which) {
    for (Index r = 0; r < m.rows(); ++r)
      for (Index c = 0; c < m.cols(); ++c)
        if (!std::isfinite(double(m(r, c))))
          throw ArgumentError(std::string("BetaVaeBaseline::train: ") + which + " displacement of frame " + std::to_string(ids[std::size_t(r)]) +
                              ", vertex " + std::to_string(c / 3) + " is not finite");
  }
  float narrow_one(double v, const char* what, Index vertex) const {
    if (!std::isfinite(v) || std::abs(v) > double(std::numeric_limits<float>::max()))
      throw ArgumentError(std::string("BetaVaeBaseline: ") + what + " of vertex " + std::to_string(vertex) + " is " + std::to_string(v * scale_) +
                          (std::isfinite(v) ? ", beyond float32's range after normalization" : ", not finite"));
    return float(v);
  }
  nn::Matrix<float> narrow(const data::FrameMatrix<S>& m, const char* what) const {
    nn::Matrix<float> out(m.rows(), m.cols());
    for (Index r = 0; r < m.rows(); ++r)
      for (Index c = 0; c < m.cols(); ++c) out(r, c) = narrow_one(double(m(r, c)) / scale_, what, c / 3);
    return out;
  }

  Index n_ = 0, m_ = 0;
  double scale_ = 1;
  nn::ParameterStore<float> store_;  // before vae_: it must outlive the model
  mutable std::optional<nn::BetaVae<float>> vae_;
  mutable nn::Matrix<float> in_, out_;
  std::vector<BetaVaeEpoch> history_;
};

static_assert(assert_trainable_interpolator<BetaVaeBaseline<double>>());

}  // namespace simsr::interp
