// Parallel primitives: overhead and scaling of seq vs omp on memory-bound and compute-bound work.
//   build/benchmarks/bench_core --benchmark_filter=Reduce
// The layers' products y = b + x·Wᵀ on one thread, a chunk of 560 rows at the widths of the
// paper-size network's largest layers (in:out = 64:512 EdgeConv block 1's point-wise first layer,
// 256:128 its edge MLP's second layer and the decoder's, 227:256 the decoder's first, 384:256
// block 1's fc_out), PackedGemm (the weight packed once per forward, the sums started at the
// bias) against SerialGemm, Eigen's packed kernel, then the bias added (nn::Linear before it):
//   build/benchmarks/bench_core --benchmark_filter=LayerProducts
#include <benchmark/benchmark.h>

#include <simsr/core/core.hpp>

#include <cmath>
#include <functional>
#include <random>
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

struct LayerOperands {
  Index rows, in, out;
  std::vector<float> x, W, b, y;
  explicit LayerOperands(const benchmark::State& state) : rows(560), in(state.range(0)), out(state.range(1)) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1, 1);
    x.resize(std::size_t(rows * in));
    W.resize(std::size_t(out * in));
    b.resize(std::size_t(out));
    y.resize(std::size_t(rows * out));
    for (auto* v : {&x, &W, &b})
      for (float& e : *v) e = u(rng);
  }
  void count(benchmark::State& state) const {
    state.counters["GMAC"] = benchmark::Counter(1e-9 * double(rows * in * out), benchmark::Counter::kIsIterationInvariantRate);
  }
};

static void BM_LayerProducts_PackedGemm(benchmark::State& state) {
  LayerOperands o(state);
  PackedGemm<float> g;
  PackedGemm<float>::Workspace ws;
  g.pack(o.W.data(), o.out, o.in, o.in);
  g.run(ws, o.rows, o.x.data(), o.in, o.b.data(), o.y.data(), o.out, false);  // warm
  for (auto _ : state) {
    g.run(ws, o.rows, o.x.data(), o.in, o.b.data(), o.y.data(), o.out, false);
    benchmark::DoNotOptimize(o.y.data());
  }
  o.count(state);
}

static void BM_LayerProducts_SerialGemm(benchmark::State& state) {
  LayerOperands o(state);
  SerialGemm<float> g;
  g.reserve(o.rows, o.out, o.in);
  for (auto _ : state) {
    g.run(o.rows, o.out, o.in, o.x.data(), o.in, false, o.W.data(), o.in, true, o.y.data(), o.out, false);
    Eigen::Map<Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> y(o.y.data(), o.rows, o.out);
    y.rowwise() += Eigen::Map<const Eigen::RowVectorXf>(o.b.data(), o.out);
    benchmark::DoNotOptimize(o.y.data());
  }
  o.count(state);
}

#define SIMSR_LAYER_SHAPES ->ArgNames({"in", "out"})->Args({64, 512})->Args({256, 128})->Args({227, 256})->Args({384, 256})->Args({64, 32})
BENCHMARK(BM_LayerProducts_PackedGemm) SIMSR_LAYER_SHAPES;
BENCHMARK(BM_LayerProducts_SerialGemm) SIMSR_LAYER_SHAPES;

BENCHMARK_MAIN();
