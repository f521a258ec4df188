#pragma once
/// \file
/// HostBuffer: DeviceBuffer's interface over host memory, so a component written once over a
/// buffer template (`template <class> class Memory`) runs its whole launch sequence under
/// exec::seq / exec::omp on the host (HostBuffer) and under exec::cuda on a device (DeviceBuffer):
/// the CPU tests then cover every body and every launch of the device path but the launch itself
/// (nn::InferenceNet is the first such component; README, "Execution policies: the cuda path").
///
///     simsr::HostBuffer<float> h(span_of(values));   // a host copy
///     h.copy_to(span_of(out));

#include <algorithm>
#include <string>
#include <type_traits>
#include <vector>

#include "device_buffer.hpp"
#include "error.hpp"
#include "exec/policy.hpp"
#include "types.hpp"

namespace simsr {

/// An owned host array with DeviceBuffer's interface (resize, copy_from, copy_to, span).
template <class T>
class HostBuffer {
  static_assert(std::is_trivially_copyable_v<T>, "simsr::HostBuffer holds trivially copyable elements only");

 public:
  HostBuffer() = default;
  explicit HostBuffer(Index n) { resize(n); }
  explicit HostBuffer(Span<const T> host) {
    resize(host.size);
    copy_from(host);
  }
  void resize(Index n) {
    if (n < 0) throw ArgumentError("HostBuffer: negative size " + std::to_string(n));
    values_.resize(std::size_t(n));
  }
  void copy_from(Span<const T> host) {
    if (host.size != size()) throw ShapeError("HostBuffer::copy_from", {size()}, {host.size});
    std::copy_n(host.data, host.size, values_.data());
  }
  void copy_to(Span<T> host) const {
    if (host.size != size()) throw ShapeError("HostBuffer::copy_to", {size()}, {host.size});
    std::copy_n(values_.data(), host.size, host.data);
  }
  /// Element i (ArgumentError outside [0, size)).
  T value_at(Index i) const {
    if (i < 0 || i >= size()) throw ArgumentError("HostBuffer::value_at: index " + std::to_string(i) + " of " + std::to_string(size()));
    return values_[std::size_t(i)];
  }
  Span<T> span() { return {values_.data(), size()}; }
  Span<const T> span() const { return {values_.data(), size()}; }
  Index size() const { return Index(values_.size()); }

 private:
  std::vector<T> values_;
};

/// Where a buffer template keeps its arrays, and so which policies may run bodies over them:
/// host memory takes exec::seq and exec::omp, device memory exec::cuda.
template <template <class> class Memory>
inline constexpr bool device_memory = false;
#if defined(__CUDACC__)
template <>
inline constexpr bool device_memory<DeviceBuffer> = true;
#endif

/// A policy that may run bodies over `Memory`'s arrays.
template <class Policy, template <class> class Memory>
concept PolicyFor = (device_memory<Memory> && std::same_as<std::remove_cvref_t<Policy>, exec::cuda_t>) || (!device_memory<Memory> && exec::HostPolicy<Policy>);

}  // namespace simsr
