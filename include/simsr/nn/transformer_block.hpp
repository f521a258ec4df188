#pragma once
/// \file
/// Transformer encoder and decoder blocks (Vaswani et al. 2017, post-norm as PyTorch's
/// nn.TransformerEncoderLayer / DecoderLayer with norm_first = False, no dropout): the blocks of
/// Chen et al. 2023's DeformTransformer (2 encoder and 2 decoder blocks, 8 heads, supplement §3).
///
///     nn::TransformerEncoderBlock<float> enc(store, "enc.0", 64, 128, 3, rng);          // d, ff, T
///     enc.forward(exec::omp, nn::Mode::train, x, y);                                    // (B·3)×64
///     nn::TransformerDecoderBlock<float> dec(store, "dec.0", 64, 128, 3, 3, rng);
///     dec.forward(exec::omp, nn::Mode::train, y_prev, memory, z);
///
/// Encoder: x₁ = LN(x + SelfAttention(x)), y = LN(x₁ + FFN(x₁)).
/// Decoder: x₁ = LN(x + CausalSelfAttention(x)), x₂ = LN(x₁ + Attention(x₁, memory)),
///          y = LN(x₂ + FFN(x₂)). FFN(x) = W₂ ReLU(W₁x + b₁) + b₂.

#include <string>

#include "activations.hpp"
#include "layer.hpp"
#include "layer_norm.hpp"
#include "linear.hpp"
#include "multi_head_attention.hpp"

namespace simsr::nn {

/// Position-wise feed-forward d → ff → d with ReLU (an nn::Layer).
template <class S = float>
class FeedForward {
 public:
  using scalar_type = S;
  FeedForward(ParameterStore<S>& store, const std::string& name, Index d, Index ff, Rng& rng)
      : l1_(store, name + ".linear1", d, ff, rng), l2_(store, name + ".linear2", ff, d, rng), relu_(S(0)) {}
  Index out_features(Index = -1) const { return l2_.out_features(); }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& in, Matrix<S>& out) {
    l1_.forward(policy, mode, in, h_);
    relu_.forward(policy, mode, h_, a_);
    l2_.forward(policy, mode, a_, out);
  }
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in) {
    l2_.backward(policy, a_, out, d_out, &da_);
    relu_.backward(policy, h_, a_, da_, &dh_);
    l1_.backward(policy, in, h_, dh_, d_in);
  }

 private:
  Linear<S> l1_, l2_;
  LeakyReLU<S> relu_;
  Matrix<S> h_, a_, da_, dh_;
};
static_assert(assert_layer<FeedForward<float>>());

/// "Add & Norm" (Vaswani et al. 2017 §3.1): y = LN(x + sublayer(x)). backward gives the gradient
/// of the sum, which is that of both x and the sublayer's output.
template <class S = float>
class AddNorm {
 public:
  AddNorm(ParameterStore<S>& store, const std::string& name, Index d) : norm_(store, name, d) {}

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& x, const ConstView<S>& sublayer_out, Matrix<S>& out) {
    sum_ = x + sublayer_out;
    norm_.forward(policy, mode, sum_, out);
  }
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>& d_sum) {
    norm_.backward(policy, sum_, out, d_out, &d_sum);
  }

 private:
  LayerNorm<S> norm_;
  Matrix<S> sum_;
};

/// One encoder block over sequences of `seq_len` tokens (an nn::Layer).
template <class S = float>
class TransformerEncoderBlock {
 public:
  using scalar_type = S;
  TransformerEncoderBlock(ParameterStore<S>& store, const std::string& name, Index d, Index ff, Index seq_len, Rng& rng, Index heads = 8)
      : att_(store, name + ".self_attn", d, seq_len, rng, {.heads = heads, .causal = false}),
        norm1_(store, name + ".norm1", d),
        ffn_(store, name + ".ffn", d, ff, rng),
        norm2_(store, name + ".norm2", d) {}
  Index out_features(Index = -1) const { return att_.out_features(); }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& in, Matrix<S>& out) {
    att_.forward(policy, mode, in, a_);
    norm1_.forward(policy, mode, in, a_, x1_);
    ffn_.forward(policy, mode, x1_, f_);
    norm2_.forward(policy, mode, x1_, f_, out);
  }
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in) {
    norm2_.backward(policy, out, d_out, d_sum2_);
    ffn_.backward(policy, x1_, f_, d_sum2_, &d_tmp_);
    d_x1_ = d_sum2_ + d_tmp_;
    norm1_.backward(policy, x1_, d_x1_, d_sum1_);
    att_.backward(policy, in, a_, d_sum1_, d_in ? &d_tmp_ : nullptr);
    if (d_in) *d_in = d_sum1_ + d_tmp_;
  }

 private:
  SelfAttention<S> att_;
  AddNorm<S> norm1_;
  FeedForward<S> ffn_;
  AddNorm<S> norm2_;
  Matrix<S> a_, x1_, f_, d_sum2_, d_tmp_, d_x1_, d_sum1_;
};
static_assert(assert_layer<TransformerEncoderBlock<float>>());

/// One decoder block: causal self-attention over `seq_len` target tokens, then attention to the
/// encoder's `memory_len` tokens, then the feed-forward. Two inputs, so not an nn::Layer.
template <class S = float>
class TransformerDecoderBlock {
 public:
  using scalar_type = S;
  TransformerDecoderBlock(ParameterStore<S>& store, const std::string& name, Index d, Index ff, Index seq_len, Index memory_len, Rng& rng,
                          Index heads = 8)
      : self_(store, name + ".self_attn", d, seq_len, rng, {.heads = heads, .causal = true}),
        norm1_(store, name + ".norm1", d),
        cross_(store, name + ".cross_attn", d, rng, {.heads = heads, .causal = false}),
        norm2_(store, name + ".norm2", d),
        ffn_(store, name + ".ffn", d, ff, rng),
        norm3_(store, name + ".norm3", d),
        t_(seq_len), tm_(memory_len) {}
  Index out_features(Index = -1) const { return self_.out_features(); }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& in, const ConstView<S>& memory, Matrix<S>& out) {
    self_.forward(policy, mode, in, a_);
    norm1_.forward(policy, mode, in, a_, x1_);
    cross_.forward(policy, mode, x1_, t_, memory, tm_, c_);
    norm2_.forward(policy, mode, x1_, c_, x2_);
    ffn_.forward(policy, mode, x2_, f_);
    norm3_.forward(policy, mode, x2_, f_, out);
  }
  /// d_in written; the memory's gradient *added* to d_memory (the encoder output feeds every
  /// decoder block) when not null.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>& memory, const ConstView<S>& out, const ConstView<S>& d_out,
                Matrix<S>* d_in, Matrix<S>* d_memory) {
    norm3_.backward(policy, out, d_out, d_sum3_);
    ffn_.backward(policy, x2_, f_, d_sum3_, &d_tmp_);
    d_x2_ = d_sum3_ + d_tmp_;
    norm2_.backward(policy, x2_, d_x2_, d_sum2_);
    cross_.backward(policy, x1_, memory, c_, d_sum2_, &d_tmp_, d_memory ? &d_mem_ : nullptr);
    if (d_memory) {
      if (d_memory->rows() != memory.rows() || d_memory->cols() != memory.cols()) d_memory->setZero(memory.rows(), memory.cols());
      *d_memory += d_mem_;
    }
    d_x1_ = d_sum2_ + d_tmp_;
    norm1_.backward(policy, x1_, d_x1_, d_sum1_);
    self_.backward(policy, in, a_, d_sum1_, d_in ? &d_tmp_ : nullptr);
    if (d_in) *d_in = d_sum1_ + d_tmp_;
  }

 private:
  SelfAttention<S> self_;
  AddNorm<S> norm1_;
  MultiHeadAttention<S> cross_;
  AddNorm<S> norm2_;
  FeedForward<S> ffn_;
  AddNorm<S> norm3_;
  Index t_, tm_;
  Matrix<S> a_, x1_, c_, x2_, f_, d_sum3_, d_tmp_, d_x2_, d_sum2_, d_mem_, d_x1_, d_sum1_;
};

}  // namespace simsr::nn
