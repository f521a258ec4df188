// Parallel primitives: overhead and scaling of seq vs omp on memory-bound and compute-bound work.
//   build/benchmarks/bench_core --benchmark_filter=Reduce
#include <benchmark/benchmark.h>

#include <simsr/core/core.hpp>

#include <cmath>
#include <functional>
#include <vector>

using namespace simsr;

template <class Policy>
static void BM_ReduceSum(benchmark::State& state) {
  const Index n = state.range(0);
  std::vector<double> x(static_cast<std::size_t>(n), 1.0);
  for (Index i = 0; i < n; ++i) x[i] = std::sin(double(i));
  for (auto _ : state) {
    double s = exec::parallel_reduce(Policy{}, n, 0.0, [&](Index i) { return x[i]; }, std::plus<>{});
    benchmark::DoNotOptimize(s);
  }
  state.SetBytesProcessed(state.iterations() * n * Index(sizeof(double)));
}
BENCHMARK(BM_ReduceSum<exec::seq_t>)->Arg(1 << 20)->Arg(1 << 24)->UseRealTime();
BENCHMARK(BM_ReduceSum<exec::omp_t>)->Arg(1 << 20)->Arg(1 << 24)->UseRealTime();

template <class Policy>
static void BM_ForTranscendental(benchmark::State& state) {
  const Index n = state.range(0);
  std::vector<double> x(static_cast<std::size_t>(n)), y(x.size());
  for (Index i = 0; i < n; ++i) x[i] = 1e-6 * double(i);
  for (auto _ : state) {
    exec::parallel_for(Policy{}, n, [&](Index i) { y[i] = std::exp(std::sin(x[i])) * std::cos(x[i]); });
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_ForTranscendental<exec::seq_t>)->Arg(1 << 20)->UseRealTime();
BENCHMARK(BM_ForTranscendental<exec::omp_t>)->Arg(1 << 20)->UseRealTime();

BENCHMARK_MAIN();
