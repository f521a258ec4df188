#pragma once
/// \file
/// The body of Embedded::apply, one functor for exec::seq, exec::omp (host arrays, any Eigen
/// matrix through EigenAccess) and exec::cuda (device arrays through MatrixSpan: DeviceEmbedded).

#include "../../core/device_buffer.hpp"
#include "../../core/host_device.hpp"
#include "../../core/types.hpp"

namespace simsr::interp::detail {

/// out(q, ·) = Σ_k w_qk · in(id_qk, ·) over the 4 vertices of HR vertex q's tet (weights and ids
/// row-major M×4). In and Out: anything with (row, col) access (MatrixSpan on a device).
template <class S, class In, class Out>
struct EmbeddedApply {
  const S* weights;
  const VIndex* ids;
  In in;
  Out out;
#if defined(__CUDACC__)
#pragma nv_exec_check_disable
#endif
  SIMSR_HOST_DEVICE void operator()(Index q) const {
    for (int d = 0; d < 3; ++d) {
      S x = S(0);
      for (int k = 0; k < 4; ++k) x += weights[4 * q + k] * S(in(ids[4 * q + k], d));
      out(q, d) = x;
    }
  }
};

/// (row, col) access to an Eigen matrix or expression on the host (the body's In / Out there).
template <class M>
struct EigenAccess {
  M* m;
  decltype(auto) operator()(Index r, Index c) const { return (*m)(r, c); }
};

}  // namespace simsr::interp::detail
