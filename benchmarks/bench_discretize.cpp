/// Google Benchmark: the LR discretization of Park et al. (2023, §4) at the paper's size.
/// Surface: simsr::ellipsoid_surface with 35,637 vertices (the HR surface size), semi-axes
/// 1, 0.8, 0.6. Cell size h = 0.0741 keeps 6,088 cells: a BCC lattice of 73,056 tets and 13,461
/// nodes (paper: 73,128 tets; BCC always makes exactly 12 tets per kept cell).
///   build/benchmarks/bench_discretize --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <simsr/discretize/bcc_lattice.hpp>
#include <simsr/mesh/generators.hpp>

using namespace simsr;
using namespace simsr::discretize;

namespace {

constexpr double kH = 0.0741;

const TriMesh<>& surface() {
  static const TriMesh<> s = ellipsoid_surface(35637, 1.0, 0.8, 0.6);
  return s;
}

void BM_Voxelize_Ellipsoid35637(benchmark::State& state) {
  VoxelSet v;
  for (auto _ : state) {
    v = voxelize(surface(), kH);
    benchmark::DoNotOptimize(v.cells.data());
  }
  state.counters["cells"] = double(v.size());
  state.counters["grid_cells"] = double(v.grid.num_cells());
}
BENCHMARK(BM_Voxelize_Ellipsoid35637)->Unit(benchmark::kMillisecond)->UseRealTime();

template <class Split>
void BM_BuildLattice(benchmark::State& state) {
  const VoxelSet v = voxelize(surface(), kH);
  Lattice<> L;
  for (auto _ : state) {
    L = build_lattice<Split>(v);
    benchmark::DoNotOptimize(L.mesh.T.data());
  }
  state.counters["tets"] = double(L.mesh.T.rows());
  state.counters["nodes"] = double(L.mesh.V.rows());
}
BENCHMARK(BM_BuildLattice<BccSplit>)->Name("BuildLattice/BCC/73k")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BuildLattice<FreudenthalSplit>)->Name("BuildLattice/Freudenthal")->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BccLattice_FromSurface(benchmark::State& state) {
  Lattice<> L;
  for (auto _ : state) {
    L = bcc_lattice(surface(), kH);
    benchmark::DoNotOptimize(L.mesh.T.data());
  }
  state.counters["tets"] = double(L.mesh.T.rows());
  state.counters["nodes"] = double(L.mesh.V.rows());
}
BENCHMARK(BM_BccLattice_FromSurface)->Name("BccLattice/Ellipsoid35637/73k")->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BccPointsInside_15872(benchmark::State& state) {
  const auto inner = ellipsoid_surface(35637, 0.97, 0.8 * 0.97, 0.6 * 0.97);
  for (auto _ : state) benchmark::DoNotOptimize(bcc_points_inside(inner, 15872).data());
}
BENCHMARK(BM_BccPointsInside_15872)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
