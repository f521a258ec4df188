#pragma once
// `simsr upsample --method embedded|idw|rbf|mls|ridge|beta_vae --lr-rest L --hr-rest H --frames IN.npz --out OUT.npz`
// IN holds `lowres` (F×N×3 absolute LR positions); OUT gets `highres` (F×M×3 absolute HR
// positions, the HR rest plus the interpolated displacement, and the `frame` ids). stdout: one JSON line with the
// timings and, when IN also holds `highres` of the right shape (as the bunny's train_frames.npz
// does), the error statistics of the prediction against it.
#include <simsr/data/data.hpp>
#include <simsr/eval/evaluate.hpp>
#include <simsr/interp/interp.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "methods.hpp"

namespace simsr::cli {

struct UpsampleArgs {
  std::string method, lr, hr, frames, out, neighbors, train;
  MethodArgs params;
};

inline int upsample(const UpsampleArgs& a) {
  interp::UpsamplingProblem<> problem{data::read_lr_rest(a.lr), data::read_hr_rest(a.hr), {}, {}};
  if (!a.neighbors.empty()) problem.neighborhoods = neighbors::load_upsampling_neighborhoods(a.neighbors);
  const data::FrameSet lowres = data::read_frame_set(a.frames, "lowres", problem.num_lr());
  std::optional<data::PairedFrames<>> train;
  if (!a.train.empty()) train = data::read_paired_frames(a.train, problem.num_lr(), problem.num_hr());
  nlohmann::ordered_json j;
  with_method(a.method, a.params, [&](auto& method, const auto&... train_options) {
    const auto t0 = std::chrono::steady_clock::now();
    if constexpr (sizeof...(train_options) > 0) {
      if (!train) throw ArgumentError(a.method + " learns from frames: give them with --train");
      interp::prepare(exec::omp, method, problem, *train, train_options..., a.params.k);
    } else {
      interp::prepare(exec::omp, method, problem, a.params.k);
    }
    const auto t1 = std::chrono::steady_clock::now();
    const auto out = interp::apply_frames(exec::omp, method, problem.lr.V, problem.hr.V, lowres);
    data::write_frame_set(a.out, "highres", out.highres);
    j["method"] = a.method;
    j["frames"] = lowres.num_frames();
    j["lr_vertices"] = problem.num_lr();
    j["hr_vertices"] = problem.num_hr();
    j["fit_ms"] = std::chrono::duration<double, std::milli>(t1 - t0).count();
    j["apply_ms_per_frame"] = out.seconds_per_frame * 1e3;
    if (io::NpzReader(a.frames).contains("highres")) {  // the truth is in the input: report the error
      const auto r = eval::evaluate_predictions(problem.hr.V, out.highres, data::read_frame_set(a.frames, "highres", problem.num_hr()), a.frames);
      j["error"] = statistics_json(r.errors.statistics());
      j["relative_error"] = statistics_json(r.errors.relative_statistics());
    }
  });
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_upsample(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("upsample", "Interpolate LR frames to the HR surface with a baseline (embedded, idw, rbf, mls, ridge)");
  auto a = std::make_shared<UpsampleArgs>();
  cmd->add_option("--method", a->method, "embedded | idw | rbf | mls | ridge | beta_vae")->required();
  cmd->add_option("--lr-rest", a->lr, "LR rest tet mesh (.msh .node/.ele .mesh, or OBJ with 4 triangles per tet)")->required();
  cmd->add_option("--hr-rest", a->hr, "HR rest surface")->required();
  cmd->add_option("--frames", a->frames, ".npz with lowres (F×N×3 absolute); an optional highres is used for errors")->required();
  cmd->add_option("--out", a->out, "output .npz with highres (F×M×3 absolute)")->required();
  cmd->add_option("--neighbors", a->neighbors, "precomputed neighbourhoods (simsr neighbors); computed when absent");
  cmd->add_option("--train", a->train, "ridge, beta_vae: training frames .npz (lowres + highres)");
  a->params.add_options(cmd);
  a->params.add_vae_options(cmd);
  cmd->callback([&action, a] { action = [a] { return upsample(*a); }; });
}

}  // namespace simsr::cli
