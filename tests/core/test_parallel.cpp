#include <doctest/doctest.h>

#include <simsr/core/core.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <vector>

using namespace simsr;

namespace {
/// Sets exec::omp's fork mode for a scope (adaptive again afterwards).
struct ForkMode {
  explicit ForkMode(exec::OmpFork mode) { exec::set_omp_fork(mode); }
  ~ForkMode() { exec::set_omp_fork(exec::OmpFork::adaptive); }
};

std::vector<double> random_values(Index n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::lognormal_distribution<double> d(0.0, 3.0);  // wide dynamic range: rounding order matters
  std::vector<double> v(static_cast<std::size_t>(n));
  for (auto& x : v) x = (rng() & 1 ? 1 : -1) * d(rng);
  return v;
}
}  // namespace

TEST_CASE("chunk_range covers [0, n) exactly once in order") {
  for (Index n : {0, 1, 5, 63, 64, 65, 1000, 12345})
    for (Index req : {1, 3, 16, 64, 100000}) {
      const Index nc = exec::chunk_count(n, req);
      Index next = 0;
      for (Index c = 0; c < nc; ++c) {
        auto [b, e] = exec::chunk_range(n, nc, c);
        CHECK(b == next);
        CHECK(e >= b);
        next = e;
      }
      CHECK(next == n);
    }
}

TEST_CASE("for_chunks: every chunk once, per-worker ranges, the same chunks under seq and omp") {
  for (Index n : {0, 1, 7, 64, 1000, 4097})
    for (Index req : {1, 5, 64}) {
      const Index nc = exec::chunk_count(n, req);
      CHECK(exec::worker_count(exec::seq, nc) == 1);
      const Index wo = exec::worker_count(exec::omp, nc);
      CHECK(wo >= 1);
      CHECK(wo <= nc);
      for (Index workers : {Index(1), wo}) {
        std::vector<int> seen(std::size_t(nc), 0);
        std::vector<Index> covered(std::size_t(n), 0);
        std::vector<std::pair<Index, Index>> ranges(static_cast<std::size_t>(nc));
        std::vector<Index> worker(static_cast<std::size_t>(nc), -1);
        auto body = [&](Index w, Index c, Index b, Index e) {  // no doctest macro here: it runs on workers
          worker[std::size_t(c)] = w;
          ++seen[std::size_t(c)];
          ranges[std::size_t(c)] = {b, e};
          for (Index i = b; i < e; ++i) ++covered[std::size_t(i)];
        };
        if (workers == 1)
          exec::for_chunks(exec::seq, n, nc, workers, body);
        else
          exec::for_chunks(exec::omp, n, nc, workers, body);
        for (Index c = 0; c < nc; ++c) {
          CHECK(seen[std::size_t(c)] == 1);
          CHECK(worker[std::size_t(c)] == c % workers);  // worker w takes chunks w, w + workers, …
          CHECK((ranges[std::size_t(c)] == exec::chunk_range(n, nc, c)));
          CHECK(ranges[std::size_t(c)].second - ranges[std::size_t(c)].first <= exec::max_chunk_size(n, nc));
        }
        for (Index i = 0; i < n; ++i) CHECK(covered[std::size_t(i)] == 1);
      }
    }
}

TEST_CASE("parallel_for: seq and omp write the same values") {
  exec::OmpFork mode = exec::OmpFork::adaptive;
  SUBCASE("exec::omp forking always") { mode = exec::OmpFork::always; }
  SUBCASE("exec::omp adaptive") {}
  const ForkMode fork(mode);
  for (unsigned seed = 0; seed < 20; ++seed) {
    const Index n = 1 + Index(seed) * 997;
    auto x = random_values(n, seed);
    std::vector<double> a(x.size()), b(x.size());
    auto body = [&](std::vector<double>& out) { return [&](Index i) { out[i] = std::sin(x[i]) * x[i] + 1.0 / (1.0 + x[i] * x[i]); }; };
    exec::parallel_for(exec::seq, n, body(a));
    exec::parallel_for(exec::omp, n, body(b));
    CHECK(a == b);
  }
}

TEST_CASE("parallel_reduce: seq and omp are bitwise identical and match a plain sum closely") {
  exec::OmpFork mode = exec::OmpFork::adaptive;
  SUBCASE("exec::omp forking always") { mode = exec::OmpFork::always; }
  SUBCASE("exec::omp adaptive") {}
  const ForkMode fork(mode);
  for (unsigned seed = 0; seed < 50; ++seed) {
    const Index n = Index(seed) * 4111 + Index(seed % 7);
    auto x = random_values(n, 100 + seed);
    auto map = [&](Index i) { return x[i]; };
    const double s = exec::parallel_reduce(exec::seq, n, 0.0, map, std::plus<>{});
    const double o = exec::parallel_reduce(exec::omp, n, 0.0, map, std::plus<>{});
    CHECK(s == o);  // bitwise: same chunking, same combination order
    long double exact = 0;
    double absum = 0;
    for (double v : x) exact += v, absum += std::abs(v);
    CHECK(std::abs(double(exact) - s) <= 1e-12 * absum + 1e-300);
    for (Index chunks : {1, 2, 7, 1000}) {
      CHECK(exec::parallel_reduce(exec::seq, n, 0.0, map, std::plus<>{}, chunks) ==
            exec::parallel_reduce(exec::omp, n, 0.0, map, std::plus<>{}, chunks));
    }
  }
}

TEST_CASE("parallel_reduce with a non-commutative-safe combine (max with index)") {
  exec::OmpFork mode = exec::OmpFork::adaptive;
  SUBCASE("exec::omp forking always") { mode = exec::OmpFork::always; }
  SUBCASE("exec::omp adaptive") {}
  const ForkMode fork(mode);
  auto x = random_values(100000, 7);
  using P = std::pair<double, Index>;
  auto map = [&](Index i) { return P{x[i], i}; };
  auto best = [](const P& a, const P& b) { return b.first > a.first ? b : a; };
  const P s = exec::parallel_reduce(exec::seq, Index(x.size()), P{-1e300, -1}, map, best);
  const P o = exec::parallel_reduce(exec::omp, Index(x.size()), P{-1e300, -1}, map, best);
  const auto it = std::max_element(x.begin(), x.end());
  CHECK(s == o);
  CHECK(s.second == it - x.begin());
}

TEST_CASE("parallel_for_accumulate: scatter-add like FEM assembly, seq == omp bitwise") {
  exec::OmpFork mode = exec::OmpFork::adaptive;
  SUBCASE("exec::omp forking always") { mode = exec::OmpFork::always; }
  SUBCASE("exec::omp adaptive") {}
  const ForkMode fork(mode);
  // Random "elements" scattering values into a shared vector, as element gradients do.
  std::mt19937 rng(3);
  const Index nodes = 500, elems = 20000;
  std::vector<std::array<Index, 4>> conn(elems);
  std::uniform_int_distribution<Index> node(0, nodes - 1);
  for (auto& e : conn)
    for (auto& v : e) v = node(rng);
  auto vals = random_values(elems * 4, 11);
  auto make = [&] { return std::vector<double>(nodes, 0.0); };
  auto body = [&](Index e, std::vector<double>& acc) {
    for (int k = 0; k < 4; ++k) acc[conn[e][k]] += vals[e * 4 + k];
  };
  auto merge = [](std::vector<double>& total, std::vector<double>&& part) {
    for (std::size_t i = 0; i < total.size(); ++i) total[i] += part[i];
  };
  const auto s = exec::parallel_for_accumulate(exec::seq, elems, make, body, merge);
  const auto o = exec::parallel_for_accumulate(exec::omp, elems, make, body, merge);
  CHECK(s == o);
  std::vector<long double> ref(nodes, 0);
  for (Index e = 0; e < elems; ++e)
    for (int k = 0; k < 4; ++k) ref[conn[e][k]] += vals[e * 4 + k];
  for (Index i = 0; i < nodes; ++i) CHECK(double(ref[i]) == doctest::Approx(s[i]).epsilon(1e-9));
}

TEST_CASE("an exception thrown inside an omp body reaches the caller") {
  exec::OmpFork mode = exec::OmpFork::adaptive;
  SUBCASE("exec::omp forking always") { mode = exec::OmpFork::always; }
  SUBCASE("exec::omp adaptive") {}
  const ForkMode fork(mode);
  auto thrower = [](Index i) {
    if (i == 777) throw ArgumentError("element 777 is bad");
  };
  CHECK_THROWS_AS(exec::parallel_for(exec::omp, 10000, thrower), ArgumentError);
  CHECK_THROWS_AS(exec::parallel_for(exec::seq, 10000, thrower), ArgumentError);
  auto map = [](Index i) -> double {
    if (i == 5) throw MeshError("tet", 5, "inverted");
    return 1.0;
  };
  CHECK_THROWS_AS(exec::parallel_reduce(exec::omp, 100, 0.0, map, std::plus<>{}), MeshError);
}

TEST_CASE("omp really runs on several threads when asked") {
  CHECK(exec::omp_max_threads() >= 1);
#if defined(_OPENMP)
  const ForkMode always(exec::OmpFork::always);
  std::vector<int> team(64);  // the team's size, not who ran what: hand-out is dynamic
  exec::parallel_for(exec::omp, 64, [&](Index i) { team[i] = omp_get_num_threads(); });
  if (exec::omp_max_threads() > 1) CHECK(*std::min_element(team.begin(), team.end()) == std::min(64, exec::omp_max_threads()));
#endif
}

TEST_CASE("exec::omp on the calling thread (a loop that does not pay for a region): same results, Eigen single-threaded") {
  const ForkMode never(exec::OmpFork::never);
  std::vector<char> in_region(1000, 1);
  std::vector<int> eigen_threads(1000, 0);
  exec::parallel_for(exec::omp, 1000, [&](Index i) {
#if defined(_OPENMP)
    in_region[std::size_t(i)] = omp_in_parallel();
#else
    in_region[std::size_t(i)] = 0;
#endif
    eigen_threads[std::size_t(i)] = Eigen::nbThreads();
  });
  CHECK(std::count(in_region.begin(), in_region.end(), 0) == 1000);
  CHECK(std::count(eigen_threads.begin(), eigen_threads.end(), 1) == 1000);  // its GEMM would fork otherwise
  for (unsigned seed = 0; seed < 5; ++seed) {
    const Index n = Index(seed) * 7919 + 3;
    auto x = random_values(n, 300 + seed);
    auto map = [&](Index i) { return x[i]; };
    CHECK(exec::parallel_reduce(exec::seq, n, 0.0, map, std::plus<>{}) == exec::parallel_reduce(exec::omp, n, 0.0, map, std::plus<>{}));
    auto make = [] { return std::vector<double>(7, 0.0); };
    auto body = [&](Index i, std::vector<double>& acc) { acc[std::size_t(i % 7)] += x[i]; };
    auto merge = [](std::vector<double>& total, std::vector<double>&& part) {
      for (std::size_t i = 0; i < total.size(); ++i) total[i] += part[i];
    };
    CHECK(exec::parallel_for_accumulate(exec::seq, n, make, body, merge) == exec::parallel_for_accumulate(exec::omp, n, make, body, merge));
  }
  auto thrower = [](Index i) {
    if (i == 77) throw ArgumentError("element 77 is bad");
  };
  CHECK_THROWS_AS(exec::parallel_for(exec::omp, 100, thrower), ArgumentError);
}

TEST_CASE("exec::omp (adaptive): a loop too small to pay for a region soon runs on the calling thread") {
  const ForkMode adaptive(exec::OmpFork::adaptive);
  std::vector<double> y(16);
  int in_region_last = 0;
  for (int call = 0; call < 100; ++call) {
    std::atomic<int> in_region{0};
    exec::parallel_for(exec::omp, 16, [&](Index i) {
      y[std::size_t(i)] = double(i) * 0.5;
#if defined(_OPENMP)
      if (omp_in_parallel()) in_region = 1;
#endif
    });
    if (call >= 90) in_region_last += in_region;
  }
  CHECK(in_region_last == 0);
}

TEST_CASE("EigenSingleThreaded: Eigen on one thread while alive, the thread count restored after") {
  const int before = exec::omp_max_threads();
  {
    const EigenSingleThreaded serial;
    CHECK(Eigen::nbThreads() == 1);
    CHECK(exec::omp_max_threads() == 1);
  }
  CHECK(exec::omp_max_threads() == before);
  CHECK(Eigen::nbThreads() == before);
}

TEST_CASE("policy concepts") {
  static_assert(exec::ExecutionPolicy<exec::seq_t>);
  static_assert(exec::ExecutionPolicy<const exec::omp_t&>);
  static_assert(exec::ExecutionPolicy<exec::cuda_t>);
  static_assert(!exec::ExecutionPolicy<int>);
  static_assert(exec::HostPolicy<exec::omp_t> && !exec::HostPolicy<exec::cuda_t>);
}
