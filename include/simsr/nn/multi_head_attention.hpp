#pragma once
/// \file
/// Multi-head scaled dot-product attention (Vaswani et al. 2017) over short sequences of tokens:
/// the attention of Chen et al. 2023's DeformTransformer (8 heads over 3 frames, supplement §3).
///
/// Layout: a batch of B sequences of T tokens is a (B·T)×d matrix, row b·T + t token t of
/// sequence b (tensor.hpp's points × channels, tokens as points). Queries and keys/values may come
/// from different matrices (cross-attention) with their own lengths Tq and Tk.
///
///     nn::MultiHeadAttention<float> att(store, "dec.cross", 64, rng, {.heads = 8});
///     att.forward(exec::omp, nn::Mode::train, x, 3, memory, 3, y);     // y: (B·3)×64
///     att.backward(exec::omp, x, memory, y, dy, &dx, &dmemory);
///
/// Per sequence and head h (d_h = d/heads columns): Q = x W_qᵀ + b_q, K = m W_kᵀ + b_k,
/// V = m W_vᵀ + b_v, A = softmax(Q_h K_hᵀ/√d_h) (row-wise; with `causal`, query t sees keys ≤ t),
/// O_h = A V_h, y = O W_oᵀ + b_o.

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "layer.hpp"
#include "linear.hpp"

namespace simsr::nn {

template <class S = float>
class MultiHeadAttention {
 public:
  using scalar_type = S;

  struct Options {
    Index heads = 8;
    bool causal = false;  ///< query t attends to keys 0..t only (needs Tq == Tk)
  };

  /// Tensors `<name>.q|k|v|out.weight` (d×d) and `.bias` (d), PyTorch's nn.Linear initialization.
  /// ArgumentError unless heads ≥ 1 divides d.
  MultiHeadAttention(ParameterStore<S>& store, const std::string& name, Index d_model, Rng& rng, Options options = {})
      : q_(store, name + ".q", d_model, d_model, rng),
        k_(store, name + ".k", d_model, d_model, rng),
        v_(store, name + ".v", d_model, d_model, rng),
        o_(store, name + ".out", d_model, d_model, rng),
        d_(d_model), opt_(options), where_("nn::MultiHeadAttention '" + name + "'") {
    if (options.heads < 1 || d_model % options.heads != 0)
      throw ArgumentError(where_ + ": heads (" + std::to_string(options.heads) + ") must divide d_model (" + std::to_string(d_model) + ")");
  }

  Index d_model() const { return d_; }
  Index heads() const { return opt_.heads; }
  Index out_features(Index = -1) const { return d_; }

  /// q_in (B·tq)×d, kv_in (B·tk)×d → out (B·tq)×d.
  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& q_in, Index tq, const ConstView<S>& kv_in, Index tk, Matrix<S>& out) {
    if (tq < 1 || tk < 1 || q_in.rows() % tq != 0 || kv_in.rows() % tk != 0 || q_in.rows() / tq != kv_in.rows() / tk)
      throw ShapeError(where_ + ": queries (B·Tq rows) and keys (B·Tk rows) with Tq = " + std::to_string(tq) + ", Tk = " + std::to_string(tk),
                       {-1, d_}, {q_in.rows(), kv_in.rows()});
    if (opt_.causal && tq != tk) throw ArgumentError(where_ + ": causal attention needs Tq == Tk");
    tq_ = tq, tk_ = tk;
    const Index B = q_in.rows() / tq, H = opt_.heads, dh = d_ / H;
    q_.forward(policy, mode, q_in, Q_);
    k_.forward(policy, mode, kv_in, K_);
    v_.forward(policy, mode, kv_in, V_);
    ensure_shape(A_, B * H * tq, tk);
    ensure_shape(O_, B * tq, d_);
    const S scale = S(1) / std::sqrt(S(dh));
    const Index nc = exec::chunk_count(B, product_chunks);
    exec::for_chunks(policy, B, nc, exec::worker_count(policy, nc), [&](Index, Index, Index lo, Index hi) {
      for (Index b = lo; b < hi; ++b)
        for (Index h = 0; h < H; ++h)
          for (Index i = 0; i < tq; ++i) {
            S* a = &A_((b * H + h) * tq + i, 0);
            const Index last = opt_.causal ? i : tk - 1;
            S mx = -std::numeric_limits<S>::infinity();
            for (Index j = 0; j <= last; ++j) {
              a[j] = Q_.row(b * tq + i).segment(h * dh, dh).dot(K_.row(b * tk + j).segment(h * dh, dh)) * scale;
              mx = std::max(mx, a[j]);
            }
            S sum = 0;
            for (Index j = 0; j <= last; ++j) sum += (a[j] = std::exp(a[j] - mx));
            for (Index j = 0; j < tk; ++j) a[j] = j <= last ? a[j] / sum : S(0);
            auto o = O_.row(b * tq + i).segment(h * dh, dh);
            o.setZero();
            for (Index j = 0; j <= last; ++j) o += a[j] * V_.row(b * tk + j).segment(h * dh, dh);
          }
    });
    o_.forward(policy, mode, O_, out);
  }

  /// Parameter gradients added; d_q_in and d_kv_in (either may be null) written. For
  /// self-attention (the same matrix as queries and keys) the caller adds the two.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& q_in, const ConstView<S>& kv_in, const ConstView<S>& out, const ConstView<S>& d_out,
                Matrix<S>* d_q_in, Matrix<S>* d_kv_in) {
    const Index tq = tq_, tk = tk_;
    if (tq < 1 || q_in.rows() != Q_.rows() || kv_in.rows() != K_.rows())
      throw ArgumentError(where_ + ": backward without a forward of the same inputs");
    const Index B = q_in.rows() / tq, H = opt_.heads, dh = d_ / H;
    o_.backward(policy, O_, out, d_out, &dO_);
    ensure_shape(dQ_, B * tq, d_);
    ensure_shape(dK_, B * tk, d_);
    ensure_shape(dV_, B * tk, d_);
    const S scale = S(1) / std::sqrt(S(dh));
    const Index nc = exec::chunk_count(B, product_chunks);
    exec::for_chunks(policy, B, nc, exec::worker_count(policy, nc), [&](Index, Index, Index lo, Index hi) {
      std::vector<S> dA(static_cast<std::size_t>(tk)), dS(static_cast<std::size_t>(tk));
      for (Index b = lo; b < hi; ++b) {
        dQ_.middleRows(b * tq, tq).setZero();
        dK_.middleRows(b * tk, tk).setZero();
        dV_.middleRows(b * tk, tk).setZero();
        for (Index h = 0; h < H; ++h)
          for (Index i = 0; i < tq; ++i) {
            const S* a = &A_((b * H + h) * tq + i, 0);
            const auto dO = dO_.row(b * tq + i).segment(h * dh, dh);
            S dot = 0;
            for (Index j = 0; j < tk; ++j) {
              dA[j] = dO.dot(V_.row(b * tk + j).segment(h * dh, dh));  // dA = dO Vᵀ
              dot += dA[j] * a[j];
              dV_.row(b * tk + j).segment(h * dh, dh) += a[j] * dO;     // dV = Aᵀ dO
            }
            for (Index j = 0; j < tk; ++j) dS[j] = a[j] * (dA[j] - dot) * scale;  // softmax, then the 1/√d_h
            for (Index j = 0; j < tk; ++j) {
              dQ_.row(b * tq + i).segment(h * dh, dh) += dS[j] * K_.row(b * tk + j).segment(h * dh, dh);
              dK_.row(b * tk + j).segment(h * dh, dh) += dS[j] * Q_.row(b * tq + i).segment(h * dh, dh);
            }
          }
      }
    });
    q_.backward(policy, q_in, Q_, dQ_, d_q_in);
    k_.backward(policy, kv_in, K_, dK_, d_kv_in);
    if (d_kv_in) {
      v_.backward(policy, kv_in, V_, dV_, &dkv_v_);
      *d_kv_in += dkv_v_;
    } else {
      v_.backward(policy, kv_in, V_, dV_, nullptr);
    }
  }

 private:
  Linear<S> q_, k_, v_, o_;
  Index d_;
  Options opt_;
  std::string where_;
  Index tq_ = 0, tk_ = 0;
  Matrix<S> Q_, K_, V_, A_, O_, dO_, dQ_, dK_, dV_, dkv_v_;
};

/// Self-attention as an nn::Layer: queries, keys and values from one (B·T)×d input, T fixed.
template <class S = float>
class SelfAttention {
 public:
  using scalar_type = S;

  SelfAttention(ParameterStore<S>& store, const std::string& name, Index d_model, Index seq_len, Rng& rng,
                typename MultiHeadAttention<S>::Options options = {})
      : att_(store, name, d_model, rng, options), t_(seq_len) {
    if (seq_len < 1) throw ArgumentError("nn::SelfAttention '" + name + "': seq_len must be >= 1");
  }

  Index out_features(Index = -1) const { return att_.d_model(); }
  Index seq_len() const { return t_; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& in, Matrix<S>& out) {
    att_.forward(policy, mode, in, t_, in, t_, out);
  }
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in) {
    att_.backward(policy, in, in, out, d_out, d_in, d_in ? &d_kv_ : nullptr);
    if (d_in) *d_in += d_kv_;
  }

 private:
  MultiHeadAttention<S> att_;
  Index t_;
  Matrix<S> d_kv_;
};
static_assert(assert_layer<SelfAttention<float>>());

}  // namespace simsr::nn
