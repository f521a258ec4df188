#pragma once
// `simsr infer --model MODEL.npz --frames IN.npz --out OUT.npz [--every n]`
// Runs a trained network (a model file from `simsr train`, or an official PyTorch checkpoint
// converted by scripts/torch_to_simsr.py) on LR frames: IN holds `lowres` (F×N×3 absolute LR
// positions), OUT gets `highres` (F×M×3 absolute HR positions = HR rest + σ·network output) and
// the `frame` ids (IN's, or the frame indices); --every n keeps the frames f with f % n == 0.
// The upsampling weights are computed once from the rest shapes; each frame is then one
// eval-mode forward. stdout: one JSON object whose
// `seconds_per_frame` is the mean wall time of a frame's forward (also: frames, setup seconds,
// and, when IN also holds `highres`, the error statistics against it).
#include <simsr/data/data.hpp>
#include <simsr/eval/evaluate.hpp>
#include <simsr/interp/interp.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>

#include "methods.hpp"

namespace simsr::cli {

struct InferArgs {
  std::string model, frames, out;
  Index every = 1;  ///< only frames f with f % every == 0 (the held-out frames of `simsr train`)
};

inline int infer_cmd(const InferArgs& a) {
  if (a.every < 1) throw ArgumentError("--every must be >= 1 (got " + std::to_string(a.every) + ")");
  const auto t0 = std::chrono::steady_clock::now();
  const auto net = interp::Learned<>::from_model_file(a.model);
  const auto& g = net.model().geometry;
  const auto t1 = std::chrono::steady_clock::now();
  const data::FrameSet all = data::read_frame_set(a.frames, "lowres", net.num_lr());
  std::vector<Index> rows;
  for (Index f = 0; f < all.num_frames(); f += a.every) rows.push_back(f);
  const data::FrameSet lowres = all.select(rows);
  const auto out = interp::apply_frames(exec::omp, net, g.lr_rest, g.hr_rest, lowres);
  data::write_frame_set(a.out, "highres", out.highres);
  nlohmann::ordered_json j;
  j["seconds_per_frame"] = out.seconds_per_frame;
  j["frames"] = lowres.num_frames();
  j["lr_vertices"] = net.num_lr();
  j["hr_vertices"] = net.num_hr();
  j["setup_seconds"] = std::chrono::duration<double>(t1 - t0).count();
  j["profile"] = net.config().profile;
  if (io::NpzReader(a.frames).contains("highres")) {  // the truth is in the input: report the error
    const auto truth = data::read_frame_set(a.frames, "highres", net.num_hr());
    if (truth.num_frames() != all.num_frames())
      throw ShapeError(a.frames + ": highres frames (as many as lowres)", {all.num_frames()}, {truth.num_frames()});
    const auto r = eval::evaluate_predictions(g.hr_rest, out.highres, truth.select(rows), a.frames);
    j["error"] = statistics_json(r.errors.statistics());
    j["relative_error"] = statistics_json(r.errors.relative_statistics());
  }
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_infer(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("infer", "Run a trained network on LR frames: highres F×M×3 out, seconds per frame on stdout");
  auto a = std::make_shared<InferArgs>();
  cmd->add_option("--model", a->model, "model .npz (simsr train, or scripts/torch_to_simsr.py)")->required();
  cmd->add_option("--frames", a->frames, ".npz with lowres (F×N×3 absolute LR positions)")->required();
  cmd->add_option("--out", a->out, "output .npz with highres (F×M×3 absolute HR positions) and frame ids")->required();
  cmd->add_option("--every", a->every, "only frames f with f % n == 0 (n = 4: the held-out frames of simsr train)");
  cmd->callback([&action, a] { action = [a] { return infer_cmd(*a); }; });
}

}  // namespace simsr::cli
