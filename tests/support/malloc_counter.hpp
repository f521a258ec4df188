#pragma once
// Counts malloc calls (Eigen allocates with std::malloc, the standard containers through operator
// new → malloc) by interposing glibc's malloc family, for the "no allocation once warm" checks.
// Include from exactly ONE source file per test executable: it defines malloc/calloc/realloc/free.
// Elsewhere, declare `long simsr_test_malloc_count();`. Without glibc the count stays 0.
#include <atomic>
#include <cstddef>

namespace simsr_test_detail {
inline std::atomic<long> malloc_calls{0};
}

long simsr_test_malloc_count() { return simsr_test_detail::malloc_calls.load(); }

#if defined(__GLIBC__)
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) {
  simsr_test_detail::malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t s) {
  simsr_test_detail::malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, s);
}
void* realloc(void* p, std::size_t n) {
  simsr_test_detail::malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
}
#endif
