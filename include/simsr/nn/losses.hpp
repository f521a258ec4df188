#pragma once
/// \file
/// Scalar losses with their gradients (SPEC §7 training loss): L1 reconstruction mean|a − b|, the
/// latent regularizers mean|z| (SPEC) and mean z² (what the reference's model.py computes:
/// `(self.z**2).mean()`). Sums run in double over fixed chunks: seq and omp agree bit for bit.
///
///     double l = nn::l1_loss(exec::omp, pred, target, &d_pred, 10.0);  // d_pred = 10·∂l/∂pred

#include <cmath>

#include "tensor.hpp"

namespace simsr::nn {

namespace detail {
/// Σ_i term(i) over the n = rows·cols entries (row-major index), and d[i] = scale·grad(i)/n.
template <class Policy, class S, class Term, class Grad>
double mean_and_gradient(Policy policy, Index rows, Index cols, Matrix<S>* d, double scale, Term&& term, Grad&& grad) {
  const Index n = rows * cols;
  if (n == 0) throw ArgumentError("nn loss: the input is empty");
  if (d) ensure_shape(*d, rows, cols);
  const Index nc = exec::chunk_count(n, exec::default_chunks), workers = exec::worker_count(policy, nc);
  double parts[exec::default_chunks];
  const S g = static_cast<S>(scale / double(n));
  exec::for_chunks(policy, n, nc, workers, [&](Index, Index c, Index b, Index e) {
    double s = 0;
    for (Index i = b; i < e; ++i) {
      s += term(i / cols, i % cols);
      if (d) d->data()[i] = g * grad(i / cols, i % cols);
    }
    parts[c] = s;
  });
  double total = 0;
  for (Index c = 0; c < nc; ++c) total += parts[c];
  return total / double(n);
}
template <class S>
S sign(S x) {
  return S((x > S(0)) - (x < S(0)));
}
}  // namespace detail

/// mean |a − b| over all entries (PyTorch's L1Loss, reduction mean); with `d_a`, writes
/// d_a = scale·sign(a − b)/n (sign 0 at equality, as PyTorch). ShapeError when shapes differ.
template <exec::HostPolicy Policy, class DA, class DB>
typename DA::Scalar l1_loss(Policy policy, const Eigen::MatrixBase<DA>& a, const Eigen::MatrixBase<DB>& b,
                            Matrix<typename DA::Scalar>* d_a = nullptr, double scale = 1.0) {
  using S = typename DA::Scalar;
  detail::check_shape("nn::l1_loss", "target", b, a.rows(), a.cols());
  return static_cast<S>(detail::mean_and_gradient<Policy, S>(
      policy, a.rows(), a.cols(), d_a, scale, [&](Index r, Index c) { return std::abs(double(a(r, c)) - double(b(r, c))); },
      [&](Index r, Index c) { return detail::sign<S>(a(r, c) - b(r, c)); }));
}

/// mean |z| (SPEC §7's latent regularizer); d_z = scale·sign(z)/n.
template <exec::HostPolicy Policy, class D>
typename D::Scalar mean_abs(Policy policy, const Eigen::MatrixBase<D>& z, Matrix<typename D::Scalar>* d_z = nullptr, double scale = 1.0) {
  using S = typename D::Scalar;
  return static_cast<S>(detail::mean_and_gradient<Policy, S>(
      policy, z.rows(), z.cols(), d_z, scale, [&](Index r, Index c) { return std::abs(double(z(r, c))); },
      [&](Index r, Index c) { return detail::sign<S>(z(r, c)); }));
}

/// mean z² (the reference implementation's z_reg); d_z = scale·2z/n.
template <exec::HostPolicy Policy, class D>
typename D::Scalar mean_square(Policy policy, const Eigen::MatrixBase<D>& z, Matrix<typename D::Scalar>* d_z = nullptr, double scale = 1.0) {
  using S = typename D::Scalar;
  return static_cast<S>(detail::mean_and_gradient<Policy, S>(
      policy, z.rows(), z.cols(), d_z, scale, [&](Index r, Index c) { return double(z(r, c)) * double(z(r, c)); },
      [&](Index r, Index c) { return S(2) * z(r, c); }));
}

}  // namespace simsr::nn
