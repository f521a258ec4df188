#pragma once
/// \file
/// Execution policies (Thrust/Kokkos style): algorithms take the policy object first,
/// `parallel_for(exec::omp, n, body)`. One backend per file: seq.hpp, omp.hpp, cuda.cuh.

#include <concepts>
#include <type_traits>

namespace simsr::exec {

/// Run on the calling thread, in index order.
struct seq_t {};
/// Run on the host with OpenMP threads where a loop pays for them, else on the calling thread
/// (needs simsr::openmp, i.e. -fopenmp; exec/omp.hpp says how it decides).
struct omp_t {};
/// Run on a CUDA device (needs nvcc; bodies must be SIMSR_HOST_DEVICE and data device-visible).
struct cuda_t {};

inline constexpr seq_t seq{};
inline constexpr omp_t omp{};
inline constexpr cuda_t cuda{};

/// Satisfied by the three policy tags above.
template <class P>
concept ExecutionPolicy = std::same_as<std::remove_cvref_t<P>, seq_t> ||
                          std::same_as<std::remove_cvref_t<P>, omp_t> ||
                          std::same_as<std::remove_cvref_t<P>, cuda_t>;

/// True for an ExecutionPolicy; for any other type a static_assert says so in one sentence.
template <class P>
constexpr bool assert_execution_policy() {
  static_assert(ExecutionPolicy<P>,
                "this type is not a simsr::exec::ExecutionPolicy: pass exec::seq, exec::omp or exec::cuda, as the first argument of every call");
  return ExecutionPolicy<P>;
}

/// Policies that run on the host (their bodies may touch host memory and throw).
template <class P>
concept HostPolicy = std::same_as<std::remove_cvref_t<P>, seq_t> || std::same_as<std::remove_cvref_t<P>, omp_t>;

namespace detail {
template <class...>
inline constexpr bool dependent_false = false;
}  // namespace detail

/// Number of chunks `parallel_reduce` and `parallel_for_accumulate` split work into by default.
/// Fixed (not the thread count) so that floating-point results are bitwise identical under seq
/// and omp and across thread counts.
inline constexpr long default_chunks = 64;

}  // namespace simsr::exec
