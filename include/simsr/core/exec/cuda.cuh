#pragma once
/// \file
/// CUDA backend (compiled by nvcc only; parallel.hpp includes it under __CUDACC__). Bodies must be
/// SIMSR_HOST_DEVICE functors or `__device__` lambdas (nvcc --extended-lambda) and touch only
/// device-visible memory. Errors from the launch are thrown as simsr::Error on the host.

#if !defined(__CUDACC__)
#error "simsr/core/exec/cuda.cuh must be compiled by nvcc (include simsr/core/parallel.hpp instead)"
#endif

#include <cuda_runtime.h>
#include <thrust/execution_policy.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/transform_reduce.h>

#include <string>

#include "../error.hpp"
#include "chunks.hpp"
#include "policy.hpp"

namespace simsr::exec {

namespace detail {
inline void cuda_check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) throw Error(std::string("simsr::exec::cuda: ") + what + ": " + cudaGetErrorString(status));
}

template <class Body>
__global__ void parallel_for_kernel(Index n, Body body) {
  for (Index i = Index(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += Index(blockDim.x) * gridDim.x) body(i);
}
}  // namespace detail

/// Calls `body(i)` for i = 0..n-1 on the current device (grid-stride loop), then synchronizes.
template <class Body>
void parallel_for(cuda_t, Index n, Body body) {
  if (n <= 0) return;
  constexpr int block = 256;
  const Index wanted = (n + block - 1) / block;
  const unsigned grid = static_cast<unsigned>(wanted < 65535 ? wanted : 65535);
  detail::parallel_for_kernel<<<grid, block>>>(n, body);
  detail::cuda_check(cudaGetLastError(), "kernel launch");
  detail::cuda_check(cudaDeviceSynchronize(), "kernel execution");
}

/// Reduction on the device with Thrust. Same contract as the host overloads; the combination
/// order is Thrust's, so results agree with seq up to rounding only.
template <class T, class Map, class Combine>
T parallel_reduce(cuda_t, Index n, T identity, Map map, Combine combine, Index /*chunks*/ = default_chunks) {
  return thrust::transform_reduce(thrust::device, thrust::counting_iterator<Index>(0), thrust::counting_iterator<Index>(n),
                                  map, identity, combine);
}

/// Per-chunk host accumulators do not exist on a device: use parallel_for with atomicAdd there.
template <class Make, class Body, class Merge>
auto parallel_for_accumulate(cuda_t, Index, Make&& make, Body&&, Merge&&, Index = 16) {
  static_assert(detail::dependent_false<Make>,
                "simsr::exec::cuda has no parallel_for_accumulate: accumulate with parallel_for and atomicAdd on device memory");
  return make();
}

}  // namespace simsr::exec
