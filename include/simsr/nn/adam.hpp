#pragma once
/// \file
/// Adam over a ParameterStore's flat buffers, with PyTorch's semantics (torch.optim.Adam, the
/// single-tensor path used on CPU): bias correction, eps added after the square root, optional
/// L2 weight decay (off by default). SPEC §7: lr 2e-4 (official) / 1e-4 (paper).
///
///     nn::Adam<float> opt(store, {.lr = 2e-4});
///     store.zero_grad(); /* forward, backward */ opt.step(exec::omp);
///     auto st = opt.state(); /* save */ opt.load_state(st);

#include <cmath>
#include <cstdint>

#include "parameters.hpp"

namespace simsr::nn {

/// Per parameter p with gradient g (t = step count after the increment):
///   g ← g + weight_decay·p;  m ← lerp(m, g, 1 − β₁);  v ← β₂·v + (1 − β₂)·g²;
///   p ← p − lr/(1 − β₁ᵗ) · m / (√v / √(1 − β₂ᵗ) + eps),
/// the scalars in double and the elementwise arithmetic in S in PyTorch's order (lerp as ATen
/// computes it), so a float run follows PyTorch's to rounding.
template <class S = float>
class Adam {
 public:
  using scalar_type = S;

  struct Options {
    double lr = 1e-3;
    double beta1 = 0.9;
    double beta2 = 0.999;
    double eps = 1e-8;
    double weight_decay = 0.0;
  };

  /// Optimizer state: the step count and PyTorch's exp_avg / exp_avg_sq, flat like the store.
  struct State {
    std::int64_t step = 0;
    Vector<S> exp_avg, exp_avg_sq;
  };

  explicit Adam(ParameterStore<S>& store, Options options = {}) : store_(&store), opt_(options) {
    if (!(options.lr >= 0) || !(options.eps >= 0) || !(options.weight_decay >= 0))
      throw ArgumentError("nn::Adam: lr, eps and weight_decay must be >= 0");
    if (!(options.beta1 >= 0 && options.beta1 < 1) || !(options.beta2 >= 0 && options.beta2 < 1))
      throw ArgumentError("nn::Adam: betas must be in [0, 1)");
  }

  const Options& options() const { return opt_; }
  void set_lr(double lr) { opt_.lr = lr; }
  std::int64_t steps() const { return st_.step; }
  const State& state() const { return st_; }
  /// Restores a saved state; ShapeError when it does not match the store's parameter count.
  void load_state(State s) {
    const Index n = store_->num_parameters();
    if (s.step < 0) throw ArgumentError("nn::Adam::load_state: negative step count");
    if (s.step == 0 && s.exp_avg.size() == 0 && s.exp_avg_sq.size() == 0) {  // the state before the first step
      st_ = std::move(s);
      return;
    }
    if (s.exp_avg.size() != n || s.exp_avg_sq.size() != n)
      throw ShapeError("nn::Adam::load_state: exp_avg / exp_avg_sq", {n}, {s.exp_avg.size()});
    st_ = std::move(s);
  }

  /// One update of every trainable parameter from the store's gradients.
  template <exec::HostPolicy Policy>
  void step(Policy policy) {
    const Index n = store_->num_parameters();
    if (st_.exp_avg.size() != n) {
      if (st_.step != 0) throw ShapeError("nn::Adam::step: the store's parameter count changed after the first step", {st_.exp_avg.size()}, {n});
      st_.exp_avg.setZero(n);
      st_.exp_avg_sq.setZero(n);
    }
    ++st_.step;
    const double t = double(st_.step);
    const S w1 = static_cast<S>(1 - opt_.beta1), b2 = static_cast<S>(opt_.beta2), w2 = static_cast<S>(1 - opt_.beta2);
    const S wd = static_cast<S>(opt_.weight_decay), eps = static_cast<S>(opt_.eps);
    const S step_size = static_cast<S>(opt_.lr / (1 - std::pow(opt_.beta1, t)));
    const S bc2_sqrt = static_cast<S>(std::sqrt(1 - std::pow(opt_.beta2, t)));
    S* p = store_->values().data();
    const S* grad = store_->gradients().data();
    S* m = st_.exp_avg.data();
    S* v = st_.exp_avg_sq.data();
    const bool decay = opt_.weight_decay != 0;
    const Index nc = exec::chunk_count(n, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, n, nc, workers, [&](Index, Index, Index b, Index e) {
      for (Index i = b; i < e; ++i) {
        const S g = decay ? grad[i] + wd * p[i] : grad[i];
        m[i] = w1 < S(0.5) ? m[i] + w1 * (g - m[i]) : g - (g - m[i]) * (S(1) - w1);
        v[i] = v[i] * b2 + w2 * (g * g);
        const S denom = std::sqrt(v[i]) / bc2_sqrt + eps;
        p[i] = p[i] + (-step_size) * (m[i] / denom);
      }
    });
  }

 private:
  ParameterStore<S>* store_;
  Options opt_;
  State st_;
};

}  // namespace simsr::nn
