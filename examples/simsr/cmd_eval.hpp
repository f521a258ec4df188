#pragma once
// `simsr eval --pred OUT.npz --truth TRUTH.npz --hr-rest H.obj [--frames-key highres] [--out DIR]`:
// Table-1 statistics (SPEC §8) of the per-vertex Euclidean error between predicted and true HR
// positions. Both files hold `highres` (or --frames-key): F×M×3 absolute positions, float32 or
// float64, M the vertex count of the HR rest surface. When both files also hold a `frame` array
// (F ids, as `simsr upsample`'s inputs do), predicted frames are matched to true ones by id and
// the truth may hold more frames (e.g. the whole performance against a held-out subset);
// otherwise the frame counts must match and frames pair up by index. stdout: one JSON object with
// the mean, median, std, max, min of the error, raw and relative to the bounding-box diagonal of
// the HR rest surface. --out DIR also writes frame_errors.csv/.svg (per-frame mean and max, Fig. 5),
// error_heatmap.vtu (the HR rest surface with the per-vertex mean and max error over frames: open
// it in ParaView) and statistics.csv.
#include <simsr/data/frame_set.hpp>
#include <simsr/data/rest_shapes.hpp>
#include <simsr/eval/comparison.hpp>
#include <simsr/eval/evaluate.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "methods.hpp"

namespace simsr::cli {

struct EvalArgs {
  std::string pred, truth, hr, key = "highres", out_dir;
};

inline int eval_cmd(const EvalArgs& a) {
  const TriMesh<> rest = data::read_hr_rest(a.hr);
  const data::FrameSet pred = data::read_frame_set(a.pred, a.key, rest.num_vertices());
  const data::FrameSet truth = data::read_frame_set(a.truth, a.key, rest.num_vertices());
  if (pred.num_frames() == 0) throw ShapeError(a.pred + ": " + a.key + " has no frames", {-1, rest.num_vertices(), 3}, {0, rest.num_vertices(), 3});
  const eval::Evaluation r = eval::evaluate_predictions(rest.V, pred, truth, a.truth);
  const auto stats = r.errors.statistics();
  nlohmann::ordered_json j;
  j["frames"] = pred.num_frames();
  j["vertices"] = rest.num_vertices();
  j["bbox_diagonal"] = r.errors.diagonal();
  j["error"] = statistics_json(stats);
  j["relative_error"] = statistics_json(stats.scaled(r.errors.diagonal()));
  if (!a.out_dir.empty()) {
    eval::write_evaluation(a.out_dir, std::filesystem::path(a.pred).stem().string(), r, rest, pred.ids);
    j["out_dir"] = a.out_dir;
    std::cerr << "simsr: wrote " << (std::filesystem::path(a.out_dir) / "statistics.csv").string() << ", frame_errors.csv/.svg, error_heatmap.vtu\n";
  }
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_eval(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("eval", "Error statistics of predicted HR frames against the true ones (Table 1), plots and a heatmap");
  auto a = std::make_shared<EvalArgs>();
  cmd->add_option("--pred", a->pred, ".npz with the predicted frames (F×M×3 absolute positions)")->required();
  cmd->add_option("--truth", a->truth, ".npz with the true frames; more frames than --pred only if both have `frame` ids")->required();
  cmd->add_option("--hr-rest", a->hr, "HR rest surface (vertex order of the frames; its bbox diagonal is the relative unit)")->required();
  cmd->add_option("--frames-key", a->key, "array holding the frames in both files (default highres)");
  cmd->add_option("--out", a->out_dir, "folder for frame_errors.csv/.svg, error_heatmap.vtu, statistics.csv");
  cmd->callback([&action, a] { action = [a] { return eval_cmd(*a); }; });
}

}  // namespace simsr::cli
