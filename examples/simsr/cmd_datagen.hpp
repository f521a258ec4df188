#pragma once
// `simsr datagen --scenario face --out DIR [--performances amazement,anger,fear,pain]
//  [--controls C.npz …] [--frames F] [--seed S] [--lr-cell H] [--preset default|paper-ratio|paper-lr]`:
// the face of the core paper simulated at two resolutions from the same controls
// (scenario/face/face_datagen.hpp). Progress (frames/s, ETA) on stderr, a JSON summary on
// stdout and in DIR/face_data.json. A rerun resumes; a finished performance is reused. Then the
// LR-only unseen-force sequences of §5.3 in DIR/unseen/ (scenario/face/unseen_forces.hpp;
// --no-unseen-forces skips them).
//
// `simsr datagen --scenario softdeca --samples N --out DIR [--template ict|sphere] [--layers L]
//  [--sphere-level K] [--seed S] [--steps K] [--solver local_global|newton] [--active-expressions A]
//  [--skin-edge CM] [--linear-solver simplicial|cholmod] [--max-iterations N] [--newton-iterations N]
//  [--stop-on-unconverged]`:
// SoftDECA's layered head template (from the same kit, or the sphere stand-in of
// scenario/softdeca/sphere_template.hpp), N sampled parameter sets and expressions simulated on it
// (scenario/softdeca/softdeca_datagen.hpp), resumable, a progress line per sample. --skin-edge
// remeshes the kit's outer wrap to that edge length first (needs a build with CGAL);
// --linear-solver cholmod factors with CHOLMOD (needs a build with it).
// Under `mpirun -np R` (a build with -DSIMSR_WITH_MPI=ON) the samples are shared over the ranks,
// a contiguous block each (mpi/softdeca_datagen.hpp): the single process's files, bitwise; and
// --scenario face's performances (mpi/face_datagen.hpp), each in --chunks contiguous chunks of
// its frames (default: ⌈R / performances⌉) after --chunk-overlap lead-in frames: bitwise with
// one chunk, to the solver tolerance past a chunk's lead-in otherwise.
#include <simsr/scenario/scenario.hpp>
#include <simsr/shell/cloth_datagen.hpp>
#include <simsr/scenario/softdeca/softdeca_datagen.hpp>
#include <simsr/scenario/softdeca/sphere_template.hpp>
#if defined(SIMSR_HAVE_MPI)
#include <simsr/mpi/face_datagen.hpp>
#include <simsr/mpi/softdeca_datagen.hpp>
#endif
#if defined(SIMSR_HAVE_CGAL)
#include "remeshed_wrap.hpp"
#endif
#include "cloth_fine_options.hpp"
#include "cloth_stepping_options.hpp"
#include "linear_solver_choice.hpp"
#include "mpi_session.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

namespace simsr::cli {

struct DatagenArgs {
  std::string scenario = "face", out, kit = "../shared/data/ict_face", preset = "default";
  std::vector<std::string> performances{"amazement", "anger", "fear", "pain"}, controls;
  Index frames = 120;
  std::uint64_t seed = 1;
  double lr_cell = 0, skull_lattice = 0, hr_max_volume = 0;
  Index checkpoint_every = 10;
  Index chunks = 0, chunk_overlap = 2;  ///< face: chunks per performance (0: ⌈ranks / performances⌉), lead-in frames
  bool unseen_forces = true;
  bool stop_on_unconverged = false;
  Index vtk_every = 10;
  Index unseen_frames = 40;
  // softdeca
  Index samples = 100, layers = 1, steps = 6, sphere_level = 3, max_iterations = 5000, newton_iterations = 100;
  std::optional<Index> active_expressions;
  std::string solver = "local_global", softdeca_template = "ict", linear_solver = "simplicial";
  ClothSteppingArgs stepping;  ///< sheet, disk: --substeps, --stepping, --step-iterations
  double skin_edge = 0;
  // sheet / disk
  Index sequences = 0, cells = 0, levels = -1, fine_cells = 0, sequence_workers = 0;
  std::string fine_frames_from;  ///< sheet/disk: a dataset whose fine frames this one takes
  CLI::Option* seed_given = nullptr;  ///< sheet/disk: without --seed, the library's (the demo's) seed
};

/// The dataset with the linear solver --linear-solver names.
template <class Template>
nlohmann::ordered_json softdeca_dataset_with(const DatagenArgs& a, const Template& tpl, const std::string& name, const scenario::SoftDecaDatagenOptions& o,
                                             const std::function<void(const std::string&)>& say) {
  return with_linear_solver(a.linear_solver, [&]<class L>(LinearSolverTag<L>) {
#if defined(SIMSR_HAVE_MPI)
    if (const MpiSession* session = mpi_session(); session != nullptr && session->size() > 1)  // shard r of R per rank
      return mpi::generate_softdeca_dataset<scenario::BasicSoftDecaSimulator<L>>(exec::omp, *session->world(), tpl, name, o, a.out, say);
#endif
    return scenario::generate_softdeca_dataset<scenario::BasicSoftDecaSimulator<L>>(exec::omp, tpl, name, o, a.out, say);
  });
}

inline int datagen_softdeca(const DatagenArgs& a) {
  scenario::SoftDecaDatagenOptions o;
  o.samples = a.samples;
  o.seed = a.seed;
  o.active_expressions = a.active_expressions;
  o.simulation.steps = a.steps;
  o.simulation.max_iterations = a.max_iterations;
  o.simulation.newton_iterations = a.newton_iterations;
  o.skip_unconverged = !a.stop_on_unconverged;
  o.simulation.solver = scenario::parse_softdeca_solver(a.solver);
  const std::string who = "softdeca" + rank_suffix();  // "softdeca (rank 1 of 2)" under mpirun
  const auto say = [who](const std::string& line) { std::fprintf(stderr, "%s: %s\n", who.c_str(), line.c_str()); };
  nlohmann::ordered_json j;
  if (a.softdeca_template == "ict") {
    scenario::SoftDecaTemplateOptions t;
    t.head.layers = a.layers;
    const scenario::IctKit kit = scenario::read_ict_kit(a.kit);
    scenario::IctOuterWrap wrap;
    std::string name = "ict";
    if (a.skin_edge > 0) {
#if defined(SIMSR_HAVE_CGAL)
      char edge[32];
      std::snprintf(edge, sizeof edge, "%g cm", a.skin_edge);
      say(std::string("remeshing the kit's outer wrap to ") + edge + " edges");
      wrap = remeshed_outer_wrap(exec::omp, kit, a.skin_edge);
      name = std::string("ict remeshed to ") + edge;
#else
      throw ArgumentError("--skin-edge: this simsr was built without CGAL (configure with -DSIMSR_WITH_CGAL=ON)");
#endif
    } else {
      wrap = scenario::ict_outer_wrap(exec::omp, kit);
    }
    say("building the layered template from " + a.kit + " (" + std::to_string(a.layers) + " layer(s) per shell)");
    const scenario::IctTemplate tpl = scenario::softdeca_template(exec::omp, kit, wrap, t);
    j = softdeca_dataset_with(a, tpl, name, o, say);
  } else if (a.softdeca_template == "sphere") {
    if (a.skin_edge > 0) throw ArgumentError("--skin-edge: only for --template ict (the sphere's resolution is --sphere-level)");
    const scenario::SoftDecaTemplate tpl = scenario::sphere_softdeca_template(exec::omp, a.sphere_level, a.layers);
    j = softdeca_dataset_with(a, tpl, "sphere level " + std::to_string(a.sphere_level), o, say);
  } else {
    throw ArgumentError("--template: ict or sphere (got '" + a.softdeca_template + "')");
  }
  nlohmann::ordered_json brief = j;
  brief.erase("per_sample");
  if (prints_results()) std::cout << brief.dump() << '\n';  // rank 0's: every rank holds the same summary
  return 0;
}

/// The thin-shell datasets (shell/cloth_datagen.hpp): a progress line per 10 frames on stderr,
/// the summary (DIR/cloth_data.json) on stdout.
inline int datagen_cloth(const DatagenArgs& a) {
  const shell::ClothDataset d = shell::cloth_dataset(a.scenario);
  shell::ClothDatagenOptions o;
  o.size = shell::scene_size(d, a.cells, a.levels, a.fine_cells);
  o.fine_frames_from = a.fine_frames_from;
  o.sequences = a.sequences;
  if (a.seed_given->count() > 0) o.seed = a.seed;  // else ClothDatagenOptions' (7): the data `simsr demo --dataset sheet|disk` simulates
  o.checkpoint_every = a.checkpoint_every;
  o.sequence_workers = a.sequence_workers;
  a.stepping.apply(o.simulation);
  const auto start = std::chrono::steady_clock::now();
  o.on_frame = [start](const std::string& seq, Index f, Index frames, const shell::ClothFrameReport& rc, const shell::ClothFrameReport& rf, double sc,
                       double sf) {
    if ((f + 1) % 10 != 0 && f + 1 != frames) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "%s frame %lld/%lld: coarse %.3f s (%lld Newton), fine %.3f s (%lld Newton), deepest %.1f mm; %.0f s so far\n", seq.c_str(),
                 static_cast<long long>(f + 1), static_cast<long long>(frames), sc, static_cast<long long>(rc.newton_iterations), sf,
                 static_cast<long long>(rf.newton_iterations), 1e3 * std::min(rc.deepest, rf.deepest), elapsed);
  };
  o.on_settle_frame = o.on_frame;  // the shared start, settled first: "settle frame 10/45: ..."
  with_linear_solver(a.linear_solver, [&]<class L>(LinearSolverTag<L>) { shell::generate_cloth_data<L>(exec::omp, d, a.out, o); });
  std::ifstream summary(std::filesystem::path(a.out) / "cloth_data.json");
  std::cout << nlohmann::ordered_json::parse(summary).dump() << '\n';
  return 0;
}

inline int datagen(const DatagenArgs& a) {
  if (a.scenario == "softdeca") return datagen_softdeca(a);
  const bool ranks = mpi_session() != nullptr && mpi_session()->size() > 1;
  if (ranks && a.scenario != "face")
    throw ArgumentError("datagen --scenario " + a.scenario + " runs on one process; under mpirun only --scenario softdeca (by sample) and face (by performance) share their work");
  if (a.scenario == "sheet" || a.scenario == "disk") return datagen_cloth(a);
  if (a.scenario != "face") throw ArgumentError("--scenario: face, softdeca, sheet or disk (got '" + a.scenario + "')");
  scenario::FaceDatasetOptions o;
  o.kit = a.kit;
  o.model = scenario::face_model_preset(a.preset, a.lr_cell, a.skull_lattice, a.hr_max_volume);
  o.performances.clear();  // `--performances ""`: none (only --controls)
  for (const auto& p : a.performances)
    if (!p.empty()) o.performances.push_back(p);
  o.controls.assign(a.controls.begin(), a.controls.end());
  o.frames = a.frames;
  o.seed = a.seed;
  o.checkpoint_every = a.checkpoint_every;
  o.chunks = a.chunks;
  o.chunk_overlap = a.chunk_overlap;
  o.vtk_every = a.vtk_every;
  o.unseen_forces = a.unseen_forces;
  o.unseen_frames = a.unseen_frames;
  const std::string who = rank_suffix();
  const auto log = [who](const std::string& line) { std::fprintf(stderr, "%s%s\n", line.c_str(), who.c_str()); };
  nlohmann::ordered_json j;
#if defined(SIMSR_HAVE_MPI)
  if (ranks)  // shard r of R of the performances per rank
    j = mpi::generate_face_dataset(exec::omp, *mpi_session()->world(), o, a.out, log);
  else
#endif
    j = scenario::generate_face_dataset(exec::omp, o, a.out, log);
  if (prints_results()) std::cout << j.dump() << '\n';
  return 0;
}

inline void add_datagen(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("datagen",
                                 "Simulate paired LR/HR data (the face of the core paper, §4; the SHEET and DISK cloths of the thin-shell paper) or "
                                 "SoftDECA's sampled layered-head data");
  auto a = std::make_shared<DatagenArgs>();
  cmd->add_option("--scenario", a->scenario,
                  "what to simulate: face (paired LR/HR frames), softdeca (sampled parameters on the layered head), sheet or disk (coarse/fine cloth "
                  "sequences)")
      ->capture_default_str();
  cmd->add_option("--sequences", a->sequences, "sheet/disk: sequences to simulate (0: sheet 32, disk 16; every 5th held out)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--cells", a->cells, "sheet: coarse cells per side (default 8: 81 vertices); disk: coarse rings (default 6: 127 vertices)")
      ->check(CLI::Range(2, 1000));
  cmd->add_option("--levels", a->levels, "sheet/disk: Loop subdivision levels from the coarse to the fine cloth (default 3)")->check(CLI::Range(0, 6));
  add_fine_cloth_options(cmd, a->fine_cells, a->fine_frames_from);
  cmd->add_option("--samples", a->samples, "softdeca: parameter samples to simulate")->capture_default_str()->check(CLI::Range(1, 10000000));
  cmd->add_option("--layers", a->layers, "softdeca: prism layers per shell of the template (its resolution)")->capture_default_str()->check(CLI::Range(1, 16));
  cmd->add_option("--steps", a->steps, "softdeca: implicit steps from rest to the expression")->capture_default_str()->check(CLI::Range(1, 10000));
  cmd->add_option("--solver", a->solver, "softdeca: local_global (projective dynamics) or newton")->capture_default_str();
  cmd->add_option("--active-expressions", a->active_expressions, "softdeca: expressions mixed per sample (default 3, or all of a template with fewer)")
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--skin-edge", a->skin_edge, "softdeca --template ict: remesh the kit's outer wrap to this edge length in cm (0: the kit's triangles; needs CGAL)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--max-iterations", a->max_iterations,
                  "softdeca --solver local_global: iterations per solve before Newton finishes it from there (the sample's result is the same to the tolerance)")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000000));
  cmd->add_option("--newton-iterations", a->newton_iterations,
                  "softdeca: Newton iterations per solve (--solver newton's own, or finishing a local-global solve); a sample not settled in them is left out")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000000));
  cmd->add_flag("--stop-on-unconverged", a->stop_on_unconverged,
               "softdeca: a sample no solver converges stops the run (default: it is left out, written to samples/*.failed.json and listed)");
  cmd->add_option("--linear-solver", a->linear_solver,
                  "softdeca, sheet, disk: the Newton steps' linear solver, simplicial (Eigen's LDLT) or cholmod (supernodal; needs CHOLMOD; the same "
                  "data to round-off, faster at the paper's sizes)")
      ->capture_default_str();
  cmd->add_option("--sequence-workers", a->sequence_workers,
                  "sheet, disk: sequences simulated at once, one thread each (0: OMP_NUM_THREADS; the same data for any count)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  add_cloth_stepping_options(cmd, a->stepping, "sheet, disk");
  cmd->add_option("--template", a->softdeca_template, "softdeca: ict (the layered head from --kit) or sphere (the stand-in ball with two expressions)")
      ->capture_default_str();
  cmd->add_option("--sphere-level", a->sphere_level, "softdeca --template sphere: icosphere level of the ball (2: 162 skin vertices, 3: 642)")
      ->capture_default_str()->check(CLI::Range(1, 6));
  cmd->add_option("--out", a->out, "output directory (rest shapes, one .npz per performance, face_data.json)")->required();
  cmd->add_option("--kit", a->kit, "the ICT face kit directory (full_neutral.obj, regions.json, expressions_full.npz)")->capture_default_str();
  cmd->add_option("--performances", a->performances, "built-in performances: amazement, anger, fear, pain (\"\": none, only --controls)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--controls", a->controls, "a controls file (.npz: names C strings, weights F×C), simulated as a performance named after the file (less a trailing _controls)");
  cmd->add_option("--frames", a->frames, "frames per built-in performance")->capture_default_str()->check(CLI::Range(14, 100000));
  a->seed_given = cmd->add_option("--seed", a->seed,
                                  "seed of the built-in performances (softdeca: of the parameter sampler; sheet/disk: of the sequences, default 7 "
                                  "as simsr demo's)")
                       ->capture_default_str();
  cmd->add_option("--preset", a->preset, "mesh sizes: default (LR 10.8k tets, 12.5x fewer than HR), paper-ratio (26x), paper-lr (LR 73k tets, the paper's)")->capture_default_str();
  cmd->add_option("--lr-cell", a->lr_cell, "LR BCC cell size in cm (overrides the preset)")->check(CLI::PositiveNumber);
  cmd->add_option("--skull-lattice", a->skull_lattice, "skull surface resolution in cm (overrides the preset)")->check(CLI::PositiveNumber);
  cmd->add_option("--hr-max-volume", a->hr_max_volume, "largest HR tet in cm^3 (overrides the preset)")->check(CLI::PositiveNumber);
  cmd->add_option("--unseen-frames", a->unseen_frames, "frames of each unseen-force sequence (DIR/unseen/)")->capture_default_str()->check(CLI::Range(2, 100000));
  cmd->add_option("--vtk-every", a->vtk_every, "write VTU series of every n-th frame to DIR/vtk/<performance>/ for ParaView (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  cmd->add_flag("!--no-unseen-forces", a->unseen_forces, "skip the LR-only unseen-force sequences (paper §5.3)");
  cmd->add_option("--checkpoint-every", a->checkpoint_every, "frames between checkpoints")->capture_default_str()->check(CLI::Range(1, 100000));
  cmd->add_option("--chunks", a->chunks,
                  "face: split each performance's frames into this many contiguous chunks, each a unit of work for the ranks of mpirun "
                  "(0: ceil(ranks / performances), 1 in one process); frames past a chunk's lead-in equal one chunk's to the solver tolerance")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--chunk-overlap", a->chunk_overlap, "face: lead-in frames solved, not written, before each chunk but a performance's first")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  cmd->callback([&action, a] { action = [a] { return datagen(*a); }; });
}

}  // namespace simsr::cli
