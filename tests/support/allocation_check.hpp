#pragma once
// The "a warm call allocates nothing" check, for any test file (malloc_counter.hpp, which defines
// the counter, is included by one file per executable).
//
// Where OpenMP is LLVM's libomp (clang -fopenmp: the ASan and TSan builds, see tests/CMakeLists.txt)
// the runtime itself mallocs in every worksharing loop (2 blocks per thread per loop, measured with
// a bare `#pragma omp for`), so an exec::omp call's count there measures libomp, not simsr: it is
// printed, not checked. exec::seq calls are checked in the normal and ASan builds, and exec::omp
// calls in the normal build (GCC's libgomp, which allocates nothing once its team is warm). Under
// TSan nothing is counted: its allocation hook misses allocations (measured: a 7×9 Eigen matrix and
// a std::vector<int>(100) counted as one), and the TSan build looks for races only.
#include <doctest/doctest.h>

#include <type_traits>

#include "simsr/core/exec/policy.hpp"

long simsr_test_malloc_count();

#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define SIMSR_TEST_THREAD_SANITIZER 1
#endif
#endif
#if !defined(SIMSR_TEST_THREAD_SANITIZER) && defined(__SANITIZE_THREAD__)
#define SIMSR_TEST_THREAD_SANITIZER 1
#endif

namespace simsr::test {

/// Makes p escape (a store to a volatile global), so the optimizer keeps the allocation behind
/// it: C++ lets a compiler elide a new/delete pair whose memory is never used ([expr.new]), and
/// clang -O1 does so for a buffer of which only the size is read (the malloc counter's own
/// checks then saw one allocation of two).
inline const void* volatile escape_sink = nullptr;
inline void escape(const void* p) { escape_sink = p; }

#if defined(SIMSR_TEST_THREAD_SANITIZER)
inline constexpr bool allocations_counted = false;
#else
inline constexpr bool allocations_counted = true;
#endif

#if defined(__clang__) && defined(_OPENMP)
inline constexpr bool omp_runtime_allocates = true;
#else
inline constexpr bool omp_runtime_allocates = false;
#endif

/// Whether a call made under `Policy` can be held to zero allocations in this build.
template <class Policy>
inline constexpr bool allocations_checked_under =
    allocations_counted && !(omp_runtime_allocates && std::is_same_v<std::remove_cvref_t<Policy>, simsr::exec::omp_t>);

}  // namespace simsr::test

/// CHECK that `count` allocations (made by warm calls under `policy`) is zero, where this build
/// can tell (see above); otherwise a MESSAGE with the count.
#define SIMSR_CHECK_NO_ALLOCATION(policy, count)                                                            \
  do {                                                                                                      \
    const long simsr_allocations_ = (count);                                                                \
    if constexpr (::simsr::test::allocations_checked_under<decltype(policy)>) {                             \
      CHECK(simsr_allocations_ == 0);                                                                       \
    } else {                                                                                                \
      MESSAGE("allocations not checked in this build (" << simsr_allocations_ << " counted; tests/support/allocation_check.hpp says why)"); \
    }                                                                                                       \
  } while (0)
