/// Google Benchmark: the LR→HR assignment and upsampling neighbourhoods of Park et al. (2023,
/// §3.2) at the paper's size (15,872 LR vertices onto 35,637 HR surface vertices), and the dense
/// exact solver at 1,000 × 2,000.
///
/// Generator (deterministic): HR = a closed ellipsoid surface (semi-axes 1, 0.8, 0.6) with exactly
/// 35,637 vertices: two poles plus latitude rings with vertex counts ∝ sin θ, zipped into
/// 71,270 triangles. LR = the 15,872 innermost points (by ellipsoidal radius) of a body-centred
/// cubic lattice inside 0.97 × that ellipsoid, spacing chosen by bisection. Every LR vertex is
/// interior, so the mapping onto the surface is far from a nearest-neighbour snap.
/// Dense case: 1,000 and 2,000 uniform random points in the unit cube (seed 1), Euclidean costs.

#include <benchmark/benchmark.h>

#include <simsr/neighbors/linear_assignment.hpp>
#include <simsr/neighbors/upsampling_neighborhoods.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

using namespace simsr;
using namespace simsr::neighbors;

namespace {

/// Closed ellipsoid surface (semi-axes a, b, c) with exactly nv ≥ 8 vertices: two poles and
/// latitude rings whose vertex counts follow sin θ, consecutive rings zipped in angular order.
/// The same generator drives benchmarks/bench_assignment.cpp at 35,637 vertices.
void ellipsoid_surface(Index nv, double a, double b, double c, Points<>& V, Tris& F) {
  const double pi = std::numbers::pi;
  const Index R = std::max<Index>(3, Index(std::lround(std::sqrt(pi * double(nv - 2) / 4))));
  std::vector<Index> n(static_cast<std::size_t>(R - 1));
  Index total = 0;
  for (Index r = 1; r < R; ++r) total += n[r - 1] = std::max<Index>(3, std::lround(2.0 * R * std::sin(pi * r / R)));
  for (Index r = 0; total != nv - 2; r = (r + 1) % (R - 1)) {  // fix the count from the equator outwards
    const Index ring = (R - 1) / 2 + (r % 2 ? -(r + 1) / 2 : r / 2);
    if (total < nv - 2) ++n[ring], ++total;
    else if (n[ring] > 3) --n[ring], --total;
  }
  V.resize(nv, 3);
  std::vector<std::vector<VIndex>> rings;
  V.row(0) << 0, 0, c;
  Index next = 1;
  for (Index r = 1; r < R; ++r) {
    const double th = pi * r / R;
    std::vector<VIndex> ids;
    for (Index i = 0; i < n[r - 1]; ++i) {
      const double ph = 2 * pi * (i + 0.5 * (r % 2)) / n[r - 1];
      V.row(next) << a * std::sin(th) * std::cos(ph), b * std::sin(th) * std::sin(ph), c * std::cos(th);
      ids.push_back(static_cast<VIndex>(next++));
    }
    rings.push_back(std::move(ids));
  }
  V.row(next) << 0, 0, -c;
  std::vector<std::array<VIndex, 3>> tris;
  const auto fan = [&](VIndex pole, const std::vector<VIndex>& ring) {
    for (std::size_t i = 0; i < ring.size(); ++i) tris.push_back({pole, ring[i], ring[(i + 1) % ring.size()]});
  };
  fan(0, rings.front());
  for (std::size_t r = 0; r + 1 < rings.size(); ++r) {
    const auto &A = rings[r], &B = rings[r + 1];
    const double oa = 0.5 * double((r + 1) % 2), ob = 0.5 * double((r + 2) % 2);
    std::size_t i = 0, j = 0;
    while (i < A.size() || j < B.size()) {
      const double na = (double(i + 1) + oa) / double(A.size()), nb = (double(j + 1) + ob) / double(B.size());
      if (j == B.size() || (i < A.size() && na < nb)) {
        tris.push_back({A[i % A.size()], B[j % B.size()], A[(i + 1) % A.size()]});
        ++i;
      } else {
        tris.push_back({A[i % A.size()], B[j % B.size()], B[(j + 1) % B.size()]});
        ++j;
      }
    }
  }
  fan(static_cast<VIndex>(nv - 1), rings.back());
  F.resize(Index(tris.size()), 3);
  for (Index f = 0; f < F.rows(); ++f) F.row(f) << tris[f][0], tris[f][1], tris[f][2];
}

/// Body-centred cubic lattice points strictly inside the ellipsoid, the `count` innermost kept.
Points<> bcc_inside(Index count, double a, double b, double c) {
  const auto inside = [&](double h) {
    std::vector<std::pair<double, Vec3<>>> p;
    const Index m = Index(std::ceil(std::max({a, b, c}) / h)) + 1;
    for (int off = 0; off < 2; ++off)
      for (Index i = -m; i <= m; ++i)
        for (Index j = -m; j <= m; ++j)
          for (Index k = -m; k <= m; ++k) {
            const Vec3<> x = h * Vec3<>(i + 0.5 * off, j + 0.5 * off, k + 0.5 * off);
            const double e = std::sqrt(std::pow(x[0] / a, 2) + std::pow(x[1] / b, 2) + std::pow(x[2] / c, 2));
            if (e < 0.97) p.push_back({e, x});
          }
    return p;
  };
  double lo = 1e-3, hi = std::max({a, b, c});
  for (int it = 0; it < 60; ++it) (Index(inside(0.5 * (lo + hi)).size()) >= count ? lo : hi) = 0.5 * (lo + hi);
  auto p = inside(lo);
  std::stable_sort(p.begin(), p.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  Points<> P(count, 3);
  for (Index i = 0; i < count; ++i) P.row(i) = p[i].second.transpose();
  return P;
}

struct PaperScene {
  Points<> hr_V;
  Tris hr_F;
  Points<> lr_V;
  PaperScene() {
    ellipsoid_surface(35637, 1.0, 0.8, 0.6, hr_V, hr_F);
    lr_V = bcc_inside(15872, 1.0, 0.8, 0.6);
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
