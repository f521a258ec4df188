#pragma once
/// \file
/// The two preparation steps every caller of an interpolator repeats, once: fit on the problem
/// (computing the §3.2 neighbourhoods first when the method reads them and the problem has none),
/// and, for a method that learns from frames, train on paired frames given as absolute positions.
///
///     interp::prepare(exec::omp, mls, problem);                          // fit
///     interp::prepare(exec::omp, ridge, problem, train_frames, {});      // fit + train
///     interp::prepare(exec::omp, ridge, problem, train_frames);          // … with default options

#include <string>

#include "../core/error.hpp"
#include "../data/paired_frames.hpp"
#include "concepts.hpp"

namespace simsr::interp {

/// Fits `method`; the neighbourhoods (k = `neighborhood_k`) are computed first if it needs them
/// and the problem has none.
template <exec::HostPolicy Policy, Interpolator I>
void prepare(Policy policy, I& method, UpsamplingProblem<typename I::scalar_type>& problem, Index neighborhood_k = 20) {
  if constexpr (needs_neighborhoods_v<I>)
    if (!problem.neighborhoods) problem.ensure_neighborhoods(policy, neighborhood_k);
  method.fit(policy, problem);
}

/// Fits `method`, then trains it on `train` (absolute positions; the displacements from the
/// problem's rest shapes are taken here). ArgumentError without training frames.
template <exec::HostPolicy Policy, TrainableInterpolator I>
void prepare(Policy policy, I& method, UpsamplingProblem<typename I::scalar_type>& problem, const data::PairedFrames<Scalar>& train,
             const typename I::train_options& options = {}, Index neighborhood_k = 20) {
  if (train.num_frames() < 1) throw ArgumentError("interp::prepare: this method learns from frames, and no training frame is given");
  prepare(policy, method, problem, neighborhood_k);
  method.train(policy, data::displacements(train, problem.lr.V, problem.hr.V), options);
}

}  // namespace simsr::interp
