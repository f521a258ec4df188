// One face frame at each resolution (issue #11 item 7), beside each other in one run:
//
//   BM_face_frame/lr_default      the LR split lattice of the default model (~10.8k tets)
//   BM_face_frame/lr_paper_size   the LR lattice at the paper's size (preset paper-lr: BCC cell
//                                 0.565 cm, ~73k tets; Park et al. 2023 §4)
//   BM_face_frame/lr_paper_size_csr     the same with every product on the scalar CSR (the
//                                       baseline of the 3×3-block products, issue #17 item 1)
//   BM_face_frame/lr_paper_size_single  … with the multigrid's level matrices in single precision
//   BM_face_frame/hr_default      the HR tetgen mesh of the default model (~135k tets, lip contact)
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

/// `storage`: the multigrid's level storage (MultigridOptions::Storage); csr also runs PCG's own
/// products on the scalar CSR (the baseline of the 3×3-block products).
void BM_face_frame(benchmark::State& state, const std::string& preset, scenario::FaceResolution res,
                   physics::MultigridOptions::Storage storage = physics::MultigridOptions::Storage::block) {
  if (!std::filesystem::exists(data_dir() / "ict_face" / "full_neutral.obj")) {
    state.SkipWithError("the ICT kit is not in data_dir()/ict_face");
    return;
  }
  const auto& face = face_model(preset);
  const auto perf = scenario::builtin_performance("amazement", face.expression_names, 1);
  scenario::FaceSimulationOptions options;
  options.multigrid.storage = storage;
  options.linear.block_products = storage != physics::MultigridOptions::Storage::csr;
  scenario::FaceSimulator<> sim(exec::omp, face, res, options);
  sim.set_controls(scenario::neutral_controls(face));
  sim.step(exec::omp);
  const auto c59 = scenario::face_controls(perf, 59, face), c60 = scenario::face_controls(perf, 60, face), c61 = scenario::face_controls(perf, 61, face);
  sim.set_controls(c59);
  sim.step(exec::omp);
  const Points<> x59 = sim.positions();
  sim.set_controls(c60);
  sim.step(exec::omp);
  const Points<> x60 = sim.positions();
  physics::NewtonReport r;
  for (auto _ : state) {
    sim.set_controls(c60);
    sim.set_positions(x59, c59, x60);
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

}  // namespace

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
BENCHMARK_CAPTURE(BM_face_frame, hr_default, std::string("default"), scenario::FaceResolution::high)
    ->Name("BM_face_frame/hr_default")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

BENCHMARK_MAIN();
