#pragma once
/// \file
/// IDW's and MLS's device twin for exec::cuda (nvcc only): their fitted gather (M×k LR ids and
/// weights, one per neighbour or one per neighbour and component) copied into device buffers it
/// owns, and NeighborGather::apply's own body (detail::NeighborGatherRow) launched on the device.
///
///     interp::IDW<float> idw;  idw.fit(exec::omp, problem);              // on the host
///     auto d = interp::to_device(idw);                                    // DeviceNeighborGather<float>
///     d.apply(exec::cuda, lr_span, hr_span);   // MatrixSpan<const float> N×3, MatrixSpan<float> M×3, device memory

#include <string>

#include "../core/device_buffer.hpp"
#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "detail/kernel.hpp"
#include "idw.hpp"
#include "mls.hpp"

#if defined(__CUDACC__)
namespace simsr::interp {

/// See the file comment. Move-only (it owns device memory).
template <class S>
class DeviceNeighborGather {
 public:
  /// `num_lr`: N, the LR vertices the ids index (the fitted interpolator's num_lr()).
  DeviceNeighborGather(const detail::NeighborGather<S>& host, Index num_lr, std::string who)
      : indices_(Span<const VIndex>{host.indices.data(), host.indices.size()}),
        weights_(Span<const S>{host.weights.data(), host.weights.size()}),
        k_(host.k()),
        per_component_(host.per_component),
        num_lr_(num_lr),
        num_hr_(host.rows()),
        who_(std::move(who)) {}

  /// hr = the gather of lr: row-major device arrays, N×3 and M×3 (ShapeError otherwise).
  void apply(exec::cuda_t policy, MatrixSpan<const S> lr, MatrixSpan<S> hr) const {
    detail::check_apply_spans(who_ + "::apply", num_lr_, num_hr_, lr, hr);
    exec::parallel_for(policy, num_hr_, detail::NeighborGatherRow<S>{indices_.span().data, weights_.span().data, k_, per_component_, lr, hr});
  }
  Index num_lr() const { return num_lr_; }
  Index num_hr() const { return num_hr_; }

 private:
  DeviceBuffer<VIndex> indices_;
  DeviceBuffer<S> weights_;
  Index k_;
  bool per_component_;
  Index num_lr_, num_hr_;
  std::string who_;
};

/// The device twin of a fitted IDW.
template <class S>
DeviceNeighborGather<S> to_device(const IDW<S>& host) {
  return DeviceNeighborGather<S>(host.gather(), host.num_lr(), "DeviceNeighborGather (IDW)");
}
/// The device twin of a fitted MLS.
template <class S>
DeviceNeighborGather<S> to_device(const MLS<S>& host) {
  return DeviceNeighborGather<S>(host.gather(), host.num_lr(), "DeviceNeighborGather (MLS)");
}

}  // namespace simsr::interp
#endif
