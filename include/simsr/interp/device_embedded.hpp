#pragma once
/// \file
/// Embedded's device twin for exec::cuda (nvcc only): the fitted weights and tet vertex ids
/// copied into device buffers it owns, and Embedded::apply's own body (detail::EmbeddedApply)
/// launched on the device over device arrays.
///
///     interp::Embedded<float> e;  e.fit(exec::omp, problem);            // on the host
///     auto d = interp::to_device(e);                                     // DeviceEmbedded<float>
///     d.apply(exec::cuda, lr_span, hr_span);   // MatrixSpan<const float> N×3, MatrixSpan<float> M×3, device memory

#include "../core/device_buffer.hpp"
#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "detail/kernel.hpp"
#include "detail/embedded_apply.hpp"
#include "embedded.hpp"

#if defined(__CUDACC__)
namespace simsr::interp {

/// See the file comment. Move-only (it owns device memory).
template <class S>
class DeviceEmbedded {
 public:
  explicit DeviceEmbedded(const Embedded<S>& host)
      : weights_(Span<const S>{host.embedding().weights.data(), 4 * host.num_hr()}),
        ids_(Span<const VIndex>{host.lr_vertex_ids().data(), 4 * host.num_hr()}),
        num_lr_(host.num_lr()),
        num_hr_(host.num_hr()) {}

  /// hr = the embedding of lr: both row-major device arrays, N×3 and M×3 (ShapeError otherwise).
  void apply(exec::cuda_t policy, MatrixSpan<const S> lr, MatrixSpan<S> hr) const {
    detail::check_apply_spans("DeviceEmbedded::apply", num_lr_, num_hr_, lr, hr);
    exec::parallel_for(policy, num_hr_, detail::EmbeddedApply<S, MatrixSpan<const S>, MatrixSpan<S>>{weights_.span().data, ids_.span().data, lr, hr});
  }
  Index num_lr() const { return num_lr_; }
  Index num_hr() const { return num_hr_; }

 private:
  DeviceBuffer<S> weights_;
  DeviceBuffer<VIndex> ids_;
  Index num_lr_, num_hr_;
};

/// The device twin of a fitted Embedded.
template <class S>
DeviceEmbedded<S> to_device(const Embedded<S>& host) {
  return DeviceEmbedded<S>(host);
}

}  // namespace simsr::interp
#endif
