// One face frame at each resolution (issue #11 item 7), beside each other in one run:
//
//   BM_face_frame/lr_default      the LR split lattice of the default model (~10.8k tets)
//   BM_face_frame/lr_paper_size   the LR lattice at the paper's size (preset paper-lr: BCC cell
//                                 0.565 cm, ~73k tets; Park et al. 2023 §4)
//   BM_face_frame/lr_paper_size_csr     the same with every product on the scalar CSR (the
//                                       baseline of the 3×3-block products, issue #17 item 1)
//   BM_face_frame/lr_paper_size_single  … with the multigrid's level matrices in single precision
//   BM_face_frame/hr_default      the HR tetgen mesh of the default model (~135k tets, lip contact)
//   BM_face_frame/lr_paper_size_…_sequence   frame 60 solved (untimed) before each timed frame 61,
//       as in a run: `single` the defaults before issue #17 item 1 switched them (fixed forcing,
//       one Jacobi sweep, levels rebuilt at every setup; single-precision levels), the baseline;
//       `fixed_forcing` today's defaults with each Newton system solved to linear.tolerance;
//       `defaults` FaceSimulationOptions{} (Eisenstat–Walker forcing at LR, Chebyshev degree 2,
//       coarse levels kept over 4 setups, single-precision levels)
//   BM_face_frame/hr_default_{previous,defaults}_sequence   the same at HR (hr_forcing: fixed)
//   BM_face_performance/lr_paper_size_…   the whole 120-frame amazement performance at the paper's
//       LR size, stepped as `simsr datagen` does, timed as one (counter ms_per_frame), with the
//       same three settings and `defaults_doubling` (the defaults with the lattice hierarchy of
//       before 2026-12-07, the cell size doubling per level); counters diff_vs_previous_* and diff_vs_converged_* (max and mean
//       vertex distance over all frames, mm) against the previous defaults' frames and against
//       the frames converged to ‖g‖ ≤ 1e-9 × the forces' scale (both solved untimed first)
//
// Scene: the ICT face from the bundled kit (data_dir()/ict_face), the model built once per
// resolution case (tetgen, lattice, muscles; untimed). A frame is what `simsr datagen` does for
// amazement frame 61 (built-in performance, seed 1): from frames 59 and 60 solved once at setup
// (from the settled neutral), every timed iteration restores them (set_positions with the frame
// before, so the warm start extrapolates as in a run), sets frame 61's controls and steps:
// warm start (jaw carry, extrapolation, energy choice) + Newton to the default tolerances.
// Counters: newton_iterations, linear_iterations, tets, vertices, fps.
//
//     OMP_NUM_THREADS=2 build/benchmarks/bench_face
#include <benchmark/benchmark.h>

#include <simsr/scenario/scenario.hpp>

#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include <unistd.h>

#include "bench_data.hpp"

using namespace simsr;

namespace {

/// The model of a preset, built once per process.
const scenario::FaceModel& face_model(const std::string& preset) {
  static std::map<std::string, std::unique_ptr<scenario::FaceModel>> cache;
  auto& slot = cache[preset];
  if (!slot) {
    static const scenario::IctKit kit = scenario::read_ict_kit(data_dir() / "ict_face");
    const scenario::FaceModelOptions o = scenario::face_model_preset(preset);  // as `simsr datagen --preset`
    const auto work = std::filesystem::temp_directory_path() / ("simsr_bench_face_" + preset + "_" + std::to_string(::getpid()));
    slot = std::make_unique<scenario::FaceModel>(scenario::build_face_model(exec::omp, kit, o, work));
    std::filesystem::remove_all(work);
    std::fprintf(stderr, "bench_face: %s model: HR %lld tets, LR %lld tets\n", preset.c_str(), (long long)slot->hr.num_tets(), (long long)slot->lr.num_tets());
  }
  return *slot;
}

/// How a case sets the Newton and multigrid options.
enum class Solver {
  /// FaceSimulationOptions' defaults before issue #17 item 1 switched them (2026-12-06), the
  /// rows' baseline: fixed forcing, one Jacobi sweep, the levels rebuilt at every setup, no
  /// carried first step, the cell size doubling per level
  previous,
  /// the defaults with each Newton system solved to linear.tolerance (fixed forcing), the
  /// Eisenstat–Walker forcing's baseline
  fixed_forcing,
  /// FaceSimulationOptions{} as it is: Eisenstat–Walker forcing at LR, a Chebyshev smoother of
  /// degree 2, coarse levels kept over 4 setups, single-precision levels, each coarse level at
  /// most 1/8 of the one before
  defaults,
  /// the defaults with the lattice hierarchy as before 2026-12-07 (the cell size doubling per
  /// level: LatticeHierarchyOptions::coarsening = 0), the coarsening's baseline
  doubling,
};

/// FaceSimulationOptions for `solver` (with the multigrid's `storage`; csr also runs PCG's own
/// products on the scalar CSR).
scenario::FaceSimulationOptions solver_options(Solver solver, physics::MultigridOptions::Storage storage) {
  scenario::FaceSimulationOptions options;
  options.multigrid.storage = storage;
  options.linear.block_products = storage != physics::MultigridOptions::Storage::csr;
  if (solver == Solver::defaults) return options;
  if (solver == Solver::doubling || solver == Solver::previous) options.hierarchy.coarsening = 0;
  if (solver == Solver::doubling) return options;
  options.newton.forcing = physics::NewtonOptions::Forcing::fixed;
  if (solver == Solver::previous) {
    options.multigrid.coarse_refresh_every = 1;
    options.multigrid.smoother = physics::MultigridOptions::Smoother::jacobi;
  }
  return options;
}

/// `storage`: the multigrid's level storage (MultigridOptions::Storage); csr also runs PCG's own
/// products on the scalar CSR (the baseline of the 3×3-block products). `sequence`: frame 60 is
/// solved (untimed, from 59) before each timed frame 61, as in a run, so what the solver carries
/// into 61 (lagged coarse levels, a chord_first setup) is frame 60's, not the last timed 61's.
void BM_face_frame(benchmark::State& state, const std::string& preset, scenario::FaceResolution res,
                   physics::MultigridOptions::Storage storage = physics::MultigridOptions::Storage::block, Solver solver = Solver::previous,
                   bool sequence = false) {
  if (!std::filesystem::exists(data_dir() / "ict_face" / "full_neutral.obj")) {
    state.SkipWithError("the ICT kit is not in data_dir()/ict_face");
    return;
  }
  const auto& face = face_model(preset);
  const auto perf = scenario::builtin_performance("amazement", face.expression_names, 1);
  scenario::FaceSimulator<> sim(exec::omp, face, res, solver_options(solver, storage));
  sim.set_controls(scenario::neutral_controls(face));
  sim.step(exec::omp);
  const auto c58 = scenario::face_controls(perf, 58, face), c59 = scenario::face_controls(perf, 59, face), c60 = scenario::face_controls(perf, 60, face),
             c61 = scenario::face_controls(perf, 61, face);
  Points<> x58;  // `sequence` only: the frame 60 is solved from (the other rows start at 59, as before)
  if (sequence) {
    sim.set_controls(c58);
    sim.step(exec::omp);
    x58 = sim.positions();
  }
  sim.set_controls(c59);
  sim.step(exec::omp);
  const Points<> x59 = sim.positions();
  sim.set_controls(c60);
  sim.step(exec::omp);
  const Points<> x60 = sim.positions();
  physics::NewtonReport r;
  for (auto _ : state) {
    if (sequence) {
      state.PauseTiming();
      sim.set_controls(c59);
      sim.set_positions(x58, c58, x59);
      sim.set_controls(c60);
      sim.step(exec::omp);
      state.ResumeTiming();
    } else {
      sim.set_controls(c60);
      sim.set_positions(x59, c59, x60);
    }
    sim.set_controls(c61);
    r = sim.step(exec::omp);
    benchmark::DoNotOptimize(sim.positions().data());
  }
  const TetMesh<>& m = res == scenario::FaceResolution::high ? face.hr : face.lr;
  state.counters["newton_iterations"] = double(r.iterations);
  state.counters["linear_iterations"] = double(r.linear_iterations);
  state.counters["tets"] = double(m.num_tets());
  state.counters["vertices"] = double(m.num_vertices());
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

/// A whole built-in performance (amazement, seed 1, 120 frames) from the settled neutral, as
/// `simsr datagen` steps it, timed as one: counters ms_per_frame, the Newton and PCG iterations
/// summed over the frames, and how far each frame's vertices lie from the same frame solved with
/// Solver::previous and from the same frame converged far below the default tolerances (max and
/// mean over frames and vertices, mm: the spread the default tolerances allow, and the error).
void BM_face_performance(benchmark::State& state, const std::string& preset, Solver solver) {
  if (!std::filesystem::exists(data_dir() / "ict_face" / "full_neutral.obj")) {
    state.SkipWithError("the ICT kit is not in data_dir()/ict_face");
    return;
  }
  const auto& face = face_model(preset);
  const auto perf = scenario::builtin_performance("amazement", face.expression_names, 1);
  // per preset, untimed: Solver::previous' frames, and the frames converged far below the default
  // tolerances (‖g‖ ≤ 1e-9 × the forces' scale, PCG to 1e-8), the yardstick of both
  static std::map<std::string, std::vector<Points<>>> reference, converged;
  const auto run = [&](Solver which, std::vector<Points<>>& frames, Index& newton, Index& linear, bool tight = false) {
    scenario::FaceSimulationOptions options = solver_options(which, physics::MultigridOptions::Storage::block_single);
    if (tight) {
      options.newton.relative_tolerance = 1e-9;
      options.newton.absolute_tolerance = 0;
      options.newton.max_iterations = 100;
      options.linear.tolerance = 1e-8;
    }
    scenario::FaceSimulator<> sim(exec::omp, face, scenario::FaceResolution::low, options);
    sim.set_controls(scenario::neutral_controls(face));
    sim.step(exec::omp);
    newton = linear = 0;
    for (Index f = 0; f < perf.num_frames(); ++f) {
      sim.set_controls(scenario::face_controls(perf, f, face));
      const physics::NewtonReport r = sim.step(exec::omp);
      newton += r.iterations;
      linear += r.linear_iterations;
      frames[std::size_t(f)] = sim.positions();  // same size: into the storage made before
    }
  };
  // every frame's storage made (and touched) before any timing: no allocation inside the timed run
  const auto frame_storage = [&] { return std::vector<Points<>>(std::size_t(perf.num_frames()), Points<>::Zero(face.lr.num_vertices(), 3)); };
  if (!reference.count(preset)) {
    Index n = 0, l = 0;
    reference[preset] = frame_storage();
    converged[preset] = frame_storage();
    run(Solver::previous, reference[preset], n, l);
    run(Solver::previous, converged[preset], n, l, true);
  }
  std::vector<Points<>> frames = frame_storage();
  Index newton = 0, linear = 0;
  for (auto _ : state) run(solver, frames, newton, linear);
  // max and mean over frames and vertices of |x − y| (mm)
  const auto spread = [&](const std::vector<Points<>>& other, const char* name) {
    double max_diff = 0, sum_diff = 0;
    Index count = 0;
    for (std::size_t f = 0; f < frames.size(); ++f) {
      const VecX<> d = (frames[f] - other[f]).rowwise().norm();
      max_diff = std::max(max_diff, d.maxCoeff());
      sum_diff += d.sum();
      count += d.size();
    }
    state.counters[std::string(name) + "_max_mm"] = 1e3 * max_diff;
    state.counters[std::string(name) + "_mean_mm"] = 1e3 * sum_diff / double(std::max<Index>(count, 1));
  };
  spread(reference[preset], "diff_vs_previous");
  spread(converged[preset], "diff_vs_converged");
  const double F = double(perf.num_frames());
  state.counters["frames"] = F;
  state.counters["ms_per_frame"] = benchmark::Counter(F, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["newton_iterations"] = double(newton);
  state.counters["linear_iterations"] = double(linear);
}

}  // namespace

BENCHMARK_CAPTURE(BM_face_performance, lr_paper_size_single, std::string("paper-lr"), Solver::previous)
    ->Name("BM_face_performance/lr_paper_size_single")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_face_performance, lr_paper_size_fixed_forcing, std::string("paper-lr"), Solver::fixed_forcing)
    ->Name("BM_face_performance/lr_paper_size_fixed_forcing")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_face_performance, lr_paper_size_defaults, std::string("paper-lr"), Solver::defaults)
    ->Name("BM_face_performance/lr_paper_size_defaults")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_face_performance, lr_paper_size_defaults_doubling, std::string("paper-lr"), Solver::doubling)
    ->Name("BM_face_performance/lr_paper_size_defaults_doubling")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

BENCHMARK_CAPTURE(BM_face_frame, lr_default, std::string("default"), scenario::FaceResolution::low)
    ->Name("BM_face_frame/lr_default")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK_CAPTURE(BM_face_frame, lr_paper_size, std::string("paper-lr"), scenario::FaceResolution::low)
    ->Name("BM_face_frame/lr_paper_size")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(5);
BENCHMARK_CAPTURE(BM_face_frame, lr_paper_size_csr, std::string("paper-lr"), scenario::FaceResolution::low, physics::MultigridOptions::Storage::csr)
    ->Name("BM_face_frame/lr_paper_size_csr")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(5);
BENCHMARK_CAPTURE(BM_face_frame, lr_paper_size_single, std::string("paper-lr"), scenario::FaceResolution::low, physics::MultigridOptions::Storage::block_single)
    ->Name("BM_face_frame/lr_paper_size_single")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(5);
// in a sequence (frame 60 solved untimed before each timed 61): the previous defaults (with
// single-precision levels), today's with fixed forcing, today's
BENCHMARK_CAPTURE(BM_face_frame, lr_paper_size_single_sequence, std::string("paper-lr"), scenario::FaceResolution::low,
                  physics::MultigridOptions::Storage::block_single, Solver::previous, true)
    ->Name("BM_face_frame/lr_paper_size_single_sequence")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(5);
BENCHMARK_CAPTURE(BM_face_frame, lr_paper_size_fixed_forcing_sequence, std::string("paper-lr"), scenario::FaceResolution::low,
                  physics::MultigridOptions::Storage::block_single, Solver::fixed_forcing, true)
    ->Name("BM_face_frame/lr_paper_size_fixed_forcing_sequence")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(5);
BENCHMARK_CAPTURE(BM_face_frame, lr_paper_size_defaults_sequence, std::string("paper-lr"), scenario::FaceResolution::low,
                  physics::MultigridOptions::Storage::block_single, Solver::defaults, true)
    ->Name("BM_face_frame/lr_paper_size_defaults_sequence")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(5);
BENCHMARK_CAPTURE(BM_face_frame, hr_default, std::string("default"), scenario::FaceResolution::high)
    ->Name("BM_face_frame/hr_default")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
BENCHMARK_CAPTURE(BM_face_frame, hr_default_defaults_sequence, std::string("default"), scenario::FaceResolution::high,
                  physics::MultigridOptions::Storage::block_single, Solver::defaults, true)
    ->Name("BM_face_frame/hr_default_defaults_sequence")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
BENCHMARK_CAPTURE(BM_face_frame, hr_default_previous_sequence, std::string("default"), scenario::FaceResolution::high,
                  physics::MultigridOptions::Storage::block, Solver::previous, true)
    ->Name("BM_face_frame/hr_default_previous_sequence")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

BENCHMARK_MAIN();
