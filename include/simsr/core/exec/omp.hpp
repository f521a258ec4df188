#pragma once
/// \file
/// OpenMP backend. Needs simsr::openmp (-fopenmp); without it, instantiating an omp algorithm is a
/// static_assert that says so. Exceptions thrown by a body are caught in the worker and the first
/// one is rethrown on the calling thread (an exception escaping an OpenMP region would terminate).
/// Eigen stays single-threaded inside these regions (it checks omp_get_num_threads() > 1), and on
/// the calling thread when a loop runs there (EigenSingleThreaded), so there is no nested
/// parallelism.
///
/// A loop forks a team only when that pays (OmpFork::adaptive, the default). Loops are timed: each
/// call site (one per body type) learns its work per item and what its regions cost beyond their
/// work (waking the team, the join, a thread the OS did not run: wall − work / threads), and the
/// process learns the same over all regions. A loop whose work would save less than that price —
/// the site's own, but at least a quarter of the process-wide one — runs on the calling thread.
/// On an idle machine a region costs microseconds, so only tiny loops stay on the caller; beside
/// a busy process it costs milliseconds — libgomp's waiting threads spin (OMP_WAIT_POLICY is read
/// once, at program start), and a join waits for a thread the scheduler put off — and the loops
/// run on the caller instead of collapsing (README, "Execution policies"). Now and then a region
/// is run anyway to measure its price again, so the threads come back when the machine is idle
/// again. Inside a region the chunks are handed out dynamically: a thread that is not running
/// does not hold up the others' work.
/// None of this changes a result: chunks are fixed and combined in order whoever runs them.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <type_traits>
#include <utility>
#include <vector>

#include "../eigen_threads.hpp"
#include "chunks.hpp"
#include "policy.hpp"
#include "seq.hpp"

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace simsr::exec {

/// When an exec::omp loop forks a team of threads.
enum class OmpFork {
  adaptive,  ///< when the loop's measured work pays for the measured cost of a region (default)
  always,    ///< every loop of at least 2 items (no measurement): for benchmarks and tests
  never,     ///< no loop: all run on the calling thread, as exec::seq does (for tests)
};

namespace detail {
/// Remembers the first exception thrown by any worker.
class FirstException {
 public:
  template <class F>
  void run(F&& f) noexcept {
    try {
      f();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!first_) first_ = std::current_exception();
    }
  }
  void rethrow() const {
    if (first_) std::rethrow_exception(first_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr first_;
};

inline std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Process-wide state of exec::omp's fork decisions.
struct RegionCost {
  /// Moving average of (wall time − work / threads) over every recent region, ns: what a call
  /// site that has not forked yet expects a region to cost.
  std::atomic<double> excess_ns{5000.0};
  /// steady clock (ns) of the last probe: at most one per 64 process-wide prices (1 ms to 0.25 s).
  std::atomic<std::int64_t> last_probe_ns{0};
  /// OmpFork; -1 until first read (SIMSR_OMP_FORK=always or =never in the environment selects
  /// that mode).
  std::atomic<int> mode{-1};
};
inline RegionCost region_cost;

/// What one call site (identified by its body's type) has measured.
struct SiteCost {
  std::atomic<double> ns_per_item{-1.0};  ///< work per item; < 0 until measured
  /// Moving average of its regions' (wall time − work / threads); < 0 until it forked. Per site:
  /// a large loop's imbalance (a few % of milliseconds) is not a small loop's price.
  std::atomic<double> excess_ns{-1.0};
  std::atomic<std::int64_t> last_region_ns{0};  ///< steady clock of its last region
};
template <class Site>
inline SiteCost site_cost;

/// Forking must save at least this much (ns) beyond the measured price of a region.
inline constexpr double min_fork_saving_ns = 2000.0;
/// Serial runs predicted shorter than this (ns) are not timed (two clock reads cost ~50 ns).
inline constexpr double min_timed_ns = 2000.0;

inline OmpFork omp_fork_mode() {
  int m = region_cost.mode.load(std::memory_order_relaxed);
  if (m < 0) {
    const char* env = std::getenv("SIMSR_OMP_FORK");
    m = int(OmpFork::adaptive);
    if (env && std::strcmp(env, "always") == 0) m = int(OmpFork::always);
    if (env && std::strcmp(env, "never") == 0) m = int(OmpFork::never);
    region_cost.mode.store(m, std::memory_order_relaxed);
  }
  return OmpFork(m);
}

/// Per-item cost: falls fast (a measurement can only be inflated, by preemption or a cold cache)
/// and rises slowly.
inline void record_work(SiteCost& site, Index n, double work_ns) {
  const double sample = work_ns / double(std::max<Index>(n, 1));
  const double old = site.ns_per_item.load(std::memory_order_relaxed);
  site.ns_per_item.store(old < 0 ? sample : old + (sample - old) * (sample < old ? 0.5 : 0.0625), std::memory_order_relaxed);
}

inline void record_region(SiteCost& site, double wall_ns, double work_ns, int threads) {
  const double sample = std::max(0.0, wall_ns - work_ns / threads);
  const double all = region_cost.excess_ns.load(std::memory_order_relaxed);
  region_cost.excess_ns.store(all + (sample - all) * 0.125, std::memory_order_relaxed);
  const double old = site.excess_ns.load(std::memory_order_relaxed);
  site.excess_ns.store(old < 0 ? sample : old + (sample - old) * 0.25, std::memory_order_relaxed);
  site.last_region_ns.store(now_ns(), std::memory_order_relaxed);
}

/// How an omp loop over n items at `site` runs now: 0 on the calling thread untimed, 1 on the
/// calling thread timed, 2 in a team of `threads`.
inline int fork_decision(SiteCost& site, Index n, int threads) {
  if (threads < 2 || n < 2) return 0;
  const OmpFork mode = omp_fork_mode();
  if (mode != OmpFork::adaptive) return mode == OmpFork::always ? 2 : 0;
  const double per_item = site.ns_per_item.load(std::memory_order_relaxed);
  // The site's own price of a region, but at least a quarter of the process-wide one: that rises
  // at once for every site when the machine gets busy.
  const double site_excess = site.excess_ns.load(std::memory_order_relaxed);
  const double all_excess = region_cost.excess_ns.load(std::memory_order_relaxed);
  const double excess = site_excess >= 0 ? std::max(site_excess, 0.25 * all_excess) : all_excess;
  // First call: a region measures the work (and the region's price), unless regions are dear.
  if (per_item < 0) return excess < 50000.0 ? 2 : 1;
  const double work = per_item * double(n);
  const double saving = work * (1.0 - 1.0 / double(std::min<Index>(threads, n)));
  if (saving > excess + min_fork_saving_ns) return 2;
  // A probe measures the price again (the machine may be idle again): when the site's last region
  // is 64 of its prices ago and no other site probed within 64 process-wide prices (1 ms to 0.25 s
  // each), so that beside a busy process the probes of all sites cost ~1 %.
  if (saving > min_fork_saving_ns) {
    const std::int64_t now = now_ns();
    std::int64_t last = region_cost.last_probe_ns.load(std::memory_order_relaxed);
    if (double(now - site.last_region_ns.load(std::memory_order_relaxed)) > std::clamp(64.0 * excess, 1e6, 2.5e8) &&
        double(now - last) > std::clamp(64.0 * all_excess, 1e6, 2.5e8) &&
        region_cost.last_probe_ns.compare_exchange_strong(last, now, std::memory_order_relaxed))
      return 2;
  }
  return work >= min_timed_ns ? 1 : 0;
}

#if defined(_OPENMP)
/// Wall time, summed busy time of the threads (ns) and team size of one region.
struct TeamRun {
  double wall_ns = 0, work_ns = 0;
  int threads = 1;
};

/// Runs chunk(c) for c in [0, chunks) on a team of at most `threads` (dynamic hand-out) and
/// rethrows the first exception.
template <class Chunk>
TeamRun run_team(Index chunks, int threads, Chunk&& chunk) {
  TeamRun run;
  run.threads = int(std::min<Index>(threads, chunks));
  FirstException error;
  std::atomic<std::int64_t> busy{0};
  const std::int64_t t0 = now_ns();
#pragma omp parallel num_threads(run.threads)
  {
    const std::int64_t start = now_ns();
#pragma omp for schedule(dynamic, 1) nowait
    for (Index c = 0; c < chunks; ++c) error.run([&] { chunk(c); });
    busy.fetch_add(now_ns() - start, std::memory_order_relaxed);
  }
  run.wall_ns = double(now_ns() - t0);
  error.rethrow();
  run.work_ns = double(busy.load(std::memory_order_relaxed));
  return run;
}

/// Makes this thread's OpenMP ICVs its own now, once per thread. libgomp keeps a thread's ICVs in
/// a task it mallocs at the thread's first write of one (omp_set_num_threads: EigenSingleThreaded,
/// on the serial path below); left to that moment, the first loop that happens to run on the
/// caller instead of forking — a timing decision — would allocate, and a warm call would not be
/// allocation-free (tests/core/test_allocation.cpp).
inline void own_thread_icvs() {
  thread_local const bool owned = [] {
    omp_set_num_threads(omp_get_max_threads());
    return true;
  }();
  (void)owned;
}

/// Runs `serial()` or `parallel(threads)` (a TeamRun) as fork_decision says and records what it
/// measured. The serial path keeps Eigen single-threaded, as it is inside a region.
template <class Site, class Serial, class Parallel>
void dispatch(Index n, Serial&& serial, Parallel&& parallel) {
  own_thread_icvs();
  SiteCost& site = site_cost<Site>;
  const int threads = omp_in_parallel() ? 1 : omp_get_max_threads();
  const int decision = fork_decision(site, n, threads);
  if (decision < 2) {
    // On the calling thread outside a region, where Eigen would start threads of its own.
    const EigenSingleThreaded eigen_serial;
    if (decision == 0) return serial();
    const std::int64_t t0 = now_ns();
    serial();
    record_work(site, n, double(now_ns() - t0));
    return;
  }
  const TeamRun run = parallel(threads);
  if (omp_fork_mode() == OmpFork::adaptive) {
    record_work(site, n, run.work_ns);
    record_region(site, run.wall_ns, run.work_ns, run.threads);
  }
}
#endif
}  // namespace detail

/// static_assert text for omp algorithms instantiated without OpenMP.
#define SIMSR_OMP_MISSING                                                                               \
  "simsr::exec::omp needs OpenMP: link the simsr::openmp target (find_package(simsr CONFIG COMPONENTS "     \
  "openmp)) or compile with -fopenmp, or use exec::seq"

/// Number of threads an omp region would use here (1 without OpenMP).
inline int omp_max_threads() {
#if defined(_OPENMP)
  return omp_get_max_threads();
#else
  return 1;
#endif
}

/// Sets when exec::omp loops fork a team, process-wide (the environment variable
/// SIMSR_OMP_FORK=always or =never sets that mode at start-up).
inline void set_omp_fork(OmpFork mode) { detail::region_cost.mode.store(int(mode), std::memory_order_relaxed); }
/// When exec::omp loops fork a team (OmpFork::adaptive unless set otherwise).
inline OmpFork omp_fork() { return detail::omp_fork_mode(); }

/// Calls `body(i)` for i = 0..n-1 on OpenMP threads (contiguous chunks, handed out dynamically),
/// or on the calling thread when forking does not pay (see the file comment).
template <class Body>
void parallel_for(omp_t, Index n, Body&& body) {
#if defined(_OPENMP)
  detail::dispatch<std::remove_cvref_t<Body>>(
      n, [&] { parallel_for(seq, n, body); },
      [&](int threads) {
        const Index nc = std::min<Index>(n, 8 * Index(threads));
        return detail::run_team(nc, threads, [&](Index c) {
          const auto [b, e] = chunk_range(n, nc, c);
          for (Index i = b; i < e; ++i) body(i);
        });
      });
#else
  static_assert(detail::dependent_false<Body>, SIMSR_OMP_MISSING);
  (void)n, (void)body;
#endif
}

/// Same contract and the same rounding as the seq overload: chunks run in parallel, then their
/// results are combined in chunk order on the calling thread.
template <class T, class Map, class Combine>
T parallel_reduce(omp_t, Index n, T identity, Map&& map, Combine&& combine, Index chunks = default_chunks) {
#if defined(_OPENMP)
  T total = identity;
  std::vector<T> parts;
  detail::dispatch<std::remove_cvref_t<Map>>(
      n, [&] { total = parallel_reduce(seq, n, identity, map, combine, chunks); },
      [&](int threads) {
        const Index nc = chunk_count(n, chunks);
        parts.assign(static_cast<std::size_t>(nc), identity);
        return detail::run_team(nc, threads, [&](Index c) {
          auto [b, e] = chunk_range(n, nc, c);
          T part = identity;
          for (Index i = b; i < e; ++i) part = combine(part, map(i));
          parts[static_cast<std::size_t>(c)] = std::move(part);
        });
      });
  for (auto& p : parts) total = combine(total, p);
  return total;
#else
  static_assert(detail::dependent_false<Map>, SIMSR_OMP_MISSING);
  (void)n, (void)map, (void)combine, (void)chunks;
  return identity;
#endif
}

/// Same contract and result as the seq overload; chunks fill their own accumulators in parallel
/// and are merged in chunk order afterwards.
template <class Make, class Body, class Merge>
auto parallel_for_accumulate(omp_t, Index n, Make&& make, Body&& body, Merge&& merge, Index chunks = 16) {
#if defined(_OPENMP)
  using Acc = decltype(make());
  std::vector<Acc> accs;
  detail::dispatch<std::remove_cvref_t<Body>>(
      n, [&] { accs.push_back(parallel_for_accumulate(seq, n, make, body, merge, chunks)); },
      [&](int threads) {
        const Index nc = chunk_count(n, chunks);
        accs.reserve(static_cast<std::size_t>(nc));
        for (Index c = 0; c < nc; ++c) accs.push_back(make());
        return detail::run_team(nc, threads, [&](Index c) {
          auto [b, e] = chunk_range(n, nc, c);
          for (Index i = b; i < e; ++i) body(i, accs[static_cast<std::size_t>(c)]);
        });
      });
  Acc total = std::move(accs[0]);
  for (std::size_t c = 1; c < accs.size(); ++c) merge(total, std::move(accs[c]));
  return total;
#else
  static_assert(detail::dependent_false<Make>, SIMSR_OMP_MISSING);
  (void)n, (void)body, (void)merge, (void)chunks;
  return make();
#endif
}

}  // namespace simsr::exec
