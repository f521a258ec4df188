#pragma once
/// \file
/// The body of NeighborUpsample's inference gather, one functor for exec::seq, exec::omp (host
/// arrays: NeighborUpsample::apply and apply_rows) and exec::cuda (device arrays:
/// DeviceNeighborUpsample).

#include <Eigen/Core>

#include "../../core/device_buffer.hpp"
#include "../../core/host_device.hpp"
#include "../../core/types.hpp"

namespace simsr::nn::detail {

/// Output row r = b·M + j (HR vertex j of batch item b): out_r = Σ_i w_{j or r, i} z_{b·N + idx(j,i)},
/// each entry accumulated from 0 over i ascending: the arithmetic apply always had, so seq and
/// omp give the same bits and a device differs by its fused multiply-adds only. Two call forms
/// of that one sum: `operator()(r)` a whole row (the host: neighbours outer, columns inner, each
/// step an Eigen row update, vectorized at any optimization level), `entry(k)` the single entry
/// k = r·C + c (the device: one thread an entry, so a warp reads consecutive columns of one row of
/// z, coalesced). Weights M×upK are shared by every item, B·M×upK are one block per item (told
/// apart by their rows). Row r goes to row r − first of `out`, so a caller can take a range of
/// rows into a buffer of its own (apply_rows).
template <class S>
struct UpsampleGather {
  const VIndex* idx;             ///< M×upK neighbour indices, row-major, each in [0, N)
  Index hr_points, lr_points;    ///< M, N
  MatrixSpan<const S> weights;   ///< M×upK or (B·M)×upK
  MatrixSpan<const S> z;         ///< (B·N)×C LR codes
  MatrixSpan<S> out;             ///< rows [first, first + out.rows) of the (B·M)×C result
  Index first = 0;

  /// Row r, every column.
  SIMSR_HOST_DEVICE void operator()(Index r) const {
    const Index K = weights.cols, C = z.cols;
    S* o = out.data + (r - first) * out.stride;
    for (Index c = 0; c < C; ++c) o[c] = S(0);
    for (Index i = 0; i < K; ++i) {
      const S wi = weight(r, i);
      const S* zr = code(r, i);
#if defined(__CUDA_ARCH__)
      for (Index c = 0; c < C; ++c) o[c] += wi * zr[c];
#else
      Eigen::Map<Eigen::Matrix<S, 1, Eigen::Dynamic>>(o, C) += wi * Eigen::Map<const Eigen::Matrix<S, 1, Eigen::Dynamic>>(zr, C);
#endif
    }
  }

  /// Entry k = r·C + c alone: the same sum, in the same order.
  SIMSR_HOST_DEVICE void entry(Index k) const {
    const Index K = weights.cols, C = z.cols, r = k / C, c = k % C;
    S sum = S(0);
    for (Index i = 0; i < K; ++i) sum += weight(r, i) * code(r, i)[c];
    out.data[(r - first) * out.stride + c] = sum;
  }

 private:
  SIMSR_HOST_DEVICE S weight(Index r, Index i) const {
    const Index M = hr_points;
    return weights.data[(weights.rows == M ? r % M : r) * weights.stride + i];
  }
  /// Row of z holding neighbour i of output row r.
  SIMSR_HOST_DEVICE const S* code(Index r, Index i) const {
    const Index M = hr_points, item = r / M, j = r % M;
    return z.data + (item * lr_points + idx[j * weights.cols + i]) * z.stride;
  }
};

/// UpsampleGather's entries as a body of its own (one index an entry: the device's launch).
template <class S>
struct UpsampleGatherEntries {
  UpsampleGather<S> gather;
  SIMSR_HOST_DEVICE void operator()(Index k) const { gather.entry(k); }
};

}  // namespace simsr::nn::detail
