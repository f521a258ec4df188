#pragma once
// Counts malloc calls (Eigen allocates with std::malloc, the standard containers through operator
// new → malloc) by interposing glibc's malloc family, for the "no allocation once warm" checks.
// Include from exactly ONE source file per test executable: it defines malloc/calloc/realloc/free.
// Elsewhere, include allocation_check.hpp (SIMSR_CHECK_NO_ALLOCATION, which also says why exec::omp
// counts are not checked under LLVM's libomp). Without glibc or a sanitizer the count stays 0.
// Under ASan (or TSan) the sanitizer owns malloc (glibc's would bypass it, and its free would meet
// blocks it never gave out), so the count comes from the sanitizer's own allocation hook instead,
// which sees every malloc, calloc, realloc and operator new alike.
#include <atomic>
#include <cstddef>

namespace simsr_test_detail {
inline std::atomic<long> malloc_calls{0};
}

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define SIMSR_TEST_SANITIZER_MALLOC 1
#endif
#endif
#if !defined(SIMSR_TEST_SANITIZER_MALLOC) && (defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__))
#define SIMSR_TEST_SANITIZER_MALLOC 1
#endif

long simsr_test_malloc_count() { return simsr_test_detail::malloc_calls.load(); }

#if defined(SIMSR_TEST_SANITIZER_MALLOC)
// Declared here: GCC ships no sanitizer/allocator_interface.h, but its runtimes have the hook.
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*, std::size_t),
                                                         void (*free_hook)(const volatile void*));
namespace simsr_test_detail {
inline void count_malloc(const volatile void*, std::size_t) { malloc_calls.fetch_add(1, std::memory_order_relaxed); }
inline void ignore_free(const volatile void*) {}
// The runtime wants both hooks (it refuses a null one and returns 0).
inline const int malloc_hook_installed = __sanitizer_install_malloc_and_free_hooks(count_malloc, ignore_free);
}  // namespace simsr_test_detail
#elif defined(__GLIBC__)
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
