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
#include <simsr/eval/error_statistics.hpp>
#include <simsr/nn/model_file.hpp>

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
  using clock = std::chrono::steady_clock;
  const auto sec = [](auto d) { return std::chrono::duration<double>(d).count(); };
  const auto t0 = clock::now();
  const io::NpzArrays arrays = nn::read_model_arrays(a.model);
  const nn::ModelData md = nn::model_data(arrays, a.model);
  nn::Rng rng(0);
  nn::SuperResolutionNet<float> net(md.config, md.geometry, rng);
  nn::load_state(net.store(), arrays);
  net.prepare_inference(exec::omp);
  const auto t1 = clock::now();

  const Index N = net.lr_points(), M = net.hr_points();
  io::NpzReader z(a.frames);
  const io::NpyArray low = read_frames(z, a.frames, "lowres", N);
  if (a.every < 1) throw ArgumentError("--every must be >= 1 (got " + std::to_string(a.every) + ")");
  std::vector<Index> sel;
  for (Index f = 0; f < low.num_frames(); f += a.every) sel.push_back(f);
  const Index F = Index(sel.size());
  const nn::Matrix<float> lr0 = nn::normalize_positions<float>(md.geometry.lr_rest, md.config.norm_mean, md.config.norm_std);
  std::vector<double> out(std::size_t(F * M * 3));
  nn::Matrix<float> ldx(N, 3), pred;
  double forward_seconds = 0;
  for (Index f = 0; f < F; ++f) {
    const Points<double> x = low.frame_points<double>(sel[std::size_t(f)]);
    for (Index r = 0; r < N; ++r)
      if (!x.row(r).allFinite())
        throw ArgumentError(a.frames + ": lowres frame " + std::to_string(sel[std::size_t(f)]) + ", vertex " + std::to_string(r) + " is not finite");
    nn::normalized_displacements(x, lr0, md.config.norm_mean, md.config.norm_std, ldx);
    const auto s = clock::now();
    net.infer(ldx, pred, exec::omp);
    forward_seconds += sec(clock::now() - s);
    // un-normalize a displacement by σ only (the mean cancels in a difference)
    Eigen::Map<Points<double>>(out.data() + f * M * 3, M, 3) = md.geometry.hr_rest + pred.cast<double>() * md.config.norm_std;
  }
  io::NpzArrays result;
  result["highres"] = io::make_npy<double>({F, M, 3}, out.data());
  std::vector<std::int64_t> ids;
  if (z.contains("frame")) {
    const auto all = z.read("frame").to_vector<std::int64_t>();
    if (Index(all.size()) != low.num_frames()) throw ShapeError(a.frames + ": frame", {low.num_frames()}, {Index(all.size())});
    for (Index f : sel) ids.push_back(all[std::size_t(f)]);
  } else {
    for (Index f : sel) ids.push_back(std::int64_t(f));
  }
  result["frame"] = io::make_npy<std::int64_t>({F}, ids.data());
  io::write_npz(a.out, result, io::NpzCompression::Deflate);

  nlohmann::ordered_json j;
  j["seconds_per_frame"] = F ? forward_seconds / double(F) : 0.0;
  j["frames"] = F;
  j["lr_vertices"] = N;
  j["hr_vertices"] = M;
  j["setup_seconds"] = sec(t1 - t0);
  j["profile"] = md.config.profile;
  if (z.contains("highres")) {
    const io::NpyArray truth = read_frames(z, a.frames, "highres", M);
    if (truth.num_frames() == low.num_frames()) {
      eval::ErrorAccumulator acc(md.geometry.hr_rest);
      for (Index f = 0; f < F; ++f)
        acc.add_frame(Eigen::Map<const Points<double>>(out.data() + f * M * 3, M, 3), truth.frame_points<double>(sel[std::size_t(f)]));
      const auto s = acc.statistics(), r = acc.relative_statistics();
      j["error"] = statistics_json(s);
      j["relative_error"] = statistics_json(r);
    }
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
