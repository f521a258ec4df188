/// Counts malloc calls (Eigen allocates with std::malloc, the standard containers through
/// operator new → malloc) by interposing glibc's malloc family, for the warm-call checks.

#include <atomic>
#include <cstddef>

#include "gradient_check.hpp"

namespace {
std::atomic<long> malloc_calls{0};
}

long simsr_test_nn_malloc_count() { return malloc_calls.load(); }

#if defined(__GLIBC__)
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) {
  malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t s) {
  malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, s);
}
void* realloc(void* p, std::size_t n) {
  malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
}
#endif

TEST_CASE("nn test support: the malloc counter sees Eigen and std allocations") {
#if defined(__GLIBC__)
  const long before = simsr_test_nn_malloc_count();
  simsr::nn::Matrix<float> m(7, 9);
  std::vector<int> v(100);
  CHECK(simsr_test_nn_malloc_count() - before >= 2);
  CHECK(m.size() + Eigen::Index(v.size()) == 163);
#endif
}
