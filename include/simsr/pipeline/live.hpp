#pragma once
/// \file
/// Live super-resolution (core paper §5.1): an LR simulation produces frame after frame and an
/// interpolator (the network) turns each into HR, as an interactive application runs them. Two
/// ways, with the same frames and figures:
///
/// - **pipelined** (the paper's setting): the source computes frame t+1 on a thread of its own
///   while the method runs on frame t on the calling thread, one frame of latency, each with its
///   share of the threads (exec::OmpThreadLimit: by default the slower stage, timed on the first
///   frame, gets every core); end to end runs at the slower stage's rate;
/// - **unpipelined**: source then method on the calling thread, every core for each in turn; end
///   to end runs at 1 / (t_source + t_method).
///
///     pipeline::LiveOptions o;                    // pipelined, the threads split by the first frame
///     auto r = pipeline::run_live(exec::omp, source, net, lr_rest, hr_rest,
///                                 [&](Index f, const Points<>& lr, const Points<>& hr) { keep(f, hr); }, o);
///     r.end_to_end_fps();  r.source_fps();  r.method_fps();
///
/// The sink sees the frames in order on the calling thread. An exception in either stage stops
/// both and is rethrown here; nothing after the failed frame reaches the sink.

#include <algorithm>
#include <chrono>
#include <concepts>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include <nlohmann/json.hpp>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../interp/apply_frames.hpp"
#include "../interp/concepts.hpp"

namespace simsr::pipeline {

/// Produces LR frames one after the other: `next(policy, x)` writes the next frame's LR vertex
/// positions (absolute, num_vertices()×3) into x, `num_frames()` of them.
template <class S>
concept FrameSource = requires(S& source, Points<Scalar>& x) {
  { source.num_frames() } -> std::convertible_to<Index>;
  { source.num_vertices() } -> std::convertible_to<Index>;
  source.next(exec::omp, x);
  source.next(exec::seq, x);
};

/// static_assert helper that prints one sentence instead of a concept backtrace.
template <class S>
constexpr bool assert_frame_source() {
  static_assert(FrameSource<S>,
                "this type is not a pipeline::FrameSource: it needs num_frames(), num_vertices() and next(policy, Points& x) "
                "writing the next LR frame's positions, for exec::seq and exec::omp");
  return FrameSource<S>;
}

struct LiveOptions {
  bool pipelined = true;
  /// Pipelined: OpenMP threads of the source's thread and of the method's (the calling thread).
  /// Both 0: the first frame runs unpipelined, timed, and the slower stage gets every core, the
  /// other one thread (one thread more than cores). Split evenly on 2 cores, the slower stage
  /// runs at half speed: on the face (`simsr animate`, anger) the network took 3.65 fps end to end
  /// split 1 + 1, 5.49 fps with 1 + 2, 5.33 fps unpipelined; with Embedded at the paper's LR size
  /// the simulation is the slower stage and needs the cores instead (3.95 fps with 1 thread).
  int source_threads = 0, method_threads = 0;
};

/// Times of one live run (seconds, summed over the frames).
struct LiveReport {
  bool pipelined = true;
  Index frames = 0;
  int source_threads = 0, method_threads = 0;
  double source_seconds = 0;  ///< in the source's next()
  double method_seconds = 0;  ///< in the method's apply() (displacement in, HR positions out)
  double wall_seconds = 0;    ///< first frame asked for to last frame handed to the sink
  double first_frame_seconds = 0;  ///< latency of the first HR frame
  double source_fps() const { return source_seconds > 0 ? double(frames) / source_seconds : 0; }
  double method_fps() const { return method_seconds > 0 ? double(frames) / method_seconds : 0; }
  double end_to_end_fps() const { return wall_seconds > 0 ? double(frames) / wall_seconds : 0; }
  nlohmann::ordered_json to_json() const {
    return {{"pipelined", pipelined},         {"frames", frames},
            {"source_threads", source_threads}, {"method_threads", method_threads},
            {"lr_simulation_fps", source_fps()}, {"inference_fps", method_fps()},
            {"end_to_end_fps", end_to_end_fps()}, {"lr_simulation_seconds", source_seconds},
            {"inference_seconds", method_seconds}, {"wall_seconds", wall_seconds},
            {"first_frame_seconds", first_frame_seconds}};
  }
};

namespace detail {

inline double seconds_since(std::chrono::steady_clock::time_point t) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count(); }

}  // namespace detail

/// Runs `source` frame after frame through `method` (fitted on lr_rest / hr_rest) and hands every
/// HR frame to `sink(frame, lr_positions, hr_positions)`; see the file comment.
template <exec::HostPolicy P, FrameSource S, interp::Interpolator I, class Sink>
  requires std::invocable<Sink&, Index, const Points<Scalar>&, const Points<Scalar>&>
LiveReport run_live(P policy, S& source, const I& method, const Points<Scalar>& lr_rest, const Points<Scalar>& hr_rest, Sink&& sink,
                    const LiveOptions& o = {}) {
  const Index n = lr_rest.rows(), m = hr_rest.rows(), frames = source.num_frames();
  if (source.num_vertices() != n || method.num_lr() != n || method.num_hr() != m)
    throw ShapeError("pipeline::run_live: source's and method's (N, M) against the rest shapes'", {n, m},
                     {source.num_vertices(), method.num_lr(), method.num_hr()});
  if (frames < 0) throw ArgumentError("pipeline::run_live: the source has a negative frame count");
  using T = typename I::scalar_type;
  Points<T> lr_disp(n, 3), hr_disp(m, 3);
  Points<Scalar> hr(m, 3);
  auto upsample = [&](const Points<Scalar>& lr, Index f) {
    interp::upsample_positions(policy, method, lr_rest, hr_rest, lr, lr_disp, hr_disp, hr, "pipeline::run_live", f);
  };
  LiveReport r;
  r.pipelined = o.pipelined;
  r.frames = frames;
  const auto start = std::chrono::steady_clock::now();
  // One frame on the calling thread, source then method, each timed: the unpipelined run, and the
  // pipelined run's first frame when it decides the split. Returns the two times.
  auto alone = [&](Points<Scalar>& lr, Index f) {
    auto t = std::chrono::steady_clock::now();
    source.next(policy, lr);
    const double ts = detail::seconds_since(t);
    t = std::chrono::steady_clock::now();
    upsample(lr, f);
    const double tm = detail::seconds_since(t);
    r.source_seconds += ts;
    r.method_seconds += tm;
    sink(f, std::as_const(lr), std::as_const(hr));
    if (f == 0) r.first_frame_seconds = detail::seconds_since(start);
    return std::pair{ts, tm};
  };

  if (!o.pipelined) {
    r.source_threads = r.method_threads = exec::omp_max_threads();
    Points<Scalar> lr(n, 3);
    for (Index f = 0; f < frames; ++f) alone(lr, f);
    r.wall_seconds = detail::seconds_since(start);
    return r;
  }

  const int cores = std::max(1, exec::omp_max_threads());
  // Two slots: the source fills slot (f % 2) while the method reads the other. produced / consumed
  // count frames; the source may run at most one frame ahead of the method's current one.
  Points<Scalar> slot[2] = {Points<Scalar>(n, 3), Points<Scalar>(n, 3)};
  Index first = 0;  // the first frame the two threads run
  r.source_threads = o.source_threads;
  r.method_threads = o.method_threads;
  if (o.source_threads <= 0 && o.method_threads <= 0 && frames > 0) {
    // the split from the first frame, run alone: the slower stage gets every core
    const auto [ts, tm] = alone(slot[0], 0);
    r.source_threads = ts > tm ? cores : 1;
    r.method_threads = ts > tm ? 1 : cores;
    first = 1;
  }
  if (r.source_threads <= 0) r.source_threads = 1;
  if (r.method_threads <= 0) r.method_threads = cores;
  std::mutex mutex;
  std::condition_variable changed;
  Index produced = first, consumed = first;
  bool stop = false;
  std::exception_ptr source_error;
  double source_seconds = 0;
  std::thread producer([&] {
    exec::OmpThreadLimit share(r.source_threads);
    try {
      for (Index f = first; f < frames; ++f) {
        {
          std::unique_lock lock(mutex);
          changed.wait(lock, [&] { return stop || f - consumed < 2; });
          if (stop) return;
        }
        const auto t = std::chrono::steady_clock::now();
        source.next(policy, slot[f % 2]);
        source_seconds += detail::seconds_since(t);
        {
          std::lock_guard lock(mutex);
          produced = f + 1;
        }
        changed.notify_all();
      }
    } catch (...) {
      std::lock_guard lock(mutex);
      source_error = std::current_exception();
      stop = true;
      changed.notify_all();
    }
  });
  std::exception_ptr method_error;
  {
    exec::OmpThreadLimit share(r.method_threads);
    try {
      for (Index f = first; f < frames; ++f) {
        {
          std::unique_lock lock(mutex);
          changed.wait(lock, [&] { return stop || produced > f; });
          if (produced <= f) break;  // the source failed
        }
        const auto t = std::chrono::steady_clock::now();
        upsample(slot[f % 2], f);
        r.method_seconds += detail::seconds_since(t);
        sink(f, std::as_const(slot[f % 2]), std::as_const(hr));
        if (f == 0) r.first_frame_seconds = detail::seconds_since(start);
        {
          std::lock_guard lock(mutex);
          consumed = f + 1;
        }
        changed.notify_all();
      }
    } catch (...) {
      method_error = std::current_exception();
      std::lock_guard lock(mutex);
      stop = true;
      changed.notify_all();
    }
  }
  producer.join();
  r.wall_seconds = detail::seconds_since(start);
  r.source_seconds += source_seconds;
  if (method_error) std::rethrow_exception(method_error);
  if (source_error) std::rethrow_exception(source_error);
  return r;
}

}  // namespace simsr::pipeline
