#pragma once
/// \file
/// The official data normalization (dataset.py; SPEC §7): positions are parsed to S, then
/// (x − μ)/σ in S; the network's inputs and targets are normalized positions minus the normalized
/// rest shape; a predicted displacement goes back to mesh units by σ alone (the mean cancels).
///
///     const nn::Matrix<float> lr0 = nn::normalize_positions<float>(lr_rest, mu, sigma);   // once
///     nn::normalized_displacements(frame, lr0, mu, sigma, ldx.middleRows(f * N, N));      // per frame, in place

#include "tensor.hpp"

namespace simsr::nn {

/// (x − μ)/σ per entry, in S after casting x to S (the official float32 order of operations).
template <class S, class D>
Matrix<S> normalize_positions(const Eigen::MatrixBase<D>& X, double mean, double std_dev) {
  const S mu = static_cast<S>(mean), sigma = static_cast<S>(std_dev);
  Matrix<S> out(X.rows(), X.cols());
  for (Index r = 0; r < X.rows(); ++r)
    for (Index c = 0; c < X.cols(); ++c) out(r, c) = (static_cast<S>(X(r, c)) - mu) / sigma;
  return out;
}

/// out = normalize_positions(positions) − rest_normalized, written in place (no temporary), with
/// the same rounding as computing the two terms first. ShapeError when the shapes differ.
template <class DP, class DR, class DO>
void normalized_displacements(const Eigen::MatrixBase<DP>& positions, const Eigen::MatrixBase<DR>& rest_normalized, double mean,
                              double std_dev, Eigen::MatrixBase<DO> const& out_) {
  using S = typename DO::Scalar;
  auto& out = const_cast<Eigen::MatrixBase<DO>&>(out_);  // Eigen's idiom for writable block arguments
  detail::check_shape("nn::normalized_displacements", "positions", positions, rest_normalized.rows(), rest_normalized.cols());
  detail::check_shape("nn::normalized_displacements", "output", out, rest_normalized.rows(), rest_normalized.cols());
  const S mu = static_cast<S>(mean), sigma = static_cast<S>(std_dev);
  for (Index r = 0; r < positions.rows(); ++r)
    for (Index c = 0; c < positions.cols(); ++c) out(r, c) = (static_cast<S>(positions(r, c)) - mu) / sigma - rest_normalized(r, c);
}

}  // namespace simsr::nn
