// The thin-shell cloth simulator (issue #14; Chen et al. 2023's data): one frame of the SHEET
// scene at each resolution the supplement names, with Eigen's simplicial LDLᵀ (the default) and,
// built with -DSIMSR_WITH_CHOLMOD=ON, CHOLMOD's supernodal LLᵀ factoring the Newton steps. At the
// fine sizes the factorization is nearly all of a step, so the ratio of the two is what
// `simsr datagen --scenario sheet --linear-solver cholmod` saves. The supplement's ARCSim took
// 2.48 s per frame at SHEET's 4,225 vertices (another machine, another simulator).
//
// Scenes: SHEET's coarse 8 × 8 cells (81 vertices) Loop-subdivided to the named fine size:
//   sheet_81     the coarse cloth itself
//   sheet_1089   Loop ×2 (the ×16 faces the README's SHEET figures use)
//   sheet_4225   Loop ×3 (the paper's SHEET: ×64 faces)
// Each iteration restores the same state (the cloth settled 12 frames under a pole coming down,
// about to touch it) and simulates the next 4 frames with the pole pressing in: contact, the
// membrane in compression, halved steps where Newton fails, as in the datagen.
//
// Cases (wall clock, ms per 4 frames; counters: newton_per_frame, s_per_newton):
//   BM_cloth_frames/<scene>/simplicial
//   BM_cloth_frames/<scene>/cholmod            (-DSIMSR_WITH_CHOLMOD=ON)
//   BM_cloth_frames/<scene>/cholmod/converged  each step's Newton solve converged, 2 steps per frame
//                                              (the default before the inexact steps: their baseline)
//
// The detail-synthesis network's training (shell/detail_synthesis.hpp), the supplement's sizes
// (9 channels, 16-d latent, 3 input frames) on SHEET's coarse 81 and fine <scene> vertices:
//   BM_synthesis_train_step/<scene>           one Adam step on 16 windows of random features
//                                             (an epoch of the 32-sequence SHEET is ~190 steps)
//   BM_tanh/<scene>/eigen                     nn::Tanh<float> forward on one step's fine-encoder
//   BM_tanh/<scene>/libm                      input (64 frames × fine vertices × 9); beside it the
//                                             per-element std::tanh loop nn::Tanh ran before
//
// Collision refinement (shell/collision_refinement.hpp) on DISK's fine cloth (7,057 vertices, the
// default 6 rings Loop ×3), wrinkled 5 mm and pressed 3 cm into a sphere (~390 vertices inside;
// the DISK run's held-out frames averaged ~470): Table 1's "refinement" stage, which the DISK run
// measured at 0.123 s per frame (simplicial, every solve analysed anew) against the supplement's
// 0.008.
//   BM_collision_refinement/disk_7057/<solver>         one frame refined (ms; counter solves)
//   BM_refinement_factorization/disk_7057/<solver>/analyse_each
//                                                      one solve's matrix factored from nothing:
//                                                      ordering, symbolic and numeric (what every
//                                                      solve did before the pattern was kept)
//   BM_refinement_factorization/disk_7057/<solver>/factor_only
//                                                      the numeric factorization on the kept
//                                                      analysis (every solve now)
// <solver>: simplicial (Eigen's LDLᵀ, the default) or cholmod (-DSIMSR_WITH_CHOLMOD=ON).
//
// Run: OMP_NUM_THREADS=2 build/benchmarks/bench_shell [--benchmark_filter=4225]
// CHOLMOD's supernodal kernels are BLAS: with Debian's reference BLAS they are ~3× slower than
// with OpenBLAS (scripts/deps.sh test installs libopenblas0-pthread).
#include <benchmark/benchmark.h>

#if defined(SIMSR_HAVE_CHOLMOD)
#include <simsr/physics/linear_solvers/cholmod_cholesky.hpp>
#endif
#include <simsr/shell/cloth_scenes.hpp>
#include <simsr/shell/cloth_simulator.hpp>
#include <simsr/shell/collision_refinement.hpp>
#include <simsr/shell/detail_synthesis.hpp>

#include <cmath>
#include <cstdint>
#include <string>

namespace {

using namespace simsr;
using namespace simsr::shell;

/// The pole of every case: across the sheet, slightly off centre, pressing 15 cm in.
SheetSequence pole() {
  SheetSequence s;
  s.pole = true;
  s.radius = 0.04;
  s.centre = Vec3<>(0.06, -0.04, -0.15);
  s.heading = 0.5;
  s.descent_time = 0.6;
  s.hold_time = 0.5;
  s.start_height = 0.35;
  return s;
}

constexpr Index warmup_frames = 12, timed_frames = 4;

/// `converged`: each step solved to convergence at 2 steps per frame (the default before the
/// inexact steps: the named baseline of their ratio); otherwise ClothOptions' default.
template <class Linear>
void cloth_frames(benchmark::State& state, Index levels, bool converged = false) {
  const ClothPair pair = cloth_pair(ClothDataset::sheet, {8, levels});
  const SheetSequence seq = pole();
  ClothOptions options;
  if (converged) {
    options.substeps = 2;
    options.newton = cloth_newton_options(ClothStepping::converged);
  }
  ClothSimulator<physics::Capsule<>, Linear> sim(pair.fine, pair.pinned, seq.obstacle_at(0), {}, options);
  const auto move = [&](physics::Capsule<>& o, double t) { o = seq.obstacle_at(t); };
  for (Index f = 0; f < warmup_frames; ++f) sim.advance(exec::omp, move);
  const Points<> x = sim.positions(), previous = sim.previous_positions();
  const Index steps = sim.steps();
  const double last = sim.last_step();
  Index newton = 0, frames = 0;
  for (auto _ : state) {
    sim.set_state(x, previous, steps, last);
    for (Index f = 0; f < timed_frames; ++f) newton += sim.advance(exec::omp, move).newton_iterations;
    frames += timed_frames;
  }
  state.counters["newton_per_frame"] = double(newton) / double(frames);
  state.counters["s_per_newton"] = benchmark::Counter(double(newton), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["vertices"] = double(pair.fine.V.rows());
}

/// One training step of the detail-synthesis network at SHEET's coarse 81 / fine (Loop ×levels)
/// vertices, on one 40-frame sequence of random normalized features, 16 windows per step.
void synthesis_train_step(benchmark::State& state, Index levels) {
  const ClothPair pair = cloth_pair(ClothDataset::sheet, {8, levels});
  const Index N = pair.coarse.V.rows(), M = pair.fine.V.rows();
  DetailSynthesisNet<float> net(vertex_adjacency(pair.coarse.F, N), vertex_adjacency(pair.fine.F, M), {}, 1);
  nn::Rng rng(3);
  std::vector<SequenceFeatures<float>> seqs(1);
  seqs[0].frames = 40;
  seqs[0].coarse = nn::Matrix<float>::Random(40 * N, ts_acap_feature_dim);
  seqs[0].fine = nn::Matrix<float>::Random(40 * M, ts_acap_feature_dim);
  SynthesisBatch batch;
  for (Index i = 0; i < 16; ++i) batch.windows.push_back({0, 2 * i});
  net.train_step(exec::omp, seqs, batch, rng);  // warm: every buffer sized
  for (auto _ : state) benchmark::DoNotOptimize(net.train_step(exec::omp, seqs, batch, rng).total());
  state.counters["fine_vertices"] = double(M);
}

/// nn::Tanh's forward against the per-element std::tanh loop, on one step's fine-encoder input.
void tanh_forward(benchmark::State& state, Index levels, bool libm) {
  const Index M = cloth_pair(ClothDataset::sheet, {8, levels}).fine.V.rows();
  const nn::Matrix<float> x = nn::Matrix<float>::Random(64 * M, ts_acap_feature_dim) * 3.0f;
  nn::Matrix<float> y(x.rows(), x.cols());
  nn::Tanh<float> act;
  for (auto _ : state) {
    if (libm) {
      for (Index i = 0; i < x.size(); ++i) y.data()[i] = std::tanh(x.data()[i]);
    } else {
      act.forward(exec::omp, nn::Mode::train, x, y);
    }
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * x.size());
}

/// DISK's fine rest cloth (the default 6 rings, Loop ×3) wrinkled along x, and a sphere it is
/// pressed 3 cm into.
Points<> disk_pressed(const ClothPair& pair, physics::Sphere<>& sphere) {
  Points<> x = pair.fine.V;
  const double top = x.col(2).mean();
  for (Index i = 0; i < x.rows(); ++i) x(i, 2) = top + 0.005 * std::sin(60 * x(i, 0));
  sphere = physics::Sphere<>(Vec3<>(x.col(0).mean(), x.col(1).mean(), top - 0.5), 0.53);
  return x;
}

template <class Linear>
void collision_refinement(benchmark::State& state) {
  const ClothPair pair = cloth_pair(ClothDataset::disk, {6, 3});
  physics::Sphere<> sphere(Vec3<>::Zero(), 1);
  const Points<> x0 = disk_pressed(pair, sphere);
  CollisionRefinement<Linear> refine(pair.fine);
  Points<> x = x0;
  CollisionRefinementReport r = refine.refine(exec::omp, sphere, x);  // warm: the analysis made
  for (auto _ : state) {
    x = x0;
    r = refine.refine(exec::omp, sphere, x);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["solves"] = double(r.solves);
  state.counters["inside"] = double(r.inside_before);
  state.counters["vertices"] = double(x0.rows());
}

/// One solve's matrix (the system with the inside vertices' weights on its diagonal) factored by
/// `Linear`: analysed anew each time (a new pattern version) or on the kept analysis.
template <class Linear>
void refinement_factorization(benchmark::State& state, bool analyse_each) {
  const ClothPair pair = cloth_pair(ClothDataset::disk, {6, 3});
  physics::Sphere<> sphere(Vec3<>::Zero(), 1);
  const Points<> x0 = disk_pressed(pair, sphere);
  const CollisionRefinement<Linear> refine(pair.fine);
  physics::SparseMatrix<double> A = refine.system_matrix();
  for (Index i = 0; i < x0.rows(); ++i)
    if (sphere.distance(Vec3<>(x0.row(i).transpose())) < 0) A.coeffRef(i, i) *= 1e4 + 1;
  Linear solver;
  std::uint64_t version = 1;
  solver.compute(exec::omp, A, version);
  for (auto _ : state) {
    if (analyse_each) ++version;
    solver.compute(exec::omp, A, version);
  }
  state.counters["nonzeros"] = double(A.nonZeros());
}

template <class Linear>
void register_refinement(const std::string& solver) {
  benchmark::RegisterBenchmark(("BM_collision_refinement/disk_7057/" + solver).c_str(), collision_refinement<Linear>)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  for (const bool each : {true, false})
    benchmark::RegisterBenchmark(("BM_refinement_factorization/disk_7057/" + solver + (each ? "/analyse_each" : "/factor_only")).c_str(),
                                 [each](benchmark::State& s) { refinement_factorization<Linear>(s, each); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
}

void register_cases() {
  register_refinement<physics::SparseCholesky<>>("simplicial");
#if defined(SIMSR_HAVE_CHOLMOD)
  register_refinement<physics::CholmodCholesky<>>("cholmod");
#endif
  for (const auto& [name, levels] : {std::pair<const char*, Index>{"sheet_81", 0}, {"sheet_1089", 2}, {"sheet_4225", 3}}) {
    const Index l = levels;
    benchmark::RegisterBenchmark((std::string("BM_cloth_frames/") + name + "/simplicial").c_str(),
                                 [l](benchmark::State& s) { cloth_frames<physics::SparseCholesky<>>(s, l); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
#if defined(SIMSR_HAVE_CHOLMOD)
    benchmark::RegisterBenchmark((std::string("BM_cloth_frames/") + name + "/cholmod").c_str(),
                                 [l](benchmark::State& s) { cloth_frames<physics::CholmodCholesky<>>(s, l); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark((std::string("BM_cloth_frames/") + name + "/cholmod/converged").c_str(),
                                 [l](benchmark::State& s) { cloth_frames<physics::CholmodCholesky<>>(s, l, true); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
#endif
  }
  for (const auto& [name, levels] : {std::pair<const char*, Index>{"sheet_1089", 2}, {"sheet_4225", 3}}) {
    const Index l = levels;
    benchmark::RegisterBenchmark((std::string("BM_synthesis_train_step/") + name).c_str(), [l](benchmark::State& s) { synthesis_train_step(s, l); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    for (const bool libm : {false, true})
      benchmark::RegisterBenchmark((std::string("BM_tanh/") + name + (libm ? "/libm" : "/eigen")).c_str(),
                                   [l, libm](benchmark::State& s) { tanh_forward(s, l, libm); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_cases();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
