#pragma once
/// \file
/// LocalLinear's device twin for exec::cuda (nvcc only): the trained per-vertex 3×3 maps and
/// neighbour ids copied into device buffers it owns, and LocalLinear::apply's own body
/// (detail::LocalLinearRow) launched on the device.
///
///     interp::LocalLinear<float> ll;  ll.fit(…); ll.train(…);             // on the host
///     auto d = interp::to_device(ll);                                      // DeviceLocalLinear<float>
///     d.apply(exec::cuda, lr_span, hr_span);   // MatrixSpan<const float> N×3, MatrixSpan<float> M×3, device memory

#include "../core/device_buffer.hpp"
#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "detail/kernel.hpp"
#include "local_linear.hpp"

#if defined(__CUDACC__)
namespace simsr::interp {

/// See the file comment. Move-only (it owns device memory).
template <class S>
class DeviceLocalLinear {
 public:
  /// ArgumentError for an untrained LocalLinear.
  explicit DeviceLocalLinear(const LocalLinear<S>& host)
      : indices_(checked_indices(host)),
        maps_(Span<const S>{host.vertex_maps().data(), host.vertex_maps().size()}),
        k_(host.neighbor_indices().cols()),
        num_lr_(host.num_lr()),
        num_hr_(host.num_hr()) {}

  /// hr = the local linear maps applied to lr: row-major device arrays, N×3 and M×3 (ShapeError otherwise).
  void apply(exec::cuda_t policy, MatrixSpan<const S> lr, MatrixSpan<S> hr) const {
    detail::check_apply_spans("DeviceLocalLinear::apply", num_lr_, num_hr_, lr, hr);
    exec::parallel_for(policy, num_hr_, detail::LocalLinearRow<S>{indices_.span().data, maps_.span().data, k_, lr, hr});
  }
  Index num_lr() const { return num_lr_; }
  Index num_hr() const { return num_hr_; }

 private:
  static DeviceBuffer<VIndex> checked_indices(const LocalLinear<S>& host) {
    if (!host.trained()) throw ArgumentError("DeviceLocalLinear: the LocalLinear is not trained");
    return DeviceBuffer<VIndex>(Span<const VIndex>{host.neighbor_indices().data(), host.neighbor_indices().size()});
  }
  DeviceBuffer<VIndex> indices_;  // first: the training checked before anything else is copied
  DeviceBuffer<S> maps_;
  Index k_, num_lr_, num_hr_;
};

/// The device twin of a trained LocalLinear.
template <class S>
DeviceLocalLinear<S> to_device(const LocalLinear<S>& host) {
  return DeviceLocalLinear<S>(host);
}

}  // namespace simsr::interp
#endif
