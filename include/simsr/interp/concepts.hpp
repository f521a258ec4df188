#pragma once
/// \file
/// The Interpolator concept: LR volume displacements → HR surface displacements (SPEC §6). Every
/// method — Embedded, IDW, RBF, MLS, Ridge, the β-VAE and the super-resolution network
/// (interp::Learned) — satisfies it as it is, so swapping one for another is one type change:
///
///     template <interp::Interpolator I> auto run(I method) {
///       method.fit(exec::omp, problem);                       // once: rest shapes (+ neighbourhoods)
///       if constexpr (interp::TrainableInterpolator<I>)       // learns from paired frames
///         method.train(exec::omp, train_displacements, typename I::train_options{});
///       method.apply(exec::omp, lr_displacement, hr_displacement);   // per frame, N×3 → M×3
///     }
///
/// Two phases: `fit(policy, problem)` once on the rest shapes (and, where
/// `needs_neighborhoods_v<I>`, the §3.2 neighbourhoods of the problem), then
/// `apply(policy, lr_displacement, hr_displacement)` per frame into a caller-sized M×3 buffer
/// without allocating (the library's methods take both as ConstPointsRef / PointsRef, so a
/// Points, a row block of one or a NumPy array is read and written in place). Methods that learn
/// from paired frames add `train(policy, frames, options)` with `frames` the training frames as
/// displacements from the fitted rest shapes (data::displacements) and `options` of their
/// `train_options` type.

#include <concepts>

#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../data/paired_frames.hpp"
#include "problem.hpp"

namespace simsr::interp {

/// fit/apply under both host policies, with the sizes fitted on (see the file comment).
template <class I>
concept Interpolator = requires(I& method, const I& cmethod, UpsamplingProblem<typename I::scalar_type>& problem,
                                const Points<typename I::scalar_type>& lr_displacement,
                                Points<typename I::scalar_type>& hr_displacement) {
  typename I::scalar_type;
  method.fit(exec::seq, problem);
  method.fit(exec::omp, problem);
  cmethod.apply(exec::seq, lr_displacement, hr_displacement);
  cmethod.apply(exec::omp, lr_displacement, hr_displacement);
  { cmethod.num_lr() } -> std::convertible_to<Index>;
  { cmethod.num_hr() } -> std::convertible_to<Index>;
};

/// An Interpolator that learns from paired frames: `train(policy, frames, options)` after fit,
/// before apply. `train_options{}` must be a sensible default.
template <class I>
concept TrainableInterpolator =
    Interpolator<I> && std::default_initializable<typename I::train_options> &&
    requires(I& method, const data::PairedFrames<typename I::scalar_type>& frames, const typename I::train_options& options) {
      method.train(exec::seq, frames, options);
      method.train(exec::omp, frames, options);
    };

/// Whether `fit` reads `problem.neighborhoods` (the §3.2 upsampling neighbourhoods): the
/// method's `static constexpr bool needs_neighborhoods`, false when it declares none.
template <class I>
inline constexpr bool needs_neighborhoods_v = [] {
  if constexpr (requires { { I::needs_neighborhoods } -> std::convertible_to<bool>; })
    return bool(I::needs_neighborhoods);
  else
    return false;
}();

/// static_assert helper that prints a sentence instead of a concept backtrace.
template <class I>
constexpr bool assert_interpolator() {
  static_assert(Interpolator<I>,
                "this type is not an interp::Interpolator: it needs a scalar_type, fit(policy, UpsamplingProblem&), "
                "apply(policy, lr_displacement, hr_displacement) const (N×3 in, caller-sized M×3 out, as Points) for exec::seq and exec::omp, "
                "num_lr() and num_hr()");
  return Interpolator<I>;
}

/// static_assert helper for the trainable refinement.
template <class I>
constexpr bool assert_trainable_interpolator() {
  static_assert(TrainableInterpolator<I>,
                "this type is not an interp::TrainableInterpolator: it must be an Interpolator with a default-constructible "
                "train_options type and train(policy, const data::PairedFrames& displacements, const train_options&)");
  return TrainableInterpolator<I>;
}

}  // namespace simsr::interp
