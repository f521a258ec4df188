#pragma once
/// \file
/// Layer normalization over each row's channels (Ba et al. 2016; PyTorch's nn.LayerNorm(C)):
/// after every mesh convolution of Chen et al. 2023's encoders (supplement §2.2) and in the
/// DeformTransformer's blocks.
///
///     nn::LayerNorm<float> ln(store, "enc.conv1.norm", 64);
///     ln.forward(exec::omp, nn::Mode::train, h, y);   // y_r = (h_r − mean)/√(var + eps)·γ + β

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "layer.hpp"
#include "parameters.hpp"

namespace simsr::nn {

/// y = (x − μ_r)/√(σ²_r + eps)·γ + β per row r: μ_r, σ²_r the mean and biased variance of the
/// row's C channels (summed in double). The same in train and eval mode. Tensors `<name>.weight`
/// γ (1s) and `<name>.bias` β (0s), PyTorch's names and initialization.
template <class S = float>
class LayerNorm {
 public:
  using scalar_type = S;

  LayerNorm(ParameterStore<S>& store, std::string name, Index channels, double eps = 1e-5)
      : store_(&store), name_(std::move(name)), where_("nn::LayerNorm '" + name_ + "'"), c_(channels), eps_(eps) {
    if (channels < 1) throw ArgumentError(where_ + ": channels must be >= 1");
    if (!(eps > 0)) throw ArgumentError(where_ + ": eps must be > 0");
    w_off_ = store.add_parameter(name_ + ".weight", {channels});
    b_off_ = store.add_parameter(name_ + ".bias", {channels});
    store.value(w_off_, 1, channels).setOnes();
  }

  const std::string& name() const { return name_; }
  Index channels() const { return c_; }
  Index out_features(Index = -1) const { return c_; }
  MatrixMap<S> weight() { return store_->value(w_off_, 1, c_); }
  MatrixMap<S> bias() { return store_->value(b_off_, 1, c_); }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode, const ConstView<S>& in, Matrix<S>& out) {
    detail::check_shape(where_, "input", in, -1, c_);
    const Index R = in.rows();
    ensure_shape(out, R, c_);
    ensure_shape(xhat_, R, c_);
    ensure_size(inv_std_, R);
    const auto g = std::as_const(*store_).value(w_off_, 1, c_);
    const auto b = std::as_const(*store_).value(b_off_, 1, c_);
    const Index nc = exec::chunk_count(R, product_chunks);
    exec::for_chunks(policy, R, nc, exec::worker_count(policy, nc), [&](Index, Index, Index lo, Index hi) {
      for (Index r = lo; r < hi; ++r) {
        double mean = 0, var = 0;
        for (Index c = 0; c < c_; ++c) mean += double(in(r, c));
        mean /= double(c_);
        for (Index c = 0; c < c_; ++c) var += (double(in(r, c)) - mean) * (double(in(r, c)) - mean);
        const S inv = S(1.0 / std::sqrt(var / double(c_) + eps_));
        inv_std_[r] = inv;
        for (Index c = 0; c < c_; ++c) {
          xhat_(r, c) = (in(r, c) - S(mean)) * inv;
          out(r, c) = xhat_(r, c) * g(0, c) + b(0, c);
        }
      }
    });
  }

  /// ∂γ += Σ_r dy⊙x̂, ∂β += Σ_r dy (fixed row chunks, merged in order);
  /// dx = inv_std·(dx̂ − mean(dx̂) − x̂·mean(dx̂⊙x̂)) with dx̂ = dy⊙γ.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in) {
    const Index R = in.rows();
    detail::check_shape(where_, "output gradient", d_out, R, c_);
    if (xhat_.rows() != R) throw ArgumentError(where_ + ": backward without a forward of the same input");
    const auto g = std::as_const(*store_).value(w_off_, 1, c_);
    if (d_in) {
      ensure_shape(*d_in, R, c_);
      const Index nc = exec::chunk_count(R, product_chunks);
      exec::for_chunks(policy, R, nc, exec::worker_count(policy, nc), [&](Index, Index, Index lo, Index hi) {
        for (Index r = lo; r < hi; ++r) {
          double m1 = 0, m2 = 0;
          for (Index c = 0; c < c_; ++c) {
            const double dxh = double(d_out(r, c)) * double(g(0, c));
            m1 += dxh;
            m2 += dxh * double(xhat_(r, c));
          }
          m1 /= double(c_);
          m2 /= double(c_);
          for (Index c = 0; c < c_; ++c)
            (*d_in)(r, c) = S(double(inv_std_[r]) * (double(d_out(r, c)) * double(g(0, c)) - m1 - double(xhat_(r, c)) * m2));
        }
      });
    }
    const Index nr = exec::chunk_count(R, reduction_chunks);
    ensure_shape(parts_, 2 * nr, c_);
    exec::for_chunks(policy, R, nr, exec::worker_count(policy, nr), [&](Index, Index c, Index lo, Index hi) {
      parts_.row(2 * c).setZero();
      parts_.row(2 * c + 1).setZero();
      for (Index r = lo; r < hi; ++r) {
        parts_.row(2 * c) += d_out.row(r).cwiseProduct(xhat_.row(r));
        parts_.row(2 * c + 1) += d_out.row(r);
      }
    });
    auto gw = store_->gradient(w_off_, 1, c_);
    auto gb = store_->gradient(b_off_, 1, c_);
    for (Index c = 0; c < nr && R > 0; ++c) gw += parts_.row(2 * c), gb += parts_.row(2 * c + 1);
  }

 private:
  ParameterStore<S>* store_;
  std::string name_, where_;
  Index c_;
  double eps_;
  Index w_off_ = -1, b_off_ = -1;
  Matrix<S> xhat_, parts_;
  Vector<S> inv_std_;
};
static_assert(assert_layer<LayerNorm<float>>());

}  // namespace simsr::nn
