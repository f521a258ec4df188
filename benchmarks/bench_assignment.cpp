/// Google Benchmark: the LR→HR assignment and upsampling neighbourhoods of Park et al. (2023,
/// §3.2) at the paper's size (15,872 LR vertices onto 35,637 HR surface vertices), and the dense
/// exact solver at 1,000 × 2,000.
///
/// Generator (deterministic): HR = a closed ellipsoid surface (semi-axes 1, 0.8, 0.6) with exactly
/// 35,637 vertices: two poles plus latitude rings with vertex counts ∝ sin θ, zipped into
/// 71,270 triangles (simsr::ellipsoid_surface). LR = the 15,872 innermost points (by ellipsoidal
/// radius) of a body-centred cubic lattice inside 0.97 × that surface, spacing chosen by bisection
/// (discretize::bcc_points_inside). Every LR vertex is interior, so the mapping onto the surface
/// is far from a nearest-neighbour snap.
/// Dense case: 1,000 and 2,000 uniform random points in the unit cube (seed 1), Euclidean costs.

#include <benchmark/benchmark.h>

#include <simsr/discretize/bcc_lattice.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/neighbors/linear_assignment.hpp>
#include <simsr/neighbors/upsampling_neighborhoods.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

using namespace simsr;
using namespace simsr::neighbors;

namespace {

struct PaperScene {
  Points<> hr_V;
  Tris hr_F;
  Points<> lr_V;
  PaperScene() {
    auto hr = ellipsoid_surface(35637, 1.0, 0.8, 0.6);
    hr_V = std::move(hr.V);
    hr_F = std::move(hr.F);
    lr_V = discretize::bcc_points_inside(ellipsoid_surface(35637, 0.97, 0.8 * 0.97, 0.6 * 0.97), 15872);
  }
};

const PaperScene& scene() {
  static const PaperScene s;
  return s;
}

template <class Policy>
void BM_Assignment_Paper(benchmark::State& state) {
  const auto& s = scene();
  PointAssignment a;
  for (auto _ : state) {
    a = assign_points(Policy{}, s.lr_V, s.hr_V);
    benchmark::DoNotOptimize(a.row_to_col.data());
  }
  state.counters["total_cost"] = a.total_cost;
  state.counters["rounds"] = double(a.rounds);
  state.counters["max_k"] = double(a.max_k);
  state.counters["edges"] = double(a.candidate_edges);
  state.counters["augmentations"] = double(a.augmentations);
  state.counters["global_opt"] = a.globally_optimal;
}
BENCHMARK_TEMPLATE(BM_Assignment_Paper, exec::seq_t)->Name("Assignment/15872x35637/seq")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_Assignment_Paper, exec::omp_t)->Name("Assignment/15872x35637/omp")->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_KLabelDijkstra_Paper(benchmark::State& state) {
  const auto& s = scene();
  const auto a = assign_points(exec::omp, s.lr_V, s.hr_V);
  GeodesicSources g;
  for (auto _ : state) {
    g = geodesic_k_nearest_sources(s.hr_V, s.hr_F, a.row_to_col, 20);
    benchmark::DoNotOptimize(g.indices.data());
  }
  state.counters["mean_kth_dist"] = g.distances.col(19).mean();
}
BENCHMARK(BM_KLabelDijkstra_Paper)->Name("KLabelDijkstra/35637x20")->Unit(benchmark::kMillisecond)->UseRealTime();

template <class Policy>
void BM_Upsampling_Paper(benchmark::State& state) {
  const auto& s = scene();
  for (auto _ : state) {
    auto nb = upsampling_neighborhoods(Policy{}, s.lr_V, s.hr_V, s.hr_F);
    benchmark::DoNotOptimize(nb.indices.data());
  }
}
BENCHMARK_TEMPLATE(BM_Upsampling_Paper, exec::seq_t)->Name("UpsamplingNeighborhoods/15872x35637/k20/seq")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_Upsampling_Paper, exec::omp_t)->Name("UpsamplingNeighborhoods/15872x35637/k20/omp")->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_DenseAssignment(benchmark::State& state) {
  const Index n = state.range(0), m = state.range(1);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  Points<> A(n, 3), B(m, 3);
  for (Index i = 0; i < A.size(); ++i) A.data()[i] = u(rng);
  for (Index i = 0; i < B.size(); ++i) B.data()[i] = u(rng);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> C(n, m);  // used in place
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < m; ++j) C(i, j) = neighbors::detail::assignment_distance(A, i, B, j);
  Assignment a;
  for (auto _ : state) {
    a = linear_assignment(C);
    benchmark::DoNotOptimize(a.row_to_col.data());
  }
  state.counters["total_cost"] = a.total_cost;
}
BENCHMARK(BM_DenseAssignment)->Name("DenseAssignment")->Args({1000, 2000})->Unit(benchmark::kMillisecond)->UseRealTime();

/// The sparse path on the same dense instance, for the ratio (and the same optimum).
void BM_SparseOnDenseInstance(benchmark::State& state) {
  const Index n = state.range(0), m = state.range(1);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  Points<> A(n, 3), B(m, 3);
  for (Index i = 0; i < A.size(); ++i) A.data()[i] = u(rng);
  for (Index i = 0; i < B.size(); ++i) B.data()[i] = u(rng);
  PointAssignment a;
  for (auto _ : state) {
    a = assign_points(exec::seq, A, B);
    benchmark::DoNotOptimize(a.row_to_col.data());
  }
  state.counters["total_cost"] = a.total_cost;
  state.counters["global_opt"] = a.globally_optimal;
}
BENCHMARK(BM_SparseOnDenseInstance)->Name("PointAssignment")->Args({1000, 2000})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
