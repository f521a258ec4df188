#pragma once
/// \file
/// Every OpenMP region a library starts on this thread, kept on this thread. A library compiled
/// with an explicit num_threads clause ignores the thread's thread count (omp_set_num_threads,
/// OMP_NUM_THREADS): CHOLMOD 3's supernodal factorization is `parallel for
/// num_threads(CHOLMOD_OMP_NUM_THREADS)`, 4 compiled in, so under exec::seq — and in each worker of
/// the cloth data's side-by-side sequences — it started a team of 4 per factorization. On two
/// cores with two workers, those six helper threads took a quarter of the CPU, a third of it in
/// the kernel (spinning at barriers). An inactive region runs on its caller alone, and with the
/// thread's max-active-levels at 0 every region is inactive, whatever its clause says.
///
///     { OpenMPSerial serial; cholmod_factorize(...); }   // one thread, whatever CHOLMOD asks for
///
/// max-active-levels is a per-task ICV since OpenMP 5.0 (libgomp, LLVM's libomp), so other
/// threads are unaffected; it is restored when the guard goes.

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace simsr {

/// While alive, every OpenMP parallel region started on the calling thread runs on it alone
/// (see the file comment). Without OpenMP it does nothing.
class OpenMPSerial {
 public:
  OpenMPSerial() {
#if defined(_OPENMP)
    saved_ = omp_get_max_active_levels();
    if (saved_ != 0) omp_set_max_active_levels(0);
#endif
  }
  ~OpenMPSerial() {
#if defined(_OPENMP)
    if (saved_ != 0) omp_set_max_active_levels(saved_);
#endif
  }
  OpenMPSerial(const OpenMPSerial&) = delete;
  OpenMPSerial& operator=(const OpenMPSerial&) = delete;

 private:
  [[maybe_unused]] int saved_ = 0;
};

}  // namespace simsr
