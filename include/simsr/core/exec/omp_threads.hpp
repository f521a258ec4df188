#pragma once
/// \file
/// A share of the cores for one thread's exec::omp loops. Two stages that run at the same time on
/// two threads (pipeline/live.hpp: the LR simulation of frame t+1 beside the network on frame t)
/// would each fork a team of every core and fight over them; each stage's thread takes its share:
///
///     std::thread sim([&] { exec::OmpThreadLimit share(1); source.next(exec::omp, x); });
///
/// OpenMP's thread count (nthreads-var) belongs to the calling thread: the limit changes nothing
/// on any other thread, and a new std::thread starts from the process default (OMP_NUM_THREADS).

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace simsr::exec {

/// While alive, exec::omp loops (and Eigen) started on the calling thread use at most `threads`
/// threads; the previous count comes back when it goes. `threads` < 1 leaves the count alone.
class OmpThreadLimit {
 public:
  explicit OmpThreadLimit(int threads) {
#if defined(_OPENMP)
    saved_ = omp_get_max_threads();
    if (threads >= 1 && threads != saved_) omp_set_num_threads(threads);
#else
    (void)threads;
#endif
  }
  ~OmpThreadLimit() {
#if defined(_OPENMP)
    if (omp_get_max_threads() != saved_) omp_set_num_threads(saved_);
#endif
  }
  OmpThreadLimit(const OmpThreadLimit&) = delete;
  OmpThreadLimit& operator=(const OmpThreadLimit&) = delete;

 private:
  [[maybe_unused]] int saved_ = 1;
};

}  // namespace simsr::exec
