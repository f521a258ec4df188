// `simsr animate --model M --controls C.npz … --out OUT [--preset P] [--untrained | --method embedded]`: the face's LR
// simulation and the network live, frame after frame, pipelined on two threads (one frame of
// latency) and unpipelined beside it (pipeline/animate.hpp). Progress on stderr; the frame rates
// as JSON on stdout and in OUT/animate.json; the HR frames in OUT/<performance>.npz and
// OUT/vtk/<performance>/hr_skin.pvd.
#include <simsr/pipeline/animate.hpp>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"

namespace simsr::cli {

namespace {
struct AnimateArgs {
  pipeline::AnimateOptions o;
  std::string preset = "default";
  double lr_cell = 0;
  std::vector<std::string> controls;
  bool no_unpipelined = false;
};

int animate_cmd(AnimateArgs& a) {
  a.o.model = scenario::face_model_preset(a.preset);
  if (a.lr_cell > 0) a.o.model.lr_cell = a.lr_cell;
  a.o.controls.assign(a.controls.begin(), a.controls.end());
  a.o.unpipelined = !a.no_unpipelined;
  const auto report = pipeline::animate_face(exec::omp, a.o, [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); });
  std::cout << report.dump() << '\n';
  return 0;
}
}  // namespace

void add_animate(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("animate", "Run the face's LR simulation and the network live (pipelined and not): HR frames and frame rates");
  auto a = std::make_shared<AnimateArgs>();
  auto& o = a->o;
  cmd->add_option("--method", o.method, "what upsamples: network (--model or --untrained) or embedded (no model; any LR size)")
      ->check(CLI::IsMember({"network", "embedded"}))
      ->capture_default_str();
  cmd->add_option("--model", o.network, "a trained network (simsr demo's DIR/network/model.npz, simsr train's model)");
  cmd->add_flag("--untrained", o.untrained, "timing only: a fresh network of the default recipe on this face's meshes (no model file; the HR frames mean nothing)");
  cmd->add_option("--controls", a->controls, "controls files (.npz: names C strings, weights F×C; e.g. datagen's DIR/<performance>_controls.npz)")->required();
  cmd->add_option("--out", o.out, "output folder")->required();
  cmd->add_option("--kit", o.kit, "the ICT face kit directory")->capture_default_str();
  cmd->add_option("--preset", a->preset, "face mesh sizes, as the network's data was made: default, paper-ratio, paper-lr")
      ->check(CLI::IsMember({"default", "paper-ratio", "paper-lr"}))
      ->capture_default_str();
  cmd->add_option("--lr-cell", a->lr_cell, "LR BCC cell size in cm (overrides the preset)")->check(CLI::PositiveNumber);
  cmd->add_option("--frames", o.max_frames, "only the first n frames of each performance (0: all)")->capture_default_str()->check(CLI::Range(0, 100000));
  cmd->add_option("--source-threads", o.live.source_threads, "pipelined: OpenMP threads of the LR simulation (both 0: the slower stage, timed on the first frame, gets every core, the other one)")->capture_default_str()->check(CLI::Range(0, 1024));
  cmd->add_option("--network-threads", o.live.method_threads, "pipelined: OpenMP threads of the network (see --source-threads)")->capture_default_str()->check(CLI::Range(0, 1024));
  cmd->add_flag("--no-unpipelined", a->no_unpipelined, "skip the unpipelined run (the comparison)");
  cmd->add_option("--vtk-every", o.vtk_every, "HR VTU every n-th frame (0: none)")->capture_default_str()->check(CLI::Range(0, 100000));
  cmd->callback([&action, a] { action = [a] { return animate_cmd(*a); }; });
}

}  // namespace simsr::cli
