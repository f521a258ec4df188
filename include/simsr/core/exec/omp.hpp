#pragma once
/// \file
/// OpenMP backend. Needs simsr::openmp (-fopenmp); without it, instantiating an omp algorithm is a
/// static_assert that says so. Exceptions thrown by a body are caught in the worker and the first
/// one is rethrown on the calling thread (an exception escaping an OpenMP region would terminate).
/// Eigen stays single-threaded inside these regions (it checks omp_get_num_threads() > 1), so
/// there is no nested parallelism.

#include <exception>
#include <mutex>
#include <utility>
#include <vector>

#include "chunks.hpp"
#include "policy.hpp"

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace simsr::exec {

namespace detail {
/// Remembers the first exception thrown by any worker.
class FirstException {
 public:
  template <class F>
  void run(F&& f) noexcept {
    try {
      f();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!first_) first_ = std::current_exception();
    }
  }
  void rethrow() const {
    if (first_) std::rethrow_exception(first_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr first_;
};

}  // namespace detail

/// static_assert text for omp algorithms instantiated without OpenMP.
#define SIMSR_OMP_MISSING                                                                               \
  "simsr::exec::omp needs OpenMP: link the simsr::openmp target (find_package(simsr CONFIG COMPONENTS "     \
  "openmp)) or compile with -fopenmp, or use exec::seq"

/// Number of threads an omp region would use here (1 without OpenMP).
inline int omp_max_threads() {
#if defined(_OPENMP)
  return omp_get_max_threads();
#else
  return 1;
#endif
}

/// Calls `body(i)` for i = 0..n-1 on OpenMP threads (static schedule).
template <class Body>
void parallel_for(omp_t, Index n, Body&& body) {
#if defined(_OPENMP)
  detail::FirstException error;
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < n; ++i) error.run([&] { body(i); });
  error.rethrow();
#else
  static_assert(detail::dependent_false<Body>, SIMSR_OMP_MISSING);
#endif
}

/// Same contract and the same rounding as the seq overload: chunks run in parallel, then their
/// results are combined in chunk order on the calling thread.
template <class T, class Map, class Combine>
T parallel_reduce(omp_t, Index n, T identity, Map&& map, Combine&& combine, Index chunks = default_chunks) {
#if defined(_OPENMP)
  const Index nc = chunk_count(n, chunks);
  std::vector<T> parts(static_cast<std::size_t>(nc), identity);
  detail::FirstException error;
#pragma omp parallel for schedule(dynamic, 1)
  for (Index c = 0; c < nc; ++c) {
    error.run([&] {
      auto [b, e] = chunk_range(n, nc, c);
      T part = identity;
      for (Index i = b; i < e; ++i) part = combine(part, map(i));
      parts[static_cast<std::size_t>(c)] = std::move(part);
    });
  }
  error.rethrow();
  T total = identity;
  for (auto& p : parts) total = combine(total, p);
  return total;
#else
  static_assert(detail::dependent_false<Map>, SIMSR_OMP_MISSING);
  return identity;
#endif
}

/// Same contract and result as the seq overload; chunks fill their own accumulators in parallel
/// and are merged in chunk order afterwards.
template <class Make, class Body, class Merge>
auto parallel_for_accumulate(omp_t, Index n, Make&& make, Body&& body, Merge&& merge, Index chunks = 16) {
#if defined(_OPENMP)
  const Index nc = chunk_count(n, chunks);
  using Acc = decltype(make());
  std::vector<Acc> accs;
  accs.reserve(static_cast<std::size_t>(nc));
  for (Index c = 0; c < nc; ++c) accs.push_back(make());
  detail::FirstException error;
#pragma omp parallel for schedule(dynamic, 1)
  for (Index c = 0; c < nc; ++c) {
    error.run([&] {
      auto [b, e] = chunk_range(n, nc, c);
      for (Index i = b; i < e; ++i) body(i, accs[static_cast<std::size_t>(c)]);
    });
  }
  error.rethrow();
  Acc total = std::move(accs[0]);
  for (Index c = 1; c < nc; ++c) merge(total, std::move(accs[static_cast<std::size_t>(c)]));
  return total;
#else
  static_assert(detail::dependent_false<Make>, SIMSR_OMP_MISSING);
  return make();
#endif
}

}  // namespace simsr::exec
