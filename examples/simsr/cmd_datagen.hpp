#pragma once
// `simsr datagen --scenario face --out DIR [--performances amazement,anger,fear,pain]
//  [--controls C.npz …] [--frames F] [--seed S] [--lr-cell H] [--preset default|paper-ratio|paper-lr]`:
// the face of the core paper simulated at two resolutions from the same controls
// (scenario/face/face_datagen.hpp). Progress (frames/s, ETA) on stderr, a JSON summary on
// stdout and in DIR/face_data.json. A rerun resumes; a finished performance is reused. Then the
// LR-only unseen-force sequences of §5.3 in DIR/unseen/ (scenario/face/unseen_forces.hpp;
// --no-unseen-forces skips them).
#include <simsr/scenario/scenario.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

namespace simsr::cli {

struct DatagenArgs {
  std::string scenario = "face", out, kit = "../shared/data/ict_face", preset = "default";
  std::vector<std::string> performances{"amazement", "anger", "fear", "pain"}, controls;
  Index frames = 120;
  std::uint64_t seed = 1;
  double lr_cell = 0, skull_lattice = 0, hr_max_volume = 0;
  Index checkpoint_every = 10;
  bool unseen_forces = true;
  Index vtk_every = 10;
  Index unseen_frames = 40;
};

/// The mesh options of a preset, then the explicit overrides.
inline scenario::FaceModelOptions face_model_options(const DatagenArgs& a) {
  scenario::FaceModelOptions o = scenario::face_model_preset(a.preset);
  if (a.lr_cell > 0) o.lr_cell = a.lr_cell;
  if (a.skull_lattice > 0) o.skull_lattice = a.skull_lattice;
  if (a.hr_max_volume > 0) o.hr.max_volume = a.hr_max_volume;
  return o;
}

inline int datagen(const DatagenArgs& a) {
  if (a.scenario != "face") throw ArgumentError("--scenario: only 'face' is built (got '" + a.scenario + "')");
  scenario::FaceDatasetOptions o;
  o.kit = a.kit;
  o.model = face_model_options(a);
  o.performances.clear();  // `--performances ""`: none (only --controls)
  for (const auto& p : a.performances)
    if (!p.empty()) o.performances.push_back(p);
  o.controls.assign(a.controls.begin(), a.controls.end());
  o.frames = a.frames;
  o.seed = a.seed;
  o.checkpoint_every = a.checkpoint_every;
  o.vtk_every = a.vtk_every;
  o.unseen_forces = a.unseen_forces;
  o.unseen_frames = a.unseen_frames;
  const auto j = scenario::generate_face_dataset(exec::omp, o, a.out, [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); });
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_datagen(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("datagen", "Simulate paired LR/HR data (the face of the core paper, §4)");
  auto a = std::make_shared<DatagenArgs>();
  cmd->add_option("--scenario", a->scenario, "what to simulate: face")->capture_default_str();
  cmd->add_option("--out", a->out, "output directory (rest shapes, one .npz per performance, face_data.json)")->required();
  cmd->add_option("--kit", a->kit, "the ICT face kit directory (full_neutral.obj, regions.json, expressions_full.npz)")->capture_default_str();
  cmd->add_option("--performances", a->performances, "built-in performances: amazement, anger, fear, pain (\"\": none, only --controls)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--controls", a->controls, "a controls file (.npz: names C strings, weights F×C), simulated as a performance named after the file (less a trailing _controls)");
  cmd->add_option("--frames", a->frames, "frames per built-in performance")->capture_default_str()->check(CLI::Range(14, 100000));
  cmd->add_option("--seed", a->seed, "seed of the built-in performances")->capture_default_str();
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
  cmd->callback([&action, a] { action = [a] { return datagen(*a); }; });
}

}  // namespace simsr::cli
