#pragma once
/// \file
/// Any fitted interpolator over a whole LR performance: F frames of LR positions in, F frames of
/// HR positions out (HR rest + the predicted displacement), timed — what `simsr upsample` and
/// `simsr infer` write.
///
///     data::FrameSet lr = data::read_frame_set("performance.npz", "lowres", N);
///     auto [hr, seconds_per_frame] = interp::apply_frames(exec::omp, method, lr_rest, hr_rest, lr);

#include <chrono>
#include <cstdint>
#include <string>

#include "../core/error.hpp"
#include "../data/frame_set.hpp"
#include "concepts.hpp"

namespace simsr::interp {

/// One frame in positions: hr = hr_rest + method(lr − lr_rest), through the method's own scalar
/// in the caller's buffers (nothing allocated once they are sized). NumericalError naming `where`
/// and the frame id for a non-finite prediction (the message is built only then). apply_frames and
/// the live pipeline (pipeline/live.hpp) run it.
template <exec::HostPolicy Policy, Interpolator I, class LR, class HR>
void upsample_positions(Policy policy, const I& method, const Points<Scalar>& lr_rest, const Points<Scalar>& hr_rest, const LR& lr,
                        Points<typename I::scalar_type>& lr_disp, Points<typename I::scalar_type>& hr_disp, HR&& hr, const char* where,
                        std::int64_t frame) {
  lr_disp = (lr - lr_rest).template cast<typename I::scalar_type>();
  method.apply(policy, lr_disp, hr_disp);
  hr = hr_rest + hr_disp.template cast<Scalar>();
  if (!hr.allFinite()) throw NumericalError(where, "the prediction of frame " + std::to_string(frame), -1, hr.sum());
}

/// What apply_frames produced.
struct AppliedFrames {
  data::FrameSet highres;        ///< F×M×3 HR positions with the LR frames' ids
  double seconds_per_frame = 0;  ///< mean wall time of one apply
};

/// Applies `method` to every frame of `lowres` (absolute LR positions; displacements from
/// lr_rest). ShapeError for sizes other than the method's, NumericalError (naming the frame id)
/// for a non-finite prediction: nothing non-finite is returned.
template <exec::HostPolicy Policy, Interpolator I>
AppliedFrames apply_frames(Policy policy, const I& method, const Points<Scalar>& lr_rest, const Points<Scalar>& hr_rest,
                           const data::FrameSet& lowres) {
  const Index n = lr_rest.rows(), m = hr_rest.rows(), f = lowres.num_frames();
  if (method.num_lr() != n || method.num_hr() != m)
    throw ShapeError("interp::apply_frames: method fitted on (N, M)", {n, m}, {method.num_lr(), method.num_hr()});
  if (lowres.num_vertices() != n) throw ShapeError("interp::apply_frames: LR frames' vertices", {n}, {lowres.num_vertices()});
  AppliedFrames out;
  out.highres.positions.resize(f, 3 * m);
  out.highres.ids = lowres.ids;
  out.highres.has_ids = lowres.has_ids;
  Points<typename I::scalar_type> lr_disp(n, 3), hr_disp(m, 3);
  double seconds = 0;
  for (Index i = 0; i < f; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    upsample_positions(policy, method, lr_rest, hr_rest, lowres.frame(i), lr_disp, hr_disp,
                       Eigen::Map<Points<Scalar>>(out.highres.positions.row(i).data(), m, 3), "interp::apply_frames",
                       lowres.ids[std::size_t(i)]);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  out.seconds_per_frame = f > 0 ? seconds / double(f) : 0.0;
  return out;
}

}  // namespace simsr::interp
