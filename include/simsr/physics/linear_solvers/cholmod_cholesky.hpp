#pragma once
/// \file
/// Sparse direct solver: SuiteSparse's CHOLMOD, supernodal LLᵀ (CHOLMOD's own fill-reducing
/// ordering: AMD, or METIS where it is smaller) through Eigen's CholmodSupport. The same contract as
/// SparseCholesky (symbolic analysis redone only when the pattern changes, a zero or negative
/// pivot a ConvergenceError), for the systems where a simplicial factorization is too slow: the
/// supernodal one runs its dense fronts through the BLAS, which on 3D tet meshes of 10⁵ DOFs is
/// many times faster (bench_softdeca's factor cases put both side by side).
///
///     physics::QuasistaticSolver<physics::CholmodCholesky<>> newton(mesh.num_vertices(), mesh.T);
///     physics::LocalGlobalSolver<physics::CholmodCholesky<>> pd(mesh.num_vertices(), mesh.T);
///
/// Optional: needs cholmod.h and libcholmod (Debian's libsuitesparse-dev); CMake's
/// -DSIMSR_WITH_CHOLMOD=ON gives the target simsr::cholmod, which defines SIMSR_HAVE_CHOLMOD.
/// Threads: CHOLMOD 3's supernodal factorization has OpenMP loops with num_threads(4) compiled
/// in, which ignore the thread count; under exec::seq they run on the calling thread
/// (OpenMPSerial), under exec::omp they keep CHOLMOD's 4. Its BLAS is the system's (Debian's
/// reference BLAS is sequential; OpenBLAS starts threads of its own under either policy unless
/// OPENBLAS_NUM_THREADS=1), so unlike SparseCholesky, exec::seq cannot promise that no thread
/// starts. The policy runs the residual check, as in SparseCholesky.

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <type_traits>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

#include "../../core/error.hpp"
#include "../../core/openmp_serial.hpp"
#include "../../core/parallel.hpp"
#include "../../core/types.hpp"
#include "linear_solver.hpp"
#include "sparse_ops.hpp"

namespace simsr::physics {

/// LLᵀ of a symmetric positive definite matrix by CHOLMOD (see the file comment). double only:
/// CHOLMOD 3 factors real matrices in double precision.
template <class S = Scalar>
class CholmodCholesky {
  static_assert(std::is_same_v<S, double>, "physics::CholmodCholesky factors double matrices only (CHOLMOD's real path)");

 public:
  using scalar_type = S;

  /// Throws ConvergenceError (0 iterations, residual NaN) when the factorization breaks down (the
  /// matrix is not positive definite: singular, e.g. rigid motions left free, or indefinite).
  template <exec::HostPolicy P>
  void compute(P, const SparseMatrix<S>& A, std::uint64_t pattern_version = 0) {
    if constexpr (std::is_same_v<std::remove_cvref_t<P>, exec::seq_t>) {
      const OpenMPSerial serial;  // CHOLMOD's num_threads(4) loops, on this thread
      factor(A, pattern_version);
    } else {
      factor(A, pattern_version);
    }
  }

  /// x = A⁻¹ b; the relative residual is computed under `policy`.
  template <exec::HostPolicy P>
  LinearSolveInfo solve(P policy, const VecX<S>& b, VecX<S>& x) {
    if (!A_) throw Error("CholmodCholesky::solve called before compute");
    if (b.size() != pattern_.rows) throw ShapeError("CholmodCholesky: right-hand side", {pattern_.rows}, {b.size()});
    x = llt_->solve(b);
    return detail::direct_solve_info(policy, *A_, b, x, Ax_, llt_->info() == Eigen::Success);
  }

  /// Nonzeros of the factor L of the last analysis (CHOLMOD's count).
  double factor_nonzeros() const {
    if (!llt_ || !A_) return 0;
    // const_cast: Eigen's accessor to the cholmod_common is non-const; nothing is changed.
    return double(const_cast<Factorization&>(*llt_).cholmod().lnz);
  }

 private:
  /// compute() under either policy.
  void factor(const SparseMatrix<S>& A, std::uint64_t pattern_version) {
    if (A.rows() != A.cols()) throw ShapeError("CholmodCholesky: matrix", {A.rows(), A.rows()}, {A.rows(), A.cols()});
    // CHOLMOD reads a compressed column matrix; a symmetric row-major CSR read as column-major is
    // its transpose, i.e. itself. CholmodSupport needs a real SparseMatrix (not a Map) whose
    // lower triangle it reads: the copy is O(nnz), against a factorization of O(nnz(L)·front).
    Ac_ = Eigen::Map<const Eigen::SparseMatrix<S, Eigen::ColMajor, int>>(A.rows(), A.cols(), A.nonZeros(), A.outerIndexPtr(), A.innerIndexPtr(),
                                                                         A.valuePtr());
    if (!llt_) {
      llt_ = std::make_unique<Factorization>();
      llt_->cholmod().print = 0;  // failures are this class's typed errors, not CHOLMOD's printout
    }
    if (pattern_.changed(A, pattern_version)) llt_->analyzePattern(Ac_);
    llt_->factorize(Ac_);
    if (llt_->info() != Eigen::Success)
      throw ConvergenceError("CholmodCholesky (CHOLMOD's LLT: the matrix is not positive definite)", 0, std::numeric_limits<double>::quiet_NaN());
    A_ = &A;
  }

  // Supernodal LLᵀ (CHOLMOD_SUPERNODAL). Held by pointer: Eigen's factorizations cannot be moved.
  using Factorization = Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<S, Eigen::ColMajor, int>, Eigen::Lower>;
  std::unique_ptr<Factorization> llt_;
  Eigen::SparseMatrix<S, Eigen::ColMajor, int> Ac_;
  const SparseMatrix<S>* A_ = nullptr;
  VecX<S> Ax_;
  detail::AnalysedPattern pattern_;
};

}  // namespace simsr::physics
