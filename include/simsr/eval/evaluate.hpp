#pragma once
/// \file
/// One function evaluates any interpolator on paired frames (SPEC §8; the paper's Table 1, Fig. 5):
///
///     interp::UpsamplingProblem<> problem{lr, hr, {}};
///     interp::MLS<> mls;
///     auto r = eval::run_method(exec::omp, mls, problem, train, test);   // fit (+ train) + evaluate
///     auto r = eval::evaluate(exec::omp, fitted_method, lr.V, hr.V, test);   // a method already fitted
///     r.errors.statistics();  r.errors.relative_statistics();  r.errors.frame_means();  r.seconds_per_frame;
///
/// Swapping the method is one type change: Embedded, IDW, RBF, MLS, Ridge, the β-VAE and the
/// network (interp::Learned) all go through the same code. `train` and `test` are frames of
/// absolute positions (as the files store them); the displacements every method consumes are
/// taken from the problem's rest shapes here.

#include <chrono>
#include <functional>
#include <string>
#include <utility>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../data/frame_set.hpp"
#include "../data/paired_frames.hpp"
#include "../interp/concepts.hpp"
#include "../interp/fit_and_train.hpp"
#include "error_statistics.hpp"

namespace simsr::eval {

/// What evaluate measured.
struct Evaluation {
  ErrorAccumulator errors;         ///< per-vertex errors of every frame: statistics, frame means, the last frame's errors
  VecX<double> vertex_mean_error;  ///< M: each HR vertex's error averaged over the frames (a heatmap)
  VecX<double> vertex_max_error;   ///< M: each HR vertex's largest error over the frames
  /// F×M: every frame's per-vertex errors (float32: heatmaps per frame, e.g. eval::MethodComparison)
  Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> vertex_errors;
  double seconds_per_frame = 0;    ///< wall time of apply per frame (warm: the first frame is timed too)
  double prepare_seconds = 0;      ///< run_method: seconds of fit + training (interp::prepare)
};

/// Called with (frame row, predicted HR positions M×3) after every frame, e.g. to keep predictions.
using FrameCallback = std::function<void(Index, const Points<Scalar>&)>;

/// Applies the fitted `method` to every frame of `test` (absolute positions; LR and HR rest
/// shapes give the displacements) and compares the predicted HR positions with test's highres.
/// ShapeError when the sizes differ from the method's; ArgumentError (naming the frame) for a
/// non-finite prediction.
template <exec::HostPolicy Policy, interp::Interpolator I>
Evaluation evaluate(Policy policy, const I& method, const Points<Scalar>& lr_rest, const Points<Scalar>& hr_rest,
                    const data::PairedFrames<Scalar>& test, const FrameCallback& on_frame = {}) {
  const Index n = lr_rest.rows(), m = hr_rest.rows();
  if (method.num_lr() != n || method.num_hr() != m)
    throw ShapeError("eval::evaluate: method fitted on (N, M)", {n, m}, {method.num_lr(), method.num_hr()});
  if (test.num_lr() != n || test.num_hr() != m) throw ShapeError("eval::evaluate: test frames (N, M)", {n, m}, {test.num_lr(), test.num_hr()});
  if (test.num_frames() < 1) throw ArgumentError("eval::evaluate: no test frames");
  Evaluation r{ErrorAccumulator(hr_rest), VecX<double>::Zero(m), VecX<double>::Zero(m), {}};
  r.vertex_errors.resize(test.num_frames(), m);
  Points<Scalar> lr_disp(n, 3), hr_disp(m, 3), predicted(m, 3);
  double seconds = 0;
  for (Index f = 0; f < test.num_frames(); ++f) {
    lr_disp = test.lr(f) - lr_rest;
    const auto t0 = std::chrono::steady_clock::now();
    method.apply(policy, lr_disp, hr_disp);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    predicted = hr_rest + hr_disp;
    if (!predicted.allFinite()) throw ArgumentError("eval::evaluate: frame " + std::to_string(test.ids[std::size_t(f)]) + ": the prediction is not finite");
    r.errors.add_frame(predicted, test.hr(f));
    r.vertex_mean_error += r.errors.last_frame_errors() / double(test.num_frames());
    r.vertex_max_error = r.vertex_max_error.cwiseMax(r.errors.last_frame_errors());
    r.vertex_errors.row(f) = r.errors.last_frame_errors().transpose().template cast<float>();
    if (on_frame) on_frame(f, predicted);
  }
  r.seconds_per_frame = seconds / double(test.num_frames());
  return r;
}

/// Predicted HR frames against true ones (both absolute positions, M = hr_rest's vertices): by
/// `frame` id when both sets carry ids (the truth may hold more frames, e.g. a whole performance
/// against its held-out part), else by index with equal counts. `vertex_errors` rows follow the
/// predicted frames. ShapeError naming the truth file for a missing id or unequal counts.
inline Evaluation evaluate_predictions(const Points<Scalar>& hr_rest, const data::FrameSet& predicted, const data::FrameSet& truth,
                                       const std::string& truth_name = "truth") {
  const Index m = hr_rest.rows(), f = predicted.num_frames();
  if (predicted.num_vertices() != m || truth.num_vertices() != m)
    throw ShapeError("eval::evaluate_predictions: HR vertices (predicted, truth)", {m, m}, {predicted.num_vertices(), truth.num_vertices()});
  if (f < 1) throw ArgumentError("eval::evaluate_predictions: no predicted frames");
  std::vector<Index> rows;
  if (predicted.has_ids && truth.has_ids) {
    rows = data::match_frame_ids(predicted.ids, truth.ids, truth_name);
  } else {
    if (truth.num_frames() != f)
      throw ShapeError(truth_name + ": frames vs the prediction's (unequal frame counts need a `frame` id array in both files)", {f, m, 3},
                       {truth.num_frames(), m, 3});
    for (Index i = 0; i < f; ++i) rows.push_back(i);
  }
  Evaluation r{ErrorAccumulator(hr_rest), VecX<double>::Zero(m), VecX<double>::Zero(m), {}};
  r.vertex_errors.resize(f, m);
  for (Index i = 0; i < f; ++i) {
    r.errors.add_frame(predicted.frame(i), truth.frame(rows[std::size_t(i)]));
    r.vertex_mean_error += r.errors.last_frame_errors() / double(f);
    r.vertex_max_error = r.vertex_max_error.cwiseMax(r.errors.last_frame_errors());
    r.vertex_errors.row(i) = r.errors.last_frame_errors().transpose().template cast<float>();
  }
  return r;
}

namespace detail {
template <class Policy, class I>
Evaluation timed(Policy policy, I& method, interp::UpsamplingProblem<typename I::scalar_type>& problem, const data::PairedFrames<Scalar>& test,
                 const FrameCallback& on_frame, std::chrono::steady_clock::time_point t0) {
  const auto t1 = std::chrono::steady_clock::now();
  Evaluation r = evaluate(policy, std::as_const(method), problem.lr.V, problem.hr.V, test, on_frame);
  r.prepare_seconds = std::chrono::duration<double>(t1 - t0).count();  // fit + train (prepare)
  return r;
}
}  // namespace detail

/// interp::prepare (fit; the neighbourhoods first when the method needs them; training on
/// `train` with default options when it learns from frames), then evaluate on `test`. Frames are
/// absolute positions. `prepare_seconds` holds the time of the preparation.
template <exec::HostPolicy Policy, interp::Interpolator I>
Evaluation run_method(Policy policy, I& method, interp::UpsamplingProblem<typename I::scalar_type>& problem,
                      const data::PairedFrames<Scalar>& train, const data::PairedFrames<Scalar>& test,
                      const FrameCallback& on_frame = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  if constexpr (interp::TrainableInterpolator<I>)
    interp::prepare(policy, method, problem, train);
  else
    interp::prepare(policy, method, problem);
  return detail::timed(policy, method, problem, test, on_frame, t0);
}

/// run_method with the training options given (a TrainableInterpolator).
template <exec::HostPolicy Policy, interp::TrainableInterpolator I>
Evaluation run_method(Policy policy, I& method, interp::UpsamplingProblem<typename I::scalar_type>& problem,
                      const data::PairedFrames<Scalar>& train, const data::PairedFrames<Scalar>& test,
                      const typename I::train_options& options, const FrameCallback& on_frame = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  interp::prepare(policy, method, problem, train, options);
  return detail::timed(policy, method, problem, test, on_frame, t0);
}

}  // namespace simsr::eval
