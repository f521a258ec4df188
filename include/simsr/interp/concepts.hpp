#pragma once
/// \file
/// The Interpolator concept: LR volume displacements → HR surface displacements (SPEC §6).
/// Two phases: `fit(problem)` once on the rest shapes (and neighbourhoods), then
/// `apply(lr_displacement, hr_displacement)` per frame, writing into a caller-sized M×3 buffer
/// without allocating. Swapping a baseline is one type change:
///
///     template <interp::Interpolator I> double mean_error(I& method, ...);
///     mean_error(interp::Embedded<>{}, ...);  mean_error(interp::MLS<>{}, ...);

#include <concepts>

#include "../core/types.hpp"
#include "problem.hpp"

namespace simsr::interp {

template <class I>
concept Interpolator = requires(I& method, const I& cmethod, UpsamplingProblem<typename I::scalar_type>& problem,
                                const Points<typename I::scalar_type>& lr_displacement,
                                Points<typename I::scalar_type>& hr_displacement) {
  typename I::scalar_type;
  { method.fit(problem) };                               // once: rest shapes (+ neighbourhoods)
  { cmethod.apply(lr_displacement, hr_displacement) };   // per frame: N×3 → M×3, no allocation
  { cmethod.num_lr() } -> std::convertible_to<Index>;
  { cmethod.num_hr() } -> std::convertible_to<Index>;
};

/// static_assert helper that prints a sentence instead of a concept backtrace.
template <class I>
constexpr bool assert_interpolator() {
  static_assert(Interpolator<I>,
                "not an interp::Interpolator: needs `scalar_type`, `fit(UpsamplingProblem&)`, "
                "`apply(const Points& lr_displacement, Points& hr_displacement) const`, `num_lr()`, `num_hr()`");
  return true;
}

}  // namespace simsr::interp
