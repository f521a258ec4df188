#pragma once
/// \file
/// The latent regularizer of the `paper` profile (paper Eq. 6): L_reg = Σ_s Σ_i ‖z̄_{s,i}‖₂, the
/// Euclidean norm of every point's feature vector summed over the points (and batch items) of
/// each intermediate feature block s, and its weight β, ramped from 0.001 to 20 during training
/// (paper Table 3: "gradually increased from 0.001 to 20").
///
///     nn::RampedWeight beta{0.001, 20, 50000, nn::RampedWeight::Kind::geometric};
///     double reg = 0;
///     for (auto& block : blocks)   // each (B·N)×C_s, or a column block of a wider activation
///       reg += nn::row_norm_sum(exec::omp, block.z, &block.d_z, beta.at(step));

#include <algorithm>
#include <cmath>
#include <string>

#include "tensor.hpp"

namespace simsr::nn {

/// Σ_r ‖z_r‖₂ over the rows of z (one row per point; Eq. 6 for one feature block), or that sum / rows
/// with `mean_over_rows`. With `d_z`, writes d_z = scale·∂/∂z, row r = scale·z_r/‖z_r‖ (/rows):
/// ‖·‖ is not differentiable at 0, and for a zero row we take the subgradient 0 (the minimal-norm
/// element of the unit ball, which is also what PyTorch's norm backward returns at 0). Norms and
/// the sum are in double over fixed row chunks: exec::seq and exec::omp agree bit for bit.
/// ArgumentError for an empty z; d_z is resized only when the shape changes (warm: no allocation).
/// z may be any matrix expression; a block of a row-major Matrix (ConstView) is read in place.
template <exec::HostPolicy Policy, class D>
double row_norm_sum(Policy policy, const Eigen::MatrixBase<D>& z, Matrix<typename D::Scalar>* d_z = nullptr, double scale = 1.0,
                    bool mean_over_rows = false) {
  using S = typename D::Scalar;
  const Index R = z.rows(), C = z.cols();
  if (R == 0 || C == 0)
    throw ArgumentError("nn::row_norm_sum: the features are empty (" + std::to_string(R) + "×" + std::to_string(C) + ")");
  if constexpr (requires { z.derived().data(); }) {
    const S* p = z.derived().data();
    if (d_z && p >= d_z->data() && p < d_z->data() + d_z->size())
      throw ArgumentError("nn::row_norm_sum: the gradient d_z must not alias z (z lies in d_z's storage)");
  }
  if (d_z) ensure_shape(*d_z, R, C);
  const double norm = mean_over_rows ? double(R) : 1.0, g_scale = scale / norm;
  const Index nc = exec::chunk_count(R, exec::default_chunks), workers = exec::worker_count(policy, nc);
  double parts[exec::default_chunks];
  exec::for_chunks(policy, R, nc, workers, [&](Index, Index c, Index b, Index e) {
    double s = 0;
    for (Index r = b; r < e; ++r) {
      double sq = 0;
      for (Index j = 0; j < C; ++j) sq += double(z(r, j)) * double(z(r, j));
      const double n = std::sqrt(sq);
      s += n;
      if (d_z) {
        const double g = n > 0 ? g_scale / n : 0.0;  // subgradient 0 at a zero row
        for (Index j = 0; j < C; ++j) (*d_z)(r, j) = static_cast<S>(g * double(z(r, j)));
      }
    }
    parts[c] = s;
  });
  double total = 0;
  for (Index c = 0; c < nc; ++c) total += parts[c];
  return total / norm;
}


/// A loss weight ramped from `start` (step 0) to `end` (step ≥ ramp_steps), then held: β of Eq. 6,
/// which the paper (Table 3) "gradually increased from 0.001 to 20" without saying how. Two
/// shapes are offered:
///  - linear:    start + (end − start)·t,
///  - geometric: start·(end/start)^t (equal factors per step: 0.001 → 20 spends as many steps in
///    each decade, where the linear ramp passes 0.001…0.2 within its first 1% of steps),
/// with t = step/ramp_steps clamped to [0, 1]. at(0) == start and at(step ≥ ramp_steps) == end
/// exactly; a decreasing ramp (start > end) is allowed. Members are plain so it aggregates:
/// RampedWeight{0.001, 20, 10000, RampedWeight::Kind::geometric} or RampedWeight{.ramp_steps = 10000}.
struct RampedWeight {
  enum class Kind { linear, geometric };

  double start = 0.001;
  double end = 20;
  long ramp_steps = 0;  ///< must be ≥ 1 (0, the default, is "not set" and rejected by at())
  Kind kind = Kind::linear;

  /// β at training step `step` ≥ 0. ArgumentError for a negative step, ramp_steps < 1, a negative
  /// or non-finite start or end, or a geometric ramp with start or end 0.
  double at(long step) const {
    check();
    if (step < 0) throw ArgumentError("nn::RampedWeight: step " + std::to_string(step) + " is negative");
    if (step == 0) return start;
    if (step >= ramp_steps) return end;
    const double t = double(step) / double(ramp_steps);
    if (kind == Kind::linear) return start + (end - start) * t;
    // clamped: exp/log rounding must not step outside [start, end] (monotone up to `end` exactly)
    return std::clamp(start * std::exp(t * std::log(end / start)), std::min(start, end), std::max(start, end));
  }

  /// ArgumentError unless the fields describe a ramp (called by at()).
  void check() const {
    if (!std::isfinite(start) || !std::isfinite(end) || start < 0 || end < 0)
      throw ArgumentError("nn::RampedWeight: start = " + std::to_string(start) + " and end = " + std::to_string(end) +
                          " must be finite and >= 0");
    if (ramp_steps < 1) throw ArgumentError("nn::RampedWeight: ramp_steps = " + std::to_string(ramp_steps) + " must be >= 1");
    if (kind == Kind::geometric && (start == 0 || end == 0))
      throw ArgumentError("nn::RampedWeight: a geometric ramp needs start > 0 and end > 0 (got " + std::to_string(start) + " → " +
                          std::to_string(end) + ")");
  }
};

}  // namespace simsr::nn
