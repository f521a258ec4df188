#pragma once
/// \file
/// BlockCsr's device twin for exec::cuda (nvcc only): the block pattern and values copied into
/// device buffers it owns, and BlockCsr::multiply's own body (detail::BlockCsrProduct) launched on
/// the device over device vectors.
///
///     physics::BlockCsr<double> A;  A.assign(exec::omp, csr);   // on the host
///     auto dA = physics::to_device(A);                          // DeviceBlockCsr<double>
///     dA.multiply(exec::cuda, x_span, y_span);                  // device vectors of 3·n

#include "../../core/device_buffer.hpp"
#include "../../core/error.hpp"
#include "../../core/parallel.hpp"
#include "block_csr.hpp"

#if defined(__CUDACC__)
namespace simsr::physics {

/// See the file comment. Move-only (it owns device memory). values() re-copies new values of the
/// same pattern (a Newton iteration's matrix).
template <class S, class Value = S>
class DeviceBlockCsr {
 public:
  explicit DeviceBlockCsr(const BlockCsr<S, Value>& host)
      : outer_(Span<const int>{host.block_outer(), host.rows() / 3 + 1}),
        inner_(Span<const int>{host.block_inner(), host.num_blocks()}),
        values_(Span<const Value>{host.block_values(), 9 * host.num_blocks()}),
        rows_(host.rows()),
        cols_(host.cols()) {}

  /// New values of the same pattern from the host copy (ShapeError if the pattern's size changed).
  void values(const BlockCsr<S, Value>& host) { values_.copy_from(Span<const Value>{host.block_values(), 9 * host.num_blocks()}); }

  /// y = A x, device vectors of cols() and rows() entries (ShapeError otherwise).
  void multiply(exec::cuda_t policy, Span<const S> x, Span<S> y) const {
    if (x.size != cols_) throw ShapeError("DeviceBlockCsr::multiply: x", {cols_}, {x.size});
    if (y.size != rows_) throw ShapeError("DeviceBlockCsr::multiply: y", {rows_}, {y.size});
    exec::parallel_for(policy, rows_ / 3, detail::BlockCsrProduct<S, Value>{outer_.span().data, inner_.span().data, values_.span().data, x.data, y.data});
  }
  Index rows() const { return rows_; }
  Index cols() const { return cols_; }

 private:
  DeviceBuffer<int> outer_, inner_;
  DeviceBuffer<Value> values_;
  Index rows_, cols_;
};

/// The device twin of an assigned BlockCsr.
template <class S, class Value>
DeviceBlockCsr<S, Value> to_device(const BlockCsr<S, Value>& host) {
  return DeviceBlockCsr<S, Value>(host);
}

}  // namespace simsr::physics
#endif
