#pragma once
/// \file
/// Dropout (the official FeatEmb's `drop_out`, applied after each embedding block; SPEC §7).
///
///     nn::Dropout<float> drop(0.1, nn::Rng(42));
///     drop.forward(exec::omp, nn::Mode::train, h, y);   // y = h ⊙ mask / (1 − p), mask ~ Bernoulli(1 − p)
///     drop.forward(exec::omp, nn::Mode::eval, h, y);    // y = h

#include <string>

#include "batch_split.hpp"
#include "layer.hpp"

namespace simsr::nn {

/// Inverted dropout: in train mode each entry is zeroed with probability p and the kept ones are
/// scaled by 1/(1 − p) (p = 1: all zeros); in eval mode, or with p = 0, out = in exactly (no random
/// draw). The mask is drawn serially, row-major, one `uniform(rng)` per entry (entry dropped when
/// u < p), from the layer's own seeded Rng, so a seed gives the same masks under exec::seq and
/// exec::omp; each train forward draws a fresh mask, which backward reuses.
template <class S = float>
class Dropout {
 public:
  using scalar_type = S;

  explicit Dropout(double p = 0.5, Rng rng = Rng(0)) : p_(p), rng_(rng) {
    if (!(p >= 0 && p <= 1)) throw ArgumentError("nn::Dropout: p = " + std::to_string(p) + " must be in [0, 1]");
  }

  double p() const { return p_; }
  Index out_features(Index in_cols) const { return in_cols; }
  Rng& rng() { return rng_; }
  /// The batch split of data-parallel training (nullptr: none): the mask of each batch item is then
  /// drawn from its own stream (one draw of rng() per forward, mixed with the item's global index),
  /// so an item gets the same mask on whichever rank holds it.
  void set_batch_split(const BatchSplit* split) { split_ = split; }

  /// The mask of the last train forward (0 or 1/(1 − p) per entry); empty after an identity forward.
  const Matrix<S>& mask() const { return mask_; }

  template <exec::HostPolicy Policy>
  void forward(Policy policy, Mode mode, const ConstView<S>& in, Matrix<S>& out) {
    const Index R = in.rows(), C = in.cols();
    ensure_shape(out, R, C);
    masked_ = mode == Mode::train && p_ > 0;
    if (masked_) {
      ensure_shape(mask_, R, C);
      const S keep = p_ < 1 ? static_cast<S>(1.0 / (1.0 - p_)) : S(0);
      if (!split_) {
        for (Index i = 0; i < mask_.size(); ++i) mask_.data()[i] = uniform(rng_, 0, 1) < p_ ? S(0) : keep;
      } else {
        const Index per_item = split_->rows_per_item(R, "nn::Dropout") * C;
        const std::uint64_t base = rng_();
        for (Index item = 0; item < split_->count(); ++item) {
          Rng r(base ^ (0x9E3779B97F4A7C15ull * std::uint64_t(split_->first() + item + 1)));
          S* m = mask_.data() + item * per_item;
          for (Index i = 0; i < per_item; ++i) m[i] = uniform(r, 0, 1) < p_ ? S(0) : keep;
        }
      }
    }
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
      if (masked_)
        out.middleRows(b, e - b) = in.middleRows(b, e - b).cwiseProduct(mask_.middleRows(b, e - b));
      else
        out.middleRows(b, e - b) = in.middleRows(b, e - b);
    });
  }

  /// d_in = d_out ⊙ mask (train, p > 0) or d_out.
  template <exec::HostPolicy Policy>
  void backward(Policy policy, const ConstView<S>& in, const ConstView<S>&, const ConstView<S>& d_out, Matrix<S>* d_in) {
    detail::check_shape("nn::Dropout", "output gradient", d_out, in.rows(), in.cols());
    if (masked_) detail::check_shape("nn::Dropout", "input (the last forward's)", in, mask_.rows(), mask_.cols());
    if (!d_in) return;
    const Index R = in.rows();
    ensure_shape(*d_in, R, in.cols());
    const Index nc = exec::chunk_count(R, product_chunks), workers = exec::worker_count(policy, nc);
    exec::for_chunks(policy, R, nc, workers, [&](Index, Index, Index b, Index e) {
      if (masked_)
        d_in->middleRows(b, e - b) = d_out.middleRows(b, e - b).cwiseProduct(mask_.middleRows(b, e - b));
      else
        d_in->middleRows(b, e - b) = d_out.middleRows(b, e - b);
    });
  }

 private:
  double p_;
  Rng rng_;
  const BatchSplit* split_ = nullptr;
  bool masked_ = false;
  Matrix<S> mask_;
};
static_assert(assert_layer<Dropout<float>>());

}  // namespace simsr::nn
