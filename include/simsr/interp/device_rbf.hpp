#pragma once
/// \file
/// RBF's device twin for exec::cuda (nvcc only), for an RBF whose fit formed the M×N evaluation
/// operator (RBFFitInfo::precomputed_operator, the dense path within max_operator_bytes): the
/// operator copied into a device buffer it owns and RBF::apply's own body
/// (detail::DenseOperatorRow) launched on the device. Without the operator apply solves with an
/// LU or LDLᵀ factor per frame, host code: ArgumentError.
///
///     interp::RBF<float> rbf;  rbf.fit(exec::omp, problem);              // on the host
///     auto d = interp::to_device(rbf);                                    // DeviceRbf<float>
///     d.apply(exec::cuda, lr_span, hr_span);   // MatrixSpan<const float> N×3, MatrixSpan<float> M×3, device memory

#include "../core/device_buffer.hpp"
#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "detail/kernel.hpp"
#include "rbf.hpp"

#if defined(__CUDACC__)
namespace simsr::interp {

/// See the file comment. Move-only (it owns device memory).
template <class S>
class DeviceRbf {
 public:
  explicit DeviceRbf(const RBF<S>& host) : op_(checked_operator(host)), num_lr_(host.num_lr()), num_hr_(host.num_hr()) {}

  /// hr = the operator times lr: row-major device arrays, N×3 and M×3 (ShapeError otherwise).
  void apply(exec::cuda_t policy, MatrixSpan<const S> lr, MatrixSpan<S> hr) const {
    detail::check_apply_spans("DeviceRbf::apply", num_lr_, num_hr_, lr, hr);
    exec::parallel_for(policy, num_hr_, detail::DenseOperatorRow<S>{op_.span().data, num_lr_, lr, hr});
  }
  Index num_lr() const { return num_lr_; }
  Index num_hr() const { return num_hr_; }

 private:
  static DeviceBuffer<S> checked_operator(const RBF<S>& host) {
    if (!host.info().precomputed_operator)
      throw ArgumentError("DeviceRbf: this RBF keeps its factor and solves per frame (host code); fit it with the dense path within "
                          "max_operator_bytes to form the M×N operator");
    const auto& A = host.evaluation_operator();
    return DeviceBuffer<S>(Span<const S>{A.data(), A.size()});
  }
  DeviceBuffer<S> op_;
  Index num_lr_, num_hr_;
};

/// The device twin of a fitted RBF with a precomputed operator.
template <class S>
DeviceRbf<S> to_device(const RBF<S>& host) {
  return DeviceRbf<S>(host);
}

}  // namespace simsr::interp
#endif
