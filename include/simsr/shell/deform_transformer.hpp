#pragma once
/// \file
/// The DeformTransformer of Chen et al. 2023 (supplement §3): a sequence-to-sequence Transformer
/// from the coarse latents of a window of frames to the fine latents of the same frames.
///
///     coarse z_c (B·T)×16 ─ Linear → d, + positions ─ 2 encoder blocks ──────────── memory
///     fine inputs (B·T)×16 ─ Linear → d, + positions ─ 2 decoder blocks (causal, memory) ─ Linear → 16
///
/// T = 3 frames (the supplement's choice: attention over whole sequences "causes memory
/// explosion"), 8 heads. The fine inputs are the fine latents shifted by one frame (frame t−1 at
/// position t; the first position gets the rest shape's latent), so position t predicts frame t
/// from the coarse window and the fine frames before it: teacher forcing in training, the model's
/// own previous outputs at inference. d_model and the feed-forward width are not printed: 64 and
/// 128 here (d_model must be divisible by the 8 heads; a 16-d token is too narrow for 8 heads).
/// Positions: the fixed sinusoidal encoding of Vaswani et al. 2017.

#include <cmath>
#include <string>
#include <vector>

#include "../nn/linear.hpp"
#include "../nn/transformer_block.hpp"

namespace simsr::shell {

struct DeformTransformerOptions {
  Index latent = 16;
  Index d_model = 64;
  Index feed_forward = 128;
  Index heads = 8;
  Index blocks = 2;  ///< encoder blocks, and as many decoder blocks
  Index frames = 3;  ///< T, the window
};

template <class S = float>
class DeformTransformer {
 public:
  using scalar_type = S;

  DeformTransformer(nn::ParameterStore<S>& store, const std::string& name, DeformTransformerOptions options, nn::Rng& rng)
      : opt_(options),
        enc_embed_(store, name + ".encoder.embed", options.latent, options.d_model, rng),
        dec_embed_(store, name + ".decoder.embed", options.latent, options.d_model, rng),
        head_(store, name + ".head", options.d_model, options.latent, rng) {
    if (options.blocks < 1 || options.frames < 1 || options.latent < 1)
      throw ArgumentError("shell::DeformTransformer: blocks, frames and latent must be >= 1");
    for (Index b = 0; b < options.blocks; ++b)
      enc_.emplace_back(store, name + ".encoder." + std::to_string(b), options.d_model, options.feed_forward, options.frames, rng,
                        options.heads);
    for (Index b = 0; b < options.blocks; ++b)
      dec_.emplace_back(store, name + ".decoder." + std::to_string(b), options.d_model, options.feed_forward, options.frames,
                        options.frames, rng, options.heads);
    positions_.resize(options.frames, options.d_model);
    for (Index t = 0; t < options.frames; ++t)
      for (Index k = 0; k < options.d_model; ++k) {
        const double angle = double(t) / std::pow(10000.0, double(2 * (k / 2)) / double(options.d_model));
        positions_(t, k) = S(k % 2 == 0 ? std::sin(angle) : std::cos(angle));
      }
  }

  const DeformTransformerOptions& options() const { return opt_; }

  /// coarse (B·T)×latent and fine_in (B·T)×latent → fine latents (B·T)×latent.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, nn::Mode mode, const nn::ConstView<S>& coarse, const nn::ConstView<S>& fine_in, nn::Matrix<S>& out) {
    const Index T = opt_.frames;
    if (coarse.rows() % T != 0 || coarse.rows() != fine_in.rows() || coarse.cols() != opt_.latent || fine_in.cols() != opt_.latent)
      throw ShapeError("shell::DeformTransformer: coarse and fine latents (B·T rows, T = " + std::to_string(T) + ")",
                       {coarse.rows(), opt_.latent}, {fine_in.rows(), fine_in.cols()});
    embed(policy, mode, enc_embed_, coarse, enc_x_[0]);
    enc_x_.resize(enc_.size() + 1);
    for (std::size_t b = 0; b < enc_.size(); ++b) enc_[b].forward(policy, mode, enc_x_[b], enc_x_[b + 1]);
    dec_x_.resize(dec_.size() + 1);
    embed(policy, mode, dec_embed_, fine_in, dec_x_[0]);
    for (std::size_t b = 0; b < dec_.size(); ++b) dec_[b].forward(policy, mode, dec_x_[b], enc_x_.back(), dec_x_[b + 1]);
    head_.forward(policy, mode, dec_x_.back(), out);
  }

  /// Parameter gradients added; d_coarse and d_fine_in (either may be null) written.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const nn::ConstView<S>& coarse, const nn::ConstView<S>& fine_in, const nn::ConstView<S>& out,
                const nn::ConstView<S>& d_out, nn::Matrix<S>* d_coarse, nn::Matrix<S>* d_fine_in) {
    head_.backward(policy, dec_x_.back(), out, d_out, &d_dec_);
    d_memory_.setZero(enc_x_.back().rows(), enc_x_.back().cols());
    for (std::size_t b = dec_.size(); b-- > 0;) {
      dec_[b].backward(policy, dec_x_[b], enc_x_.back(), dec_x_[b + 1], d_dec_, &d_tmp_, &d_memory_);
      std::swap(d_dec_, d_tmp_);
    }
    dec_embed_.backward(policy, fine_in, dec_x_[0], d_dec_, d_fine_in);
    for (std::size_t b = enc_.size(); b-- > 0;) {
      enc_[b].backward(policy, enc_x_[b], enc_x_[b + 1], d_memory_, &d_tmp_);
      std::swap(d_memory_, d_tmp_);
    }
    enc_embed_.backward(policy, coarse, enc_x_[0], d_memory_, d_coarse);
  }

 private:
  template <exec::HostPolicy Policy>
  void embed(Policy policy, nn::Mode mode, nn::Linear<S>& lin, const nn::ConstView<S>& in, nn::Matrix<S>& out) {
    lin.forward(policy, mode, in, out);
    for (Index r = 0; r < out.rows(); ++r) out.row(r) += positions_.row(r % opt_.frames);
  }

  DeformTransformerOptions opt_;
  nn::Linear<S> enc_embed_, dec_embed_, head_;
  std::vector<nn::TransformerEncoderBlock<S>> enc_;
  std::vector<nn::TransformerDecoderBlock<S>> dec_;
  nn::Matrix<S> positions_;
  std::vector<nn::Matrix<S>> enc_x_{1}, dec_x_{1};
  nn::Matrix<S> d_dec_, d_tmp_, d_memory_;
};

}  // namespace simsr::shell
