#pragma once
/// \file
/// Any fitted interpolator over a whole LR performance: F frames of LR positions in, F frames of
/// HR positions out (HR rest + the predicted displacement), timed — what `simsr upsample` and
/// `simsr infer` write.
///
///     data::FrameSet lr = data::read_frame_set("performance.npz", "lowres", N);
///     auto [hr, seconds_per_frame] = interp::apply_frames(exec::omp, method, lr_rest, hr_rest, lr);

#include <chrono>
#include <string>

#include "../core/error.hpp"
#include "../data/frame_set.hpp"
#include "concepts.hpp"

namespace simsr::interp {

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
    lr_disp = (lowres.frame(i) - lr_rest).template cast<typename I::scalar_type>();
    const auto t0 = std::chrono::steady_clock::now();
    method.apply(policy, lr_disp, hr_disp);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    Eigen::Map<Points<Scalar>> dst(out.highres.positions.row(i).data(), m, 3);
    dst = hr_rest + hr_disp.template cast<Scalar>();
    if (!dst.allFinite()) throw NumericalError("interp::apply_frames", "the prediction of frame " + std::to_string(lowres.ids[std::size_t(i)]), -1, dst.sum());
  }
  out.seconds_per_frame = f > 0 ? seconds / double(f) : 0.0;
  return out;
}

}  // namespace simsr::interp
