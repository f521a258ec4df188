#pragma once
/// \file
/// Where a kernel's data live, for the bodies that run unchanged under exec::seq, exec::omp and
/// exec::cuda (README, "Execution policies: the cuda path").
///
/// The design: a component (an interpolator, a block matrix) keeps its data on the host, where
/// fit/assign build them, and runs its kernel body there under seq and omp. `to_device(component)`
/// gives the component's device twin: the same arrays copied into `DeviceBuffer`s it owns, and
/// the same body launched under exec::cuda. A body reads its arrays through `Span`s (a pointer and
/// a length, trivially copyable, SIMSR_HOST_DEVICE), so one functor type serves both spaces.
///
///     simsr::DeviceBuffer<double> d(host_span);     // cudaMalloc + copy (nvcc only)
///     d.copy_to(host_vector);                        // back
///
/// DeviceBuffer exists only where nvcc compiles the file (__CUDACC__); Span and the host side
/// compile everywhere.

#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "error.hpp"
#include "host_device.hpp"
#include "types.hpp"

#if defined(__CUDACC__)
#include <cuda_runtime.h>
#endif

namespace simsr {

/// A pointer and a length: what a kernel body holds of an array (host or device memory alike).
template <class T>
struct Span {
  T* data = nullptr;
  Index size = 0;
  SIMSR_HOST_DEVICE T& operator[](Index i) const { return data[i]; }
  /// A read-only span of the same array.
  template <class U = T>
    requires(!std::is_const_v<U>)
  SIMSR_HOST_DEVICE operator Span<const U>() const {
    return {data, size};
  }
};

/// A row-major rows×cols view (row stride `stride`, unit column stride): the N×3 displacement
/// arrays of the interpolators, host or device memory.
template <class T>
struct MatrixSpan {
  T* data = nullptr;
  Index rows = 0, cols = 0, stride = 0;
  SIMSR_HOST_DEVICE T& operator()(Index r, Index c) const { return data[r * stride + c]; }
};

/// Span of a contiguous host container (std::vector, Eigen plain objects).
template <class C>
auto span_of(C& c) -> Span<std::remove_reference_t<decltype(*c.data())>> {
  return {c.data(), Index(c.size())};
}

#if defined(__CUDACC__)
/// An array in device memory, owned (cudaMalloc / cudaFree), copied from and to the host.
/// Errors of the CUDA runtime are simsr::Error naming the call.
template <class T>
class DeviceBuffer {
  static_assert(std::is_trivially_copyable_v<T>, "simsr::DeviceBuffer holds trivially copyable elements only");

 public:
  DeviceBuffer() = default;
  explicit DeviceBuffer(Index n) { resize(n); }
  /// A device copy of the host array.
  explicit DeviceBuffer(Span<const T> host) {
    resize(host.size);
    copy_from(host);
  }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& o) noexcept : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)) {}
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    if (this != &o) {
      release();
      data_ = std::exchange(o.data_, nullptr);
      size_ = std::exchange(o.size_, 0);
    }
    return *this;
  }
  ~DeviceBuffer() { release(); }

  void resize(Index n) {
    if (n < 0) throw ArgumentError("DeviceBuffer: negative size " + std::to_string(n));
    if (n == size_) return;
    release();
    if (n > 0) check(cudaMalloc(reinterpret_cast<void**>(&data_), std::size_t(n) * sizeof(T)), "cudaMalloc");
    size_ = n;
  }
  void copy_from(Span<const T> host) {
    if (host.size != size_) throw ShapeError("DeviceBuffer::copy_from", {size_}, {host.size});
    if (size_) check(cudaMemcpy(data_, host.data, std::size_t(size_) * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy to the device");
  }
  void copy_to(Span<T> host) const {
    if (host.size != size_) throw ShapeError("DeviceBuffer::copy_to", {size_}, {host.size});
    if (size_) check(cudaMemcpy(host.data, data_, std::size_t(size_) * sizeof(T), cudaMemcpyDeviceToHost), "cudaMemcpy to the host");
  }
  /// Element i copied to the host (a message's value; ArgumentError outside [0, size)).
  T value_at(Index i) const {
    if (i < 0 || i >= size_) throw ArgumentError("DeviceBuffer::value_at: index " + std::to_string(i) + " of " + std::to_string(size_));
    T v;
    check(cudaMemcpy(&v, data_ + i, sizeof(T), cudaMemcpyDeviceToHost), "cudaMemcpy to the host");
    return v;
  }
  Span<T> span() { return {data_, size_}; }
  Span<const T> span() const { return {data_, size_}; }
  Index size() const { return size_; }

 private:
  static void check(cudaError_t status, const char* what) {
    if (status != cudaSuccess) throw Error(std::string("simsr::DeviceBuffer: ") + what + ": " + cudaGetErrorString(status));
  }
  void release() noexcept {
    if (data_) cudaFree(data_);
    data_ = nullptr;
    size_ = 0;
  }
  T* data_ = nullptr;
  Index size_ = 0;
};
#endif

}  // namespace simsr
