#pragma once
/// \file
/// Parallel primitives under every execution policy:
///
///     parallel_for(exec::omp, n, [&](Index i) { y[i] = 2 * x[i]; });
///     double s = parallel_reduce(exec::seq, n, 0.0, [&](Index i) { return x[i]; }, std::plus<>{});
///     auto g = parallel_for_accumulate(exec::omp, nt, make_zero_gradient, add_tet_gradient, add);
///
/// seq and omp give bitwise-identical results (fixed chunking); cuda is available under nvcc.

#include <algorithm>
#include <type_traits>

#include "exec/omp.hpp"
#include "exec/omp_threads.hpp"
#include "exec/policy.hpp"
#include "exec/seq.hpp"

#if defined(__CUDACC__)
#include "exec/cuda.cuh"
#else
namespace simsr::exec {
/// Host compilers: the cuda policy exists as a type, but running with it needs nvcc.
template <class Body>
void parallel_for(cuda_t, Index, Body&&) {
  static_assert(detail::dependent_false<Body>, "simsr::exec::cuda needs nvcc: compile this translation unit as CUDA (simsr::cuda target)");
}
template <class T, class Map, class Combine>
T parallel_reduce(cuda_t, Index, T identity, Map&&, Combine&&, Index = default_chunks) {
  static_assert(detail::dependent_false<Map>, "simsr::exec::cuda needs nvcc: compile this translation unit as CUDA (simsr::cuda target)");
  return identity;
}
template <class Make, class Body, class Merge>
auto parallel_for_accumulate(cuda_t, Index, Make&& make, Body&&, Merge&&, Index = 16) {
  static_assert(detail::dependent_false<Make>, "simsr::exec::cuda needs nvcc: compile this translation unit as CUDA (simsr::cuda target)");
  return make();
}
}  // namespace simsr::exec
#endif

namespace simsr::exec {

/// The policy comes first in every call: a primitive called with anything else there (the policy
/// last, as before issue #10, or none) stops the build with assert_execution_policy's sentence.
template <class NotAPolicy, class... Args>
  requires(!ExecutionPolicy<NotAPolicy>)
void parallel_for(NotAPolicy&&, Args&&...) {
  static_assert(assert_execution_policy<NotAPolicy>());
}
template <class NotAPolicy, class... Args>
  requires(!ExecutionPolicy<NotAPolicy>)
void parallel_reduce(NotAPolicy&&, Args&&...) {
  static_assert(assert_execution_policy<NotAPolicy>());
}
template <class NotAPolicy, class... Args>
  requires(!ExecutionPolicy<NotAPolicy>)
void parallel_for_accumulate(NotAPolicy&&, Args&&...) {
  static_assert(assert_execution_policy<NotAPolicy>());
}

/// Workers a chunked loop uses under `policy` for `chunks` chunks: 1 under seq (no thread is
/// started), min(chunks, OpenMP threads) under omp.
template <ExecutionPolicy Policy>
Index worker_count(Policy, Index chunks) {
  if constexpr (std::is_same_v<std::remove_cvref_t<Policy>, omp_t>)
    return std::max<Index>(1, std::min<Index>(chunks, omp_max_threads()));
  else
    return 1;
}

/// Calls body(worker, chunk, begin, end) for each of the `chunks` ranges of [0, n) (chunk_range);
/// worker w takes chunks w, w + workers, … so per-worker scratch can be indexed by `worker`. A
/// chunk's arithmetic never depends on its worker: results are the same under seq and omp.
template <HostPolicy Policy, class Body>
void for_chunks(Policy policy, Index n, Index chunks, Index workers, Body&& body) {
  parallel_for(policy, workers, [&](Index w) {
    for (Index c = w; c < chunks; c += workers) {
      const auto [b, e] = chunk_range(n, chunks, c);
      body(w, c, b, e);
    }
  });
}

}  // namespace simsr::exec
