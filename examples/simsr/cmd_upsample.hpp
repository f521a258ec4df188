#pragma once
// `simsr upsample --method embedded|idw|rbf|mls|ridge --lr-rest L --hr-rest H --frames IN.npz --out OUT.npz`
// IN holds `lowres` (F×N×3 absolute LR positions); OUT gets `highres` (F×M×3 absolute HR
// positions, the HR rest plus the interpolated displacement). stdout: one JSON line with the
// timings and, when IN also holds `highres` of the right shape (as the bunny's train_frames.npz
// does), the error statistics of the prediction against it.
#include <simsr/eval/error_statistics.hpp>
#include <simsr/interp/interp.hpp>
#include <simsr/io/npz.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cmd_neighbors.hpp"
#include "methods.hpp"

namespace simsr::cli {

struct UpsampleArgs {
  std::string method, lr, hr, frames, out, neighbors, train;
  MethodArgs params;
};

inline int upsample(const UpsampleArgs& a) {
  using clock = std::chrono::steady_clock;
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  AnyMethod method = make_method(a.method, a.params);
  interp::UpsamplingProblem<double> problem{read_lr_rest(a.lr), read_hr_rest(a.hr), std::nullopt};
  if (!a.neighbors.empty()) problem.neighborhoods = neighbors::load_upsampling_neighborhoods(a.neighbors);
  io::NpzReader z(a.frames);
  const io::NpyArray lowres = read_frames(z, a.frames, "lowres", problem.num_lr());
  const Index frames = lowres.num_frames(), m = problem.num_hr();

  std::vector<double> train_lr, train_hr;
  Index train_frames = 0;
  if (!a.train.empty()) {  // training frames (ridge): lowres + highres of the same layout
    io::NpzReader t(a.train);
    const auto tl = read_frames(t, a.train, "lowres", problem.num_lr()), th = read_frames(t, a.train, "highres", m);
    if (tl.num_frames() != th.num_frames()) throw ShapeError(a.train + ": highres frames", {tl.num_frames(), m, 3}, th.shape);
    std::vector<Index> all(static_cast<std::size_t>(tl.num_frames()));
    for (Index f = 0; f < tl.num_frames(); ++f) all[std::size_t(f)] = f;
    train_lr = frame_displacements(tl, all, problem.lr.V);
    train_hr = frame_displacements(th, all, problem.hr.V);
    train_frames = tl.num_frames();
  }

  const auto t0 = clock::now();
  if (needs_neighborhoods(method)) problem.ensure_neighborhoods(a.params.k, exec::omp);
  const auto t1 = clock::now();
  fit_method(method, problem, train_lr, train_hr, train_frames);
  const auto t2 = clock::now();

  std::vector<double> out(static_cast<std::size_t>(frames * m * 3));
  Points<double> lr_disp(problem.num_lr(), 3), hr_disp(m, 3);
  double apply_ms = 0;
  for (Index f = 0; f < frames; ++f) {
    lr_disp = lowres.frame_points<double>(f) - problem.lr.V;
    const auto s = clock::now();
    apply_method(method, lr_disp, hr_disp);
    apply_ms += ms(clock::now() - s);
    Eigen::Map<Points<double>>(out.data() + f * m * 3, m, 3) = problem.hr.V + hr_disp;
  }
  io::NpzArrays result;
  result["highres"] = io::make_npy<double>({frames, m, 3}, out.data());
  io::write_npz(a.out, result, io::NpzCompression::Deflate);

  nlohmann::ordered_json j;
  j["method"] = a.method;
  j["frames"] = frames;
  j["lr_vertices"] = problem.num_lr();
  j["hr_vertices"] = m;
  j["neighborhoods_ms"] = ms(t1 - t0);
  j["fit_ms"] = ms(t2 - t1);
  j["apply_ms_per_frame"] = frames ? apply_ms / double(frames) : 0.0;
  if (z.contains("highres")) {
    const io::NpyArray truth = read_frames(z, a.frames, "highres", m);
    if (truth.num_frames() != frames) throw ShapeError(a.frames + ": highres frames", {frames, m, 3}, truth.shape);
    eval::ErrorAccumulator acc(problem.hr.V);
    for (Index f = 0; f < frames; ++f)
      acc.add_frame(Eigen::Map<const Points<double>>(out.data() + f * m * 3, m, 3), truth.frame_points<double>(f));
    const auto s = acc.statistics(), r = acc.relative_statistics();
    j["error"] = statistics_json(s);
    j["relative_error"] = statistics_json(r);
  }
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_upsample(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("upsample", "Interpolate LR frames to the HR surface with a baseline (embedded, idw, rbf, mls, ridge)");
  auto a = std::make_shared<UpsampleArgs>();
  cmd->add_option("--method", a->method, "embedded | idw | rbf | mls | ridge")->required();
  cmd->add_option("--lr-rest", a->lr, "LR rest tet mesh (.msh .node/.ele .mesh, or OBJ with 4 triangles per tet)")->required();
  cmd->add_option("--hr-rest", a->hr, "HR rest surface")->required();
  cmd->add_option("--frames", a->frames, ".npz with lowres (F×N×3 absolute); an optional highres is used for errors")->required();
  cmd->add_option("--out", a->out, "output .npz with highres (F×M×3 absolute)")->required();
  cmd->add_option("--neighbors", a->neighbors, "precomputed neighbourhoods (simsr neighbors); computed when absent");
  cmd->add_option("--train", a->train, "ridge: training frames .npz (lowres + highres)");
  a->params.add_options(cmd);
  cmd->callback([&action, a] { action = [a] { return upsample(*a); }; });
}

}  // namespace simsr::cli
