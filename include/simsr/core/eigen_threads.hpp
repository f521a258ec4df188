#pragma once
/// \file
/// Eigen's own threads, kept off. Compiled with OpenMP, Eigen parallelizes two things by itself
/// when it is called outside a parallel region: dense matrix products (its GEMM, also inside the
/// blocked LU, QR and eigen-decompositions of matrices larger than about 50) and row-major
/// sparse × dense products of more than 20,000 multiply-adds. Under exec::seq that starts OpenMP
/// threads (beside a busy process a sequential run became 3× slower), under exec::omp a second
/// level of threads the policy does not control. simsr starts threads only through its policies:
///
///     { EigenSingleThreaded serial; lu.compute(K); }         // a decomposition, on this thread
///     { EigenSingleThreaded serial; K.noalias() = X * X.transpose(); }
///
/// Where simsr multiplies a row-major sparse matrix by dense data, a loop under the caller's policy
/// is better still (physics::sparse_multiply): parallel under exec::omp, same rounding as Eigen.
/// tests/threads checks that exec::seq starts no thread in representative workloads.

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace simsr {

/// While alive, Eigen runs single-threaded on the calling thread: the thread's OpenMP thread
/// count (nthreads-var, which Eigen reads through omp_get_max_threads()) is 1, and restored when
/// the guard goes. Other threads are unaffected. Note that an exec::omp loop started inside the
/// guard's scope runs on the calling thread too; keep the scope to the Eigen calls. It cannot
/// override Eigen::setNbThreads(n > 1), which a program calls only to ask for Eigen's threads.
class EigenSingleThreaded {
 public:
  EigenSingleThreaded() {
#if defined(_OPENMP)
    saved_ = omp_get_max_threads();
    if (saved_ != 1) omp_set_num_threads(1);
#endif
  }
  ~EigenSingleThreaded() {
#if defined(_OPENMP)
    if (saved_ != 1) omp_set_num_threads(saved_);
#endif
  }
  EigenSingleThreaded(const EigenSingleThreaded&) = delete;
  EigenSingleThreaded& operator=(const EigenSingleThreaded&) = delete;

 private:
  [[maybe_unused]] int saved_ = 1;
};

}  // namespace simsr
