// Neighbour gathering at the paper's sizes (LR 15,872 vertices, HR surface 35,637 vertices):
//   3-D kNN k=20 of the HR vertices among the LR ones: the uniform grid (GridKnn, build and
//     query) beside the kd-tree (KdTree, the baseline; the grid's setup checks that both give the
//     same indices and distances, bitwise),
//   EdgeConv's feature kNN N=15,872, D=64, k=5 (brute force, self included as in DGCNN): the
//     fused kernel (default) beside the blocked-GEMM one (SelfKernel::blocked_gemm, the baseline),
//   geodesic kNN k=5 on a BCC lattice graph of ~15.6k vertices (the first EdgeConv graph).
// Uniform random points in [-1,1]^3 and standard-normal features, as scripts/peers/knn_peer.py
// --bench uses for the scipy and torch peers. Buffers are built once and reused across iterations.
//   build/benchmarks/bench_neighbors --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <simsr/discretize/bcc_lattice.hpp>
#include <simsr/neighbors/neighbors.hpp>

#include <array>
#include <random>
#include <vector>

using namespace simsr;
using namespace simsr::neighbors;

namespace {

constexpr Index kLR = 15872, kHR = 35637, kFeatureDim = 64;

const Points<double>& lr_points() {
  static const Points<double> P = [] {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-1, 1);
    Points<double> X(kLR, 3);
    for (Index i = 0; i < X.size(); ++i) X.data()[i] = u(rng);
    return X;
  }();
  return P;
}

const Points<double>& hr_points() {
  static const Points<double> Q = [] {
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(-1, 1);
    Points<double> X(kHR, 3);
    for (Index i = 0; i < X.size(); ++i) X.data()[i] = u(rng);
    return X;
  }();
  return Q;
}

const BruteForceKnn<float>::point_matrix& features() {
  static const BruteForceKnn<float>::point_matrix F = [] {
    std::mt19937 rng(3);
    std::normal_distribution<float> g(0, 1);
    BruteForceKnn<float>::point_matrix X(kLR, kFeatureDim);
    for (Index i = 0; i < X.size(); ++i) X.data()[i] = g(rng);
    return X;
  }();
  return F;
}

/// Body-centred cubic lattice graph: the nodes (cube corners and centres) and edges of the BCC
/// lattice mesh of a full box of nx×ny×nz cubes (discretize::build_lattice; its boundary faces
/// carry the pyramid diagonals).
struct Lattice {
  Points<double> V;
  Edges E;
};

const Lattice& lattice() {
  static const Lattice L = [] {
    discretize::VoxelSet box;
    box.grid.h = 0.0125;
    box.grid.dims = {20, 20, 18};
    for (Index k = 0; k < 18; ++k)
      for (Index j = 0; j < 20; ++j)
        for (Index i = 0; i < 20; ++i) box.cells.push_back({i, j, k});
    const auto bcc = discretize::build_lattice(box);  // 8,379 corners + 7,200 centres = 15,579 vertices
    return Lattice{bcc.mesh.V, unique_edges(bcc.mesh.T)};
  }();
  return L;
}

void BM_KdTreeBuild_LR15872(benchmark::State& state) {
  const auto& P = lr_points();
  KdTree<double> tree;
  for (auto _ : state) {
    tree.build(P);
    benchmark::DoNotOptimize(tree);
  }
  state.SetItemsProcessed(state.iterations() * kLR);
}
BENCHMARK(BM_KdTreeBuild_LR15872)->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.2);

template <class Policy>
void BM_KdTreeQuery_HR35637_in_LR15872_k20(benchmark::State& state) {
  const KdTree<double> tree(lr_points());
  KnnResult<double> r;
  tree.query_into(Policy{}, hr_points(), 20, r);
  for (auto _ : state) {
    tree.query_into(Policy{}, hr_points(), 20, r);
    benchmark::DoNotOptimize(r.indices.data());
  }
  state.SetItemsProcessed(state.iterations() * kHR);
}
BENCHMARK(BM_KdTreeQuery_HR35637_in_LR15872_k20<exec::seq_t>)->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.2);
BENCHMARK(BM_KdTreeQuery_HR35637_in_LR15872_k20<exec::omp_t>)->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.2);

void BM_GridBuild_LR15872(benchmark::State& state) {
  const auto& P = lr_points();
  GridKnn<double> grid;
  for (auto _ : state) {
    grid.build(P);
    benchmark::DoNotOptimize(grid);
  }
  state.SetItemsProcessed(state.iterations() * kLR);
}
BENCHMARK(BM_GridBuild_LR15872)->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.2);

template <class Policy>
void BM_GridQuery_HR35637_in_LR15872_k20(benchmark::State& state) {
  GridKnn<double> grid(lr_points());
  KnnResult<double> r, tree;
  grid.query_into(Policy{}, hr_points(), 20, r);
  KdTree<double>(lr_points()).query_into(exec::omp, hr_points(), 20, tree);
  if (r.indices != tree.indices || r.distances != tree.distances) state.SkipWithError("GridKnn and KdTree differ");
  for (auto _ : state) {
    grid.query_into(Policy{}, hr_points(), 20, r);
    benchmark::DoNotOptimize(r.indices.data());
  }
  state.SetItemsProcessed(state.iterations() * kHR);
}
BENCHMARK(BM_GridQuery_HR35637_in_LR15872_k20<exec::seq_t>)->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.2);
BENCHMARK(BM_GridQuery_HR35637_in_LR15872_k20<exec::omp_t>)->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.2);

template <class Policy, SelfKernel Kernel = SelfKernel::fused>
void BM_FeatureKnn_N15872_D64_k5(benchmark::State& state) {
  BruteForceKnn<float, Kernel> knn(features(), {state.range(0), state.range(1), 8});
  KnnResult<float> r;
  knn.query_self_into(Policy{}, 5, r, false);
  for (auto _ : state) {
    knn.query_self_into(Policy{}, 5, r, false);
    benchmark::DoNotOptimize(r.indices.data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(2.0 * kLR * kLR * kFeatureDim * 1e-9 * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FeatureKnn_N15872_D64_k5<exec::seq_t>)->Args({256, 2048})->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.5);
BENCHMARK(BM_FeatureKnn_N15872_D64_k5<exec::omp_t>)
    ->ArgNames({"qblock", "pblock"})
    ->Args({128, 1024})
    ->Args({256, 2048})
    ->Args({64, 512})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinWarmUpTime(0.5);
// the baseline: the blocked-GEMM kernel at its default tile (256)
BENCHMARK(BM_FeatureKnn_N15872_D64_k5<exec::seq_t, SelfKernel::blocked_gemm>)->Name("BM_FeatureKnn_N15872_D64_k5_baseline/seq")->Args({256, 2048})->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.5);
BENCHMARK(BM_FeatureKnn_N15872_D64_k5<exec::omp_t, SelfKernel::blocked_gemm>)->Name("BM_FeatureKnn_N15872_D64_k5_baseline/omp")->Args({256, 2048})->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.5);

template <class Policy>
void BM_GeodesicKnn_BCC15579_k5(benchmark::State& state) {
  GeodesicKnn<double> g(lattice().V, lattice().E);
  KnnResult<double> r;
  g.query_into(Policy{}, 5, r);
  for (auto _ : state) {
    g.query_into(Policy{}, 5, r);
    benchmark::DoNotOptimize(r.indices.data());
  }
  state.SetItemsProcessed(state.iterations() * lattice().V.rows());
}
BENCHMARK(BM_GeodesicKnn_BCC15579_k5<exec::seq_t>)->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.2);
BENCHMARK(BM_GeodesicKnn_BCC15579_k5<exec::omp_t>)->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.2);

void BM_GeodesicKnnBuild_BCC15579(benchmark::State& state) {
  GeodesicKnn<double> g;
  for (auto _ : state) {
    g.build(lattice().V, lattice().E);
    benchmark::DoNotOptimize(g);
  }
}
BENCHMARK(BM_GeodesicKnnBuild_BCC15579)->Unit(benchmark::kMillisecond)->UseRealTime()->MinWarmUpTime(0.2);

}  // namespace

BENCHMARK_MAIN();
