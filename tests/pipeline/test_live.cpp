// pipeline::run_live with a synthetic source (a smooth wave over random rest points) and a linear
// interpolator (hr = A · lr displacement): every frame reaches the sink once, in order, equal to
// the method applied by hand; pipelined and unpipelined give the same frames; the pipeline really
// overlaps (the method's frame t waits for the source to start frame t+1, which only a concurrent
// source can do) and never runs more than one frame ahead; each stage runs with its thread share,
// by default the slower stage with every core;
// a failure in either stage is rethrown and nothing after it reaches the sink.
#include <simsr/pipeline/live.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace simsr;

namespace pipeline_live {

/// LR frame f: rest + a wave that changes every frame.
struct WaveSource {
  Points<> rest;
  Index frames = 0;
  Index produced = 0;
  std::function<void(Index)> before;  ///< called with the frame about to be computed
  std::vector<int> threads;           ///< OpenMP threads seen in each next()
  static Points<> frame_of(const Points<>& rest, Index f) {
    Points<> x = rest;
    for (Index i = 0; i < x.rows(); ++i)
      for (int c = 0; c < 3; ++c) x(i, c) += 0.01 * std::sin(0.7 * double(f) + 1.3 * double(i) + 2.1 * c);
    return x;
  }
  Index num_frames() const { return frames; }
  Index num_vertices() const { return rest.rows(); }
  template <class P>
  void next(P, Points<>& x) {
    if (before) before(produced);
    threads.push_back(exec::omp_max_threads());
    x = frame_of(rest, produced++);
  }
};
static_assert(pipeline::FrameSource<WaveSource>);
static_assert(!pipeline::FrameSource<int>);

/// hr = A · lr (an Interpolator the test can watch).
struct LinearMethod {
  using scalar_type = Scalar;
  Eigen::MatrixXd A;
  std::function<void(Index)> before;  ///< called with the frame about to be applied
  mutable Index applied = 0;
  mutable std::vector<int> threads;
  template <class P>
  void fit(P, interp::UpsamplingProblem<Scalar>&) {}
  template <class P>
  void apply(P, const Points<>& lr, Points<>& hr) const {
    if (before) before(applied);
    threads.push_back(exec::omp_max_threads());
    hr = A * lr;
    ++applied;
  }
  Index num_lr() const { return A.cols(); }
  Index num_hr() const { return A.rows(); }
};
static_assert(interp::Interpolator<LinearMethod>);

struct Setup {
  Points<> lr_rest, hr_rest;
  WaveSource source;
  LinearMethod method;
  Setup(Index n, Index m, Index frames, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    lr_rest = Points<>::NullaryExpr(n, 3, [&] { return u(rng); });
    hr_rest = Points<>::NullaryExpr(m, 3, [&] { return u(rng); });
    method.A = Eigen::MatrixXd::NullaryExpr(m, n, [&] { return u(rng); });
    source.rest = lr_rest;
    source.frames = frames;
  }
};

struct Received {
  std::vector<Index> order;
  std::vector<Points<>> lr, hr;
};

pipeline::LiveReport run(Setup& s, bool pipelined, Received& got, pipeline::LiveOptions o = {}) {
  o.pipelined = pipelined;
  return pipeline::run_live(exec::omp, s.source, s.method, s.lr_rest, s.hr_rest, [&](Index f, const Points<>& lr, const Points<>& hr) {
    got.order.push_back(f);
    got.lr.push_back(lr);
    got.hr.push_back(hr);
  }, o);
}

TEST_CASE("pipeline::run_live: every frame once, in order, as the method applied by hand; pipelined = unpipelined") {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    const Index n = 5 + seed, m = 20 + 3 * seed, frames = Index(seed % 3 == 0 ? 1 : 3 + 2 * seed);
    Received a, b;
    Setup s1(n, m, frames, seed), s2(n, m, frames, seed);
    const auto ra = run(s1, false, a), rb = run(s2, true, b);
    for (const auto* r : {&ra, &rb}) {
      CHECK(r->frames == frames);
      CHECK(r->wall_seconds >= r->method_seconds);
      CHECK(r->source_seconds > 0);
      CHECK(r->end_to_end_fps() > 0);
      CHECK(r->first_frame_seconds > 0);
      CHECK(r->first_frame_seconds <= r->wall_seconds);
    }
    CHECK_FALSE(ra.pipelined);
    CHECK(rb.pipelined);
    REQUIRE(a.order.size() == std::size_t(frames));
    REQUIRE(b.order.size() == std::size_t(frames));
    for (Index f = 0; f < frames; ++f) {
      CHECK(a.order[std::size_t(f)] == f);
      CHECK(b.order[std::size_t(f)] == f);
      const Points<> lr = WaveSource::frame_of(s1.lr_rest, f);
      const Points<> hr = s1.hr_rest + s1.method.A * (lr - s1.lr_rest);
      CHECK(a.lr[std::size_t(f)] == lr);
      CHECK((a.hr[std::size_t(f)] - hr).cwiseAbs().maxCoeff() <= 1e-14);  // the product evaluated another way
      CHECK(b.lr[std::size_t(f)] == lr);
      CHECK(b.hr[std::size_t(f)] == a.hr[std::size_t(f)]);
    }
  }
}

TEST_CASE("pipeline::run_live: pipelined, the source computes frame t+1 while the method runs on frame t, at most one frame ahead") {
  const Index frames = 8;
  Setup s(6, 9, frames, 3);
  std::mutex mutex;
  std::condition_variable cv;
  Index source_started = -1;  // last frame whose next() began
  std::atomic<Index> sunk{0};
  bool waited_too_long = false, ran_ahead = false;
  s.source.before = [&](Index f) {
    // frame f may start only once frame f-2 left the method (two slots, one frame of latency)
    if (sunk.load() < f - 1) ran_ahead = true;
    std::lock_guard lock(mutex);
    source_started = f;
    cv.notify_all();
  };
  s.method.before = [&](Index f) {
    if (f + 1 >= frames) return;
    // only a source running beside the method can start frame f+1 now: sequentially it would
    // wait for this apply to end, and the wait below would time out
    std::unique_lock lock(mutex);
    if (!cv.wait_for(lock, std::chrono::seconds(20), [&] { return source_started >= f + 1; })) waited_too_long = true;
  };
  pipeline::LiveOptions o;  // threads given: every frame pipelined (the automatic split runs frame 0 alone)
  o.source_threads = o.method_threads = 1;
  const auto r = pipeline::run_live(exec::omp, s.source, s.method, s.lr_rest, s.hr_rest, [&](Index, const Points<>&, const Points<>&) { ++sunk; }, o);
  CHECK_FALSE(waited_too_long);
  CHECK_FALSE(ran_ahead);
  CHECK(sunk.load() == frames);
  CHECK(r.frames == frames);
}

TEST_CASE("pipeline::run_live: each stage runs with its share of the threads; the caller's count comes back") {
  const int before = exec::omp_max_threads();
  Setup s(4, 7, 5, 9);
  Received got;
  pipeline::LiveOptions o;
  o.source_threads = 1;
  o.method_threads = 3;
  const auto r = run(s, true, got, o);
  CHECK(r.source_threads == 1);
  CHECK(r.method_threads == 3);
#if defined(_OPENMP)
  for (int t : s.source.threads) CHECK(t == 1);
  for (int t : s.method.threads) CHECK(t == 3);
#endif
  CHECK(exec::omp_max_threads() == before);
  // unpipelined: both on the calling thread with all of its threads
  Setup u(4, 7, 3, 9);
  Received ug;
  run(u, false, ug);
  for (int t : u.source.threads) CHECK(t == before);
  for (int t : u.method.threads) CHECK(t == before);
}

TEST_CASE("pipeline::run_live: by default the slower stage (timed on the first frame, run alone) gets every core, the other one thread") {
  const int cores = std::max(1, exec::omp_max_threads());
  for (bool slow_source : {true, false}) {
    CAPTURE(slow_source);
    Setup s(4, 7, 6, 5);
    auto wait = [](Index) { std::this_thread::sleep_for(std::chrono::milliseconds(20)); };
    if (slow_source)
      s.source.before = wait;
    else
      s.method.before = wait;
    Received got;
    const auto r = run(s, true, got);
    CHECK(r.source_threads == (slow_source ? cores : 1));
    CHECK(r.method_threads == (slow_source ? 1 : cores));
    CHECK(got.order == std::vector<Index>{0, 1, 2, 3, 4, 5});
#if defined(_OPENMP)
    // frame 0 ran on the calling thread with all of its threads, the rest with their shares
    CHECK(s.source.threads[0] == cores);
    CHECK(s.method.threads[0] == cores);
    for (std::size_t f = 1; f < s.source.threads.size(); ++f) CHECK(s.source.threads[f] == r.source_threads);
    for (std::size_t f = 1; f < s.method.threads.size(); ++f) CHECK(s.method.threads[f] == r.method_threads);
#endif
  }
}

TEST_CASE("pipeline::run_live: a failure in either stage is rethrown; nothing after it reaches the sink") {
  for (bool pipelined : {false, true}) {
    CAPTURE(pipelined);
    {
      Setup s(4, 6, 9, 2);
      s.source.before = [](Index f) {
        if (f == 3) throw ConvergenceError("test source", 30, 1.0);
      };
      Received got;
      CHECK_THROWS_AS(run(s, pipelined, got), ConvergenceError);
      CHECK(got.order == std::vector<Index>{0, 1, 2});
    }
    {
      Setup s(4, 6, 9, 2);
      s.method.before = [](Index f) {
        if (f == 2) throw std::runtime_error("test method");
      };
      Received got;
      CHECK_THROWS_WITH(run(s, pipelined, got), "test method");
      CHECK(got.order == std::vector<Index>{0, 1});
      CHECK(s.source.produced <= 4);  // at most one frame beyond the one in the method
    }
    {
      Setup s(4, 6, 5, 2);
      s.method.A(2, 1) = std::nan("");
      Received got;
      CHECK_THROWS_WITH_AS(run(s, pipelined, got), doctest::Contains("frame 0"), NumericalError);
      CHECK(got.order.empty());
    }
  }
  Setup s(4, 6, 5, 2);
  Received got;
  const Points<> wrong = Points<>::Zero(5, 3);
  CHECK_THROWS_AS(pipeline::run_live(exec::omp, s.source, s.method, wrong, s.hr_rest, [](Index, const Points<>&, const Points<>&) {}), ShapeError);
}

}  // namespace pipeline_live
