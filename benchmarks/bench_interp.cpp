/// Interpolators at the paper's sizes (N = 15,872 LR vertices, M = 35,637 HR vertices, k = 20):
/// `apply` per frame under exec::seq and exec::omp, fits of IDW/MLS, and the RBF fit (geodesic,
/// sparse truncated LDLᵀ path). LR: a 32×31×16 lattice (spacing 1, 6 tets per cube) = 15,872
/// vertices; HR: jittered copies of LR vertices with synthetic neighbourhoods (20 random LR ids
/// near the vertex, sorted, ascending distances), which is all IDW/MLS `apply` depends on.
/// RBF (geodesic: HR-surface paths between mapped positions) needs a real surface: the same LR
/// lattice with an enclosing ellipsoid of 35,637 vertices, LR vertex i mapped onto HR vertex
/// ⌊(2i+1)M/2N⌋ (spread over the rings; the assignment itself is not what is timed).
/// LocalLinear: trained on 240 random frames of the paper-size problem (two "performances" of 120,
/// so cross-validation leaves one out, as on the face), its fit and its apply.
#include <benchmark/benchmark.h>

#include <simsr/interp/idw.hpp>
#include <simsr/interp/local_linear.hpp>
#include <simsr/interp/mls.hpp>
#include <simsr/interp/rbf.hpp>
#include <simsr/mesh/generators.hpp>

#include <algorithm>
#include <array>
#include <memory>
#include <random>
#include <vector>

using namespace simsr;
using namespace simsr::interp;

namespace {

constexpr Index kLr = 15872, kHr = 35637, kK = 20;

UpsamplingProblem<>& paper_problem() {
  static std::unique_ptr<UpsamplingProblem<>> p = [] {
    auto q = std::make_unique<UpsamplingProblem<>>();
    const int nx = 32, ny = 31, nz = 16;
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-0.2, 0.2);
    q->lr.V.resize(nx * ny * nz, 3);
    const auto id = [&](int i, int j, int k) { return VIndex(i + nx * (j + ny * k)); };
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) q->lr.V.row(id(i, j, k)) << i + u(rng), j + u(rng), k + u(rng);
    std::vector<std::array<VIndex, 4>> tets;
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int k = 0; k + 1 < nz; ++k)
      for (int j = 0; j + 1 < ny; ++j)
        for (int i = 0; i + 1 < nx; ++i)
          for (const auto& pm : perms) {
            int c[3] = {i, j, k};
            std::array<VIndex, 4> t;
            t[0] = id(c[0], c[1], c[2]);
            for (int s = 0; s < 3; ++s) ++c[pm[s]], t[s + 1] = id(c[0], c[1], c[2]);
            tets.push_back(t);
          }
    q->lr.T.resize(Index(tets.size()), 4);
    for (std::size_t e = 0; e < tets.size(); ++e)
      for (int c = 0; c < 4; ++c) q->lr.T(Index(e), c) = tets[e][std::size_t(c)];
    q->hr.V.resize(kHr, 3);
    neighbors::UpsamplingNeighborhoods nb;
    nb.indices.resize(kHr, kK);
    nb.distances.resize(kHr, kK);
    std::uniform_int_distribution<int> off(-100, 100);
    std::uniform_real_distribution<double> d(0.0, 3.0);
    for (Index j = 0; j < kHr; ++j) {
      const Index base = j % kLr;
      q->hr.V.row(j) = q->lr.V.row(base) + Eigen::RowVector3d(u(rng), u(rng), u(rng));
      std::vector<VIndex> ids{VIndex(base)};
      while (Index(ids.size()) < kK) {
        const VIndex c = VIndex(std::clamp<Index>(base + off(rng), 0, kLr - 1));
        if (std::find(ids.begin(), ids.end(), c) == ids.end()) ids.push_back(c);
      }
      std::vector<double> ds(kK);
      for (auto& x : ds) x = d(rng);
      std::sort(ds.begin(), ds.end());
      for (Index n = 0; n < kK; ++n) nb.indices(j, n) = ids[std::size_t(n)], nb.distances(j, n) = ds[std::size_t(n)];
    }
    q->neighborhoods = std::move(nb);
    return q;
  }();
  return *p;
}

/// Times method.apply on one random LR displacement of problem `p` (warmed up once).
template <class I, class Policy>
void run_apply(benchmark::State& state, I& method, Policy policy, const UpsamplingProblem<>& p) {
  std::mt19937 rng(2);
  std::normal_distribution<double> g;
  Points<> dX(p.num_lr(), 3), dx(p.num_hr(), 3);
  for (Index i = 0; i < dX.size(); ++i) dX.data()[i] = g(rng);
  method.apply(policy, dX, dx);
  for (auto _ : state) {
    method.apply(policy, dX, dx);
    benchmark::DoNotOptimize(dx.data());
  }
}

IDW<>& idw() {
  static IDW<> m = [] { IDW<> x; x.fit(exec::seq, paper_problem()); return x; }();
  return m;
}
MLS<>& mls(MlsBasis b) {
  static MLS<> pc = [] { MLS<> x; x.fit(exec::omp, paper_problem()); return x; }();
  static MLS<> l3 = [] { MLS<> x(MLSOptions{.basis = MlsBasis::linear_3d}); x.fit(exec::omp, paper_problem()); return x; }();
  return b == MlsBasis::per_coordinate ? pc : l3;
}
/// The paper-size LR lattice with an HR ellipsoid surface around it and a spread LR→HR mapping.
UpsamplingProblem<>& rbf_problem() {
  static std::unique_ptr<UpsamplingProblem<>> p = [] {
    auto q = std::make_unique<UpsamplingProblem<>>();
    q->lr = paper_problem().lr;
    q->hr = ellipsoid_surface<double>(kHr, 18.0, 17.5, 9.5);
    q->hr.V.rowwise() += Eigen::RowVector3d(15.5, 15.0, 7.5);
    neighbors::UpsamplingNeighborhoods nb;
    nb.lr_to_hr.resize(kLr);
    for (Index i = 0; i < kLr; ++i) nb.lr_to_hr[i] = VIndex((2 * i + 1) * kHr / (2 * kLr));
    q->neighborhoods = std::move(nb);
    return q;
  }();
  return *p;
}
RBF<>& rbf() {
  static std::unique_ptr<RBF<>> m = [] {
    auto x = std::make_unique<RBF<>>();
    x->fit(exec::omp, rbf_problem());
    return x;
  }();
  return *m;
}

/// 240 frames of random displacements at the paper's sizes, in two sequences of 120 (what the fit
/// costs does not depend on the values).
const data::PairedFrames<>& paper_frames() {
  static const data::PairedFrames<> f = [] {
    data::PairedFrames<> x;
    const Index F = 240;
    std::mt19937 rng(4);
    std::normal_distribution<double> g;
    x.lowres.resize(F, 3 * kLr);
    x.highres.resize(F, 3 * kHr);
    for (Index i = 0; i < x.lowres.size(); ++i) x.lowres.data()[i] = g(rng);
    for (Index i = 0; i < x.highres.size(); ++i) x.highres.data()[i] = g(rng);
    x.controls.resize(F, 0);
    x.sequence_names = {"a", "b"};
    for (Index i = 0; i < F; ++i) x.ids.push_back(i), x.sequence.push_back(i < F / 2 ? 0 : 1);
    return x;
  }();
  return f;
}
LocalLinear<>& local_linear() {
  static LocalLinear<> m = [] {
    LocalLinear<> x;
    x.fit(exec::omp, paper_problem());
    x.train(exec::omp, paper_frames(), {.lambda = 1e-5});
    return x;
  }();
  return m;
}

void BM_IDW_apply_seq(benchmark::State& s) { run_apply(s, idw(), exec::seq, paper_problem()); }
void BM_IDW_apply_omp(benchmark::State& s) { run_apply(s, idw(), exec::omp, paper_problem()); }
void BM_MLS_as_written_apply_seq(benchmark::State& s) { run_apply(s, mls(MlsBasis::per_coordinate), exec::seq, paper_problem()); }
void BM_MLS_as_written_apply_omp(benchmark::State& s) { run_apply(s, mls(MlsBasis::per_coordinate), exec::omp, paper_problem()); }
void BM_MLS_linear3d_apply_seq(benchmark::State& s) { run_apply(s, mls(MlsBasis::linear_3d), exec::seq, paper_problem()); }
void BM_MLS_linear3d_apply_omp(benchmark::State& s) { run_apply(s, mls(MlsBasis::linear_3d), exec::omp, paper_problem()); }
void BM_RBF_geodesic_sparse_apply_seq(benchmark::State& s) { run_apply(s, rbf(), exec::seq, rbf_problem()); }
void BM_RBF_geodesic_sparse_apply_omp(benchmark::State& s) { run_apply(s, rbf(), exec::omp, rbf_problem()); }

void BM_LocalLinear_apply_seq(benchmark::State& s) { run_apply(s, local_linear(), exec::seq, paper_problem()); }
void BM_LocalLinear_apply_omp(benchmark::State& s) { run_apply(s, local_linear(), exec::omp, paper_problem()); }
/// The demo's fit at the paper's size: 35,637 vertices × (Gram of 60 × 240, 9 λ × 2 folds + 1 solves).
void BM_LocalLinear_train_cv_omp(benchmark::State& s) {
  for (auto _ : s) {
    LocalLinear<> m;
    m.fit(exec::omp, paper_problem());
    m.train(exec::omp, paper_frames(), {});
    s.counters["lambda"] = m.info().lambda_relative;
  }
}

void BM_MLS_as_written_fit_omp(benchmark::State& s) {
  for (auto _ : s) {
    MLS<> m;
    m.fit(exec::omp, paper_problem());
  }
}
/// The paper-size RBF fit: HR-surface Dijkstra per LR vertex within σ·sqrt(ln 1e10), sparse LDLᵀ
/// (σ = mapped-centre spacing, the default). Measured (2 cores): 0.94 s, 233,566 entries in Φ_LL's
/// lower triangle, 3.28M in L, rcond (min|D|/max|D|) 0.14.
void BM_RBF_geodesic_sparse_fit_omp(benchmark::State& s) {
  for (auto _ : s) {
    RBF<> r;
    r.fit(exec::omp, rbf_problem());
    s.counters["lr_nnz"] = double(r.info().lr_nonzeros);
    s.counters["L_nnz"] = double(r.info().factor_nonzeros);
    s.counters["sigma"] = r.info().sigma;
  }
}
/// The same fit with σ = the mean LR edge length (the old default, 4.6× the centre spacing here):
/// 67 s, 37.2M entries in L, rcond 4e-12, and Φ_LL indefinite (negative pivots: SimplicialLLT
/// fails), which is why LDLᵀ stays the sparse factorization.
void BM_RBF_geodesic_sparse_fit_sigma_lr_edge_omp(benchmark::State& s) {
  for (auto _ : s) {
    RBF<> r(RBFOptions{.sigma = interp::detail::mean_edge_length(rbf_problem().lr.V, rbf_problem().lr.T, "bench"),
                       .solver = RbfSolver::sparse, .min_rcond = 0});
    r.fit(exec::omp, rbf_problem());
    s.counters["lr_nnz"] = double(r.info().lr_nonzeros);
    s.counters["L_nnz"] = double(r.info().factor_nonzeros);
  }
}

}  // namespace

BENCHMARK(BM_IDW_apply_seq)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IDW_apply_omp)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MLS_as_written_apply_seq)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MLS_as_written_apply_omp)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MLS_linear3d_apply_seq)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MLS_linear3d_apply_omp)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LocalLinear_apply_seq)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LocalLinear_apply_omp)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LocalLinear_train_cv_omp)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_MLS_as_written_fit_omp)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_RBF_geodesic_sparse_fit_omp)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_RBF_geodesic_sparse_fit_sigma_lr_edge_omp)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_RBF_geodesic_sparse_apply_seq)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RBF_geodesic_sparse_apply_omp)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
