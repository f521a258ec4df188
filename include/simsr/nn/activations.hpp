#pragma once
/// \file
/// Elementwise activations (no parameters): LeakyReLU (slope 0.2 in the feature embedding, SPEC §7),
/// Tanh (the thin-shell encoders) and Sine, sin(ω₀·x), of SIREN (the upsampling weight network and the decoder), with the SIREN
/// initialization of the Linear layer before a Sine.
///
///     nn::Linear<float> l0(store, "net_decoder.decoder.layers.0.fc", 227, 256, rng);
///     nn::siren_init(l0, rng, 30.0, true);   // first layer: U(±1/fan_in)
///     nn::Sine<float> s0(30.0f);

#include <cmath>
#include <type_traits>

#include "layer.hpp"
#include "linear.hpp"

namespace simsr::nn {

namespace detail {
/// out = f(in) elementwise over fixed row chunks.
template <class S, class Policy, class F>
void map_rows(Policy policy, const ConstView<S>& in, Matrix<S>& out, F&& f) {
  const Index R = in.rows(), C = in.cols();
  ensure_shape(out, R, C);
  const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
  exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
    // Row pointers, a local count and a local copy of f: the loop vectorizes. Through the caller's
    // f, its captures (LeakyReLU's slope) could alias the stored floats and were reloaded after
    // every store, which kept the loop scalar: LeakyReLU was a quarter of a bunny training step.
    const std::decay_t<F> fn = f;
    const Index n = C;
    for (Index r = b; r < e; ++r) {
      const S* x = in.row(r).data();
      S* y = out.row(r).data();
      for (Index c = 0; c < n; ++c) y[c] = fn(x[c]);
    }
  });
}
/// d_in = d_out ⊙ f'(in) elementwise over fixed row chunks.
template <class S, class Policy, class F>
void map_rows_backward(Policy policy, const ConstView<S>& in, const ConstView<S>& d_out, Matrix<S>& d_in, const char* layer, F&& df) {
  check_shape(layer, "output gradient", d_out, in.rows(), in.cols());
  const Index R = in.rows(), C = in.cols();
  ensure_shape(d_in, R, C);
  const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
  exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
    const std::decay_t<F> dfn = df;  // a local copy: the loop vectorizes (map_rows)
    const Index n = C;
    for (Index r = b; r < e; ++r) {
      const S* x = in.row(r).data();
      const S* g = d_out.row(r).data();
      S* d = d_in.row(r).data();
      for (Index c = 0; c < n; ++c) d[c] = g[c] * dfn(x[c]);
    }
  });
}
/// y[i] = f(x[i], …) for i < n over one or more inputs, `f` an Eigen array expression of fixed
/// blocks of 16 values: every value goes through Eigen's packet functions (the last block padded),
/// so its result depends on the values alone. Eigen's own loop over a span computes the span's
/// unaligned head and its tail with the scalar functor, which for sin is std::sin: the bits would
/// depend on where a value sits in memory and in its chunk. `y` may be one of the inputs.
inline constexpr Index packet_block = 16;
template <class S, class F, class... Inputs>
void map_packets(S* y, Index n, F&& f, const Inputs*... x) {
  using Block = Eigen::Array<S, packet_block, 1>;
  Index i = 0;
  for (; i + packet_block <= n; i += packet_block) {
    const Block r = f(Block(Eigen::Map<const Block>(x + i))...);
    Eigen::Map<Block>(y + i) = r;
  }
  if (i == n) return;
  const Index tail = n - i;
  const auto padded = [&](const S* p) {
    Block a = Block::Zero();
    for (Index k = 0; k < tail; ++k) a[k] = p[i + k];
    return a;
  };
  const Block r = f(padded(x)...);
  for (Index k = 0; k < tail; ++k) y[i + k] = r[k];
}
/// out = f(in, more…) over fixed row chunks through map_packets (a chunk of contiguous views is one
/// span); `more` have in's shape (the caller checks).
template <class S, class Policy, class F, class... Views>
void map_rows_packets(Policy policy, Matrix<S>& out, F&& f, const ConstView<S>& in, const Views&... more) {
  const Index R = in.rows(), C = in.cols();
  ensure_shape(out, R, C);
  const bool contiguous = in.outerStride() == C && ((more.outerStride() == C) && ...);
  const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
  exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
    if (b >= e) return;
    if (contiguous) {
      map_packets(out.row(b).data(), (e - b) * C, f, in.row(b).data(), more.row(b).data()...);
    } else {
      for (Index r = b; r < e; ++r) map_packets(out.row(r).data(), C, f, in.row(r).data(), more.row(r).data()...);
    }
  });
}
}  // namespace detail

/// LeakyReLU: x for x > 0, slope·x otherwise (PyTorch: the gradient at 0 is `slope`).
/// `out` must not alias `in` (backward reads `in`).
template <class S = float>
class LeakyReLU {
 public:
  using scalar_type = S;
  explicit LeakyReLU(S slope = S(0.2)) : slope_(slope) {}
  S slope() const { return slope_; }
  Index out_features(Index in_cols) const { return in_cols; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode, const ConstView<S>& in, Matrix<S>& out) {
    const S a = slope_;
    detail::map_rows<S>(policy, in, out, [a](S x) { return x > S(0) ? x : a * x; });
  }
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in) {
    if (!d_in) return;
    const S a = slope_;
    detail::map_rows_backward<S>(policy, in, d_out, *d_in, "nn::LeakyReLU", [a](S x) { return x > S(0) ? S(1) : a; });
  }

 private:
  S slope_;
};
static_assert(assert_layer<LeakyReLU<float>>());

/// tanh (the activation of Chen et al. 2023's mesh encoders, supplement §3). `out` must not
/// alias `in`. Eigen's packet tanh (detail::map_packets): for float its vectorized rational
/// approximation (within a few ulp of std::tanh; tested), which made the thin-shell network's training step 2× faster at the
/// fine SHEET's 4,225 vertices (libm's scalar tanhf and its expm1f were 40 % of a step). The
/// gradient is 1 − y² from the forward's output y, not a second tanh of the input.
template <class S = float>
class Tanh {
 public:
  using scalar_type = S;
  Index out_features(Index in_cols) const { return in_cols; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode, const ConstView<S>& in, Matrix<S>& out) {
    detail::map_rows_packets<S>(policy, out, [](const auto& x) { return x.tanh(); }, in);
  }
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>& out, const ConstView<S>& d_out, Matrix<S>* d_in) {
    if (!d_in) return;
    detail::check_shape("nn::Tanh", "forward output", out, in.rows(), in.cols());
    // map_rows_backward's df takes the input; here the factor comes from the output
    detail::map_rows_backward<S>(policy, out, d_out, *d_in, "nn::Tanh", [](S y) { return S(1) - y * y; });
  }
};
static_assert(assert_layer<Tanh<float>>());

/// Sine activation sin(ω₀·x) (SIREN, Sitzmann et al. 2020; the reference's `Sine(w0)`).
/// `out` must not alias `in`. Eigen's packet sin and cos (detail::map_packets): for float its
/// vectorized ones (Cody–Waite range reduction and a polynomial, within a few ulp of std::sin;
/// tested), for double std::sin and std::cos. libm's scalar sinf and cosf were 9 % of a bunny
/// training step (README, "Training on the bunny").
template <class S = float>
class Sine {
 public:
  using scalar_type = S;
  explicit Sine(S omega0 = S(1)) : w0_(omega0) {}
  S omega0() const { return w0_; }
  Index out_features(Index in_cols) const { return in_cols; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode, const ConstView<S>& in, Matrix<S>& out) {
    const S w0 = w0_;
    detail::map_rows_packets<S>(policy, out, [w0](const auto& x) { return (x * w0).sin(); }, in);
  }
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in) {
    if (!d_in) return;
    const S w0 = w0_;
    detail::check_shape("nn::Sine", "output gradient", d_out, in.rows(), in.cols());
    detail::map_rows_packets<S>(policy, *d_in, [w0](const auto& x, const auto& g) { return g * (w0 * (x * w0).cos()); }, in, d_out);
  }

 private:
  S w0_;
};
static_assert(assert_layer<Sine<float>>());

/// Bound of the SIREN uniform initialization of a Linear with `fan_in` inputs followed by
/// sin(ω₀·): 1/fan_in for the first layer, √(c/fan_in)/ω₀ after (c = 6; SPEC §7, the
/// reference's `Siren.init_`).
inline double siren_bound(Index fan_in, double omega0, bool first, double c = 6.0) {
  if (fan_in < 1 || !(omega0 > 0)) throw ArgumentError("nn::siren_bound: fan_in must be >= 1 and omega0 > 0");
  return first ? 1.0 / double(fan_in) : std::sqrt(c / double(fan_in)) / omega0;
}

/// Draws `layer`'s weight, then bias, U(±siren_bound(in_features, omega0, first, c)).
template <class S>
void siren_init(Linear<S>& layer, Rng& rng, double omega0, bool first, double c = 6.0) {
  const double bound = siren_bound(layer.in_features(), omega0, first, c);
  layer.init_uniform(rng, bound, bound);
}

}  // namespace simsr::nn
