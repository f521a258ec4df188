// Barycentric embedding at the paper's sizes (§4: LR 73k tets / 15,872 vertices, HR surface
// 35,637 vertices): a non-conforming lattice of cubes (5-tet alternating split, the bunny LR
// mesh's kind) kept where the cube centre lies inside the ellipsoid x²/1 + y²/0.8² + z²/0.6² ≤ 1,
// and 35,637 query points on the ellipsoid surface (Fibonacci spiral), so, as for a real HR
// surface in a BCC lattice, a good share lies just outside the lattice and needs the nearest-tet
// search.
//   build/benchmarks/bench_embedding --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <simsr/discretize/embedding.hpp>
#include <simsr/interp/embedded.hpp>

#include <array>
#include <cmath>
#include <map>
#include <random>
#include <vector>

using namespace simsr;

namespace {

constexpr Index kHR = 35637;
constexpr double kAxes[3] = {1.0, 0.8, 0.6};
constexpr double kCell = 0.0517;  // gives ≈ 73k tets in the ellipsoid

bool in_ellipsoid(const Vec3<>& p) {
  double s = 0;
  for (int d = 0; d < 3; ++d) s += (p[d] / kAxes[d]) * (p[d] / kAxes[d]);
  return s <= 1;
}

/// Cubes of edge kCell whose centre is inside the ellipsoid, each split into 5 tets (alternating
/// with the cube's parity so shared faces match); vertices numbered in first-use order.
const TetMesh<>& lattice() {
  static const TetMesh<> m = [] {
    const int n[3] = {int(std::ceil(kAxes[0] / kCell)) + 1, int(std::ceil(kAxes[1] / kCell)) + 1,
                      int(std::ceil(kAxes[2] / kCell)) + 1};
    std::map<std::array<int, 3>, VIndex> ids;
    std::vector<Vec3<>> verts;
    std::vector<std::array<VIndex, 4>> tets;
    auto vid = [&](int i, int j, int k) {
      auto [it, fresh] = ids.try_emplace({i, j, k}, VIndex(verts.size()));
      if (fresh) verts.push_back(kCell * Vec3<>(i, j, k));
      return it->second;
    };
    for (int k = -n[2]; k < n[2]; ++k)
      for (int j = -n[1]; j < n[1]; ++j)
        for (int i = -n[0]; i < n[0]; ++i) {
          if (!in_ellipsoid(kCell * Vec3<>(i + 0.5, j + 0.5, k + 0.5))) continue;
          VIndex c[8];
          for (int b = 0; b < 8; ++b) c[b] = vid(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
          static const int even[5][4] = {{1, 2, 4, 7}, {0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}};
          static const int odd[5][4] = {{0, 3, 5, 6}, {1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}};
          const auto& local = ((i + j + k) % 2 + 2) % 2 == 0 ? even : odd;
          for (const auto& l : local) tets.push_back({c[l[0]], c[l[1]], c[l[2]], c[l[3]]});
        }
    TetMesh<> out;
    out.V.resize(Index(verts.size()), 3);
    for (Index v = 0; v < out.V.rows(); ++v) out.V.row(v) = verts[std::size_t(v)].transpose();
    out.T.resize(Index(tets.size()), 4);
    for (Index t = 0; t < out.T.rows(); ++t) {
      auto x = tets[std::size_t(t)];
      Eigen::Matrix3d E;
      for (int k = 0; k < 3; ++k) E.col(k) = out.V.row(x[std::size_t(k) + 1]) - out.V.row(x[0]);
      if (E.determinant() < 0) std::swap(x[2], x[3]);
      for (int k = 0; k < 4; ++k) out.T(t, k) = x[std::size_t(k)];
    }
    return out;
  }();
  return m;
}

/// kHR points on the ellipsoid surface (Fibonacci spiral on the sphere, scaled by the axes).
const Points<>& surface_points() {
  static const Points<> Q = [] {
    Points<> X(kHR, 3);
    const double golden = M_PI * (3 - std::sqrt(5.0));
    for (Index i = 0; i < kHR; ++i) {
      const double z = 1 - 2 * (double(i) + 0.5) / double(kHR), r = std::sqrt(1 - z * z), a = golden * double(i);
      X.row(i) << kAxes[0] * r * std::cos(a), kAxes[1] * r * std::sin(a), kAxes[2] * z;
    }
    return X;
  }();
  return Q;
}

const TetLocator<>& locator() {
  static const TetLocator<> loc(lattice());
  return loc;
}

void counters(benchmark::State& state, const Embedding<>& e) {
  state.counters["tets"] = double(lattice().num_tets());
  state.counters["lr_vertices"] = double(lattice().num_vertices());
  state.counters["queries"] = double(e.size());
  state.counters["outside"] = double(e.num_outside());
  state.counters["max_dist/h"] = e.max_distance() / kCell;
  state.counters["queries/s"] = benchmark::Counter(double(e.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_LocatorBuild(benchmark::State& state) {
  const TetMesh<>& m = lattice();
  for (auto _ : state) {
    TetLocator<> loc(m);
    benchmark::DoNotOptimize(loc.num_entries());
  }
  const TetLocator<>& loc = locator();
  state.counters["tets"] = double(m.num_tets());
  state.counters["cells"] = double(loc.grid_size()[0] * loc.grid_size()[1] * loc.grid_size()[2]);
  state.counters["entries/tet"] = double(loc.num_entries()) / double(m.num_tets());
}
BENCHMARK(BM_LocatorBuild)->Unit(benchmark::kMillisecond);

template <class P>
void BM_EmbedQueries(benchmark::State& state) {
  const TetLocator<>& loc = locator();
  Embedding<> e;
  for (auto _ : state) {
    e = embed(P{}, loc, surface_points());
    benchmark::DoNotOptimize(e.weights.data());
  }
  counters(state, e);
}
BENCHMARK_TEMPLATE(BM_EmbedQueries, exec::seq_t)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_EmbedQueries, exec::omp_t)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The whole call a user makes once per model: index build + 35,637 queries.
template <class P>
void BM_EmbedFull(benchmark::State& state) {
  Embedding<> e;
  for (auto _ : state) {
    e = embed(P{}, lattice(), surface_points());
    benchmark::DoNotOptimize(e.weights.data());
  }
  counters(state, e);
}
BENCHMARK_TEMPLATE(BM_EmbedFull, exec::seq_t)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_EmbedFull, exec::omp_t)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Per-frame cost of the Embedded baseline: N = lattice vertices → M = 35,637, buffers reused.
template <class P>
void BM_EmbeddedApply(benchmark::State& state) {
  static const interp::Embedded<> method = [] {
    interp::Embedded<> e;
    e.fit(exec::omp, lattice(), surface_points());
    return e;
  }();
  std::mt19937 rng(4);
  std::normal_distribution<double> g(0, 0.01);
  Points<> lr(lattice().num_vertices(), 3), hr(kHR, 3);
  for (Index i = 0; i < lr.size(); ++i) lr.data()[i] = g(rng);
  for (auto _ : state) {
    method.apply(P{}, lr, hr);
    benchmark::DoNotOptimize(hr.data());
    benchmark::ClobberMemory();
  }
  state.counters["M"] = double(kHR);
  state.counters["N"] = double(lr.rows());
  state.counters["frames/s"] = benchmark::Counter(1, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK_TEMPLATE(BM_EmbeddedApply, exec::seq_t)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_EmbeddedApply, exec::omp_t)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
