#pragma once
/// \file
/// NeighborUpsample's device twin for exec::cuda (nvcc only): the neighbour indices and the
/// precomputed inference weights copied into device buffers it owns, and NeighborUpsample::apply's
/// own body (detail::UpsampleGather) launched on the device over device arrays, one entry per
/// thread (UpsampleGather::entry: coalesced reads of z).
///
///     nn::NeighborUpsample<float> up(up_indices, N);                    // on the host
///     nn::NeighborUpsample<float>::softmax_rows(exec::omp, logits, w);   // M×upK (or B·M×upK)
///     auto d = nn::to_device(up, w);                                     // DeviceNeighborUpsample<float>
///     d.apply(exec::cuda, z_span, out_span);   // MatrixSpan<const float> (B·N)×C, MatrixSpan<float> (B·M)×C, device memory

#include <string>
#include <type_traits>

#include "../core/device_buffer.hpp"
#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "detail/neighbor_gather.hpp"
#include "neighbor_upsample.hpp"

#if defined(__CUDACC__)
namespace simsr::nn {

/// See the file comment. Move-only (it owns device memory). The weights are fixed at construction
/// (inference: they depend on rest shapes only); per-item weights (B·M rows) fix B as well.
template <class S>
class DeviceNeighborUpsample {
 public:
  /// weights: M×upK (shared by every item) or (B·M)×upK, as NeighborUpsample::apply takes them;
  /// ShapeError otherwise.
  DeviceNeighborUpsample(const NeighborUpsample<S>& host, const ConstView<S>& weights)
      : weights_(checked_weights(host, weights)),
        idx_(Span<const VIndex>{host.indices().data(), host.indices().size()}),
        m_(host.hr_points()),
        n_(host.lr_points()),
        k_(host.neighbors()),
        weight_rows_(weights.rows()) {}

  /// out = the gather of z with the weights: row-major device arrays, z (B·N)×C and out (B·M)×C.
  /// ShapeError for z or weights that NeighborUpsample::apply would refuse and for an `out` of
  /// another shape (on the host apply resizes it; device memory is the caller's), ArgumentError
  /// for a row stride below the columns.
  void apply(exec::cuda_t policy, MatrixSpan<const S> z, MatrixSpan<S> out) const {
    if (z.rows % n_ || z.cols < 1)
      throw ShapeError("nn::DeviceNeighborUpsample::apply: LR codes (B·" + std::to_string(n_) + " rows)", {-1, z.cols}, {z.rows, z.cols});
    const Index B = z.rows / n_;
    if (weight_rows_ != m_ && weight_rows_ != B * m_)
      throw ShapeError("nn::DeviceNeighborUpsample::apply: weights (M or B·M rows, B = " + std::to_string(B) + ")", {B * m_, k_},
                       {weight_rows_, k_});
    if (out.rows != B * m_ || out.cols != z.cols)
      throw ShapeError("nn::DeviceNeighborUpsample::apply: output (B·M rows)", {B * m_, z.cols}, {out.rows, out.cols});
    if (z.stride < z.cols || out.stride < out.cols)
      throw ArgumentError("nn::DeviceNeighborUpsample::apply: row strides " + std::to_string(z.stride) + " (LR codes) and " +
                          std::to_string(out.stride) + " (output) for " + std::to_string(z.cols) + " columns");
    exec::parallel_for(policy, B * m_ * z.cols,
                       detail::UpsampleGatherEntries<S>{{idx_.span().data, m_, n_, {weights_.span().data, weight_rows_, k_, k_}, z, out, 0}});
  }
  Index hr_points() const { return m_; }
  Index lr_points() const { return n_; }
  Index neighbors() const { return k_; }
  /// M (shared weights) or B·M (per item).
  Index weight_rows() const { return weight_rows_; }

 private:
  /// The weights as one contiguous device array, after the shape check.
  static DeviceBuffer<S> checked_weights(const NeighborUpsample<S>& host, const ConstView<S>& weights) {
    const Index M = host.hr_points(), K = host.neighbors();
    if (weights.cols() != K || weights.rows() < M || weights.rows() % M)
      throw ShapeError("nn::DeviceNeighborUpsample: weights (M or B·M rows)", {M, K}, {weights.rows(), weights.cols()});
    const Matrix<S> packed = weights;  // a column block has a row stride of its own
    return DeviceBuffer<S>(Span<const S>{packed.data(), packed.size()});
  }

  DeviceBuffer<S> weights_;  // first: checked before anything is allocated
  DeviceBuffer<VIndex> idx_;
  Index m_, n_, k_, weight_rows_;
};

/// The device twin of `host` with its inference weights (M×upK or B·M×upK; ShapeError otherwise).
template <class S>
DeviceNeighborUpsample<S> to_device(const NeighborUpsample<S>& host, const std::type_identity_t<ConstView<S>>& weights) {
  return DeviceNeighborUpsample<S>(host, weights);
}

}  // namespace simsr::nn
#endif
