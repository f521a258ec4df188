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
#include <simsr/eval/eval.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/io/vtu.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cmd_neighbors.hpp"
#include "methods.hpp"

namespace simsr::cli {

struct EvalArgs {
  std::string pred, truth, hr, key = "highres", out_dir;
};

namespace detail {

/// The F×M×3 positions array `key` of an .npz: float32 or float64, M = `vertices`.
inline io::NpyArray read_eval_frames(io::NpzReader& z, const std::string& file, const std::string& key, Index vertices) {
  io::NpyArray a = read_frames(z, file, key, vertices);
  if (a.dtype.kind != io::NpyKind::Float || (a.dtype.itemsize != 4 && a.dtype.itemsize != 8))
    throw ArgumentError(file + ": " + key + " has dtype " + a.dtype.name() + ", expected float32 or float64");
  return a;
}

/// The `frame` ids of an .npz holding `frames` frames, or empty when it has none.
inline std::vector<std::int64_t> read_frame_ids(io::NpzReader& z, const std::string& file, Index frames) {
  if (!z.contains("frame")) return {};
  const io::NpyArray a = z.read("frame");
  if (a.dtype.kind != io::NpyKind::Int && a.dtype.kind != io::NpyKind::UInt)
    throw ArgumentError(file + ": frame has dtype " + a.dtype.name() + ", expected integer frame ids");
  if (a.ndim() != 1 || a.shape[0] != frames) throw ShapeError(file + ": frame (one id per frame)", {frames}, a.shape);
  return a.to_vector<std::int64_t>();
}

/// Throws ArgumentError naming file, frame and vertex at the first NaN/Inf coordinate.
inline void require_finite(const Points<double>& p, const std::string& file, const std::string& key, Index f,
                           const std::vector<std::int64_t>& ids) {
  if (p.allFinite()) return;
  for (Index v = 0; v < p.rows(); ++v)
    if (!p.row(v).allFinite()) {
      std::string frame = "frame " + std::to_string(f);
      if (!ids.empty()) frame += " (id " + std::to_string(ids[std::size_t(f)]) + ")";
      throw ArgumentError(file + ": " + key + " " + frame + ", vertex " + std::to_string(v) + " is not finite (" +
                          std::to_string(p(v, 0)) + ", " + std::to_string(p(v, 1)) + ", " + std::to_string(p(v, 2)) + ")");
    }
}

}  // namespace detail

inline int eval_cmd(const EvalArgs& a) {
  const TriMesh<double> rest = read_hr_rest(a.hr);
  const Index m = rest.V.rows();
  io::NpzReader zp(a.pred), zt(a.truth);
  const io::NpyArray pred = detail::read_eval_frames(zp, a.pred, a.key, m);
  const io::NpyArray truth = detail::read_eval_frames(zt, a.truth, a.key, m);
  const Index frames = pred.num_frames();
  if (frames == 0) throw ShapeError(a.pred + ": " + a.key + " has no frames", {-1, m, 3}, pred.shape);

  // Frame pairing: by `frame` id when both files have one, else by index with equal counts.
  const auto pred_ids = detail::read_frame_ids(zp, a.pred, frames);
  const auto truth_ids = detail::read_frame_ids(zt, a.truth, truth.num_frames());
  std::vector<Index> truth_of(static_cast<std::size_t>(frames));
  if (!pred_ids.empty() && !truth_ids.empty()) {
    std::map<std::int64_t, Index> where;
    for (Index f = 0; f < Index(truth_ids.size()); ++f)
      if (!where.emplace(truth_ids[std::size_t(f)], f).second)
        throw ArgumentError(a.truth + ": frame id " + std::to_string(truth_ids[std::size_t(f)]) + " appears twice");
    for (Index f = 0; f < frames; ++f) {
      const auto it = where.find(pred_ids[std::size_t(f)]);
      if (it == where.end())
        throw ShapeError(a.truth + ": no frame with id " + std::to_string(pred_ids[std::size_t(f)]) + " (frame " + std::to_string(f) +
                             " of " + a.pred + "); " + a.key + " of the truth",
                         pred.shape, truth.shape);
      truth_of[std::size_t(f)] = it->second;
    }
  } else {
    if (truth.num_frames() != frames)
      throw ShapeError(a.truth + ": " + a.key + " frames vs " + a.pred +
                           " (unequal frame counts need a `frame` id array in both files)",
                       pred.shape, truth.shape);
    for (Index f = 0; f < frames; ++f) truth_of[std::size_t(f)] = f;
  }

  eval::ErrorAccumulator acc(rest.V);
  VecX<double> vertex_mean = VecX<double>::Zero(m), vertex_max = VecX<double>::Zero(m);
  std::vector<long long> ids;
  for (Index f = 0; f < frames; ++f) {
    const Index g = truth_of[std::size_t(f)];
    const Points<double> p = pred.frame_points<double>(f), t = truth.frame_points<double>(g);
    detail::require_finite(p, a.pred, a.key, f, pred_ids);
    detail::require_finite(t, a.truth, a.key, g, truth_ids);
    acc.add_frame(p, t);
    vertex_mean += acc.last_frame_errors();
    vertex_max = vertex_max.cwiseMax(acc.last_frame_errors());
    ids.push_back(pred_ids.empty() ? f : pred_ids[std::size_t(f)]);
  }
  vertex_mean /= double(frames);
  const auto stats = acc.statistics();
  const double diagonal = acc.diagonal();

  nlohmann::ordered_json j;
  j["frames"] = frames;
  j["vertices"] = m;
  j["bbox_diagonal"] = diagonal;
  j["error"] = statistics_json(stats);
  j["relative_error"] = statistics_json(stats.scaled(diagonal));

  if (!a.out_dir.empty()) {
    const std::filesystem::path dir(a.out_dir);
    std::filesystem::create_directories(dir);
    std::vector<double> rel_means = acc.frame_means(), rel_maxes = acc.frame_maxes();
    for (double& v : rel_means) v /= diagonal;
    for (double& v : rel_maxes) v /= diagonal;
    eval::write_frame_csv(dir / "frame_errors.csv",
                          {{"mean", acc.frame_means()}, {"max", acc.frame_maxes()}, {"relative_mean", rel_means}, {"relative_max", rel_maxes}},
                          ids);
    eval::write_svg_plot(dir / "frame_errors.svg", {{"mean", rel_means}, {"max", rel_maxes}},
                         "Per-vertex error of " + std::filesystem::path(a.pred).filename().string() + " per frame",
                         "error / bbox diagonal", false, "frame (index)");
    io::VtuGrid grid(rest);
    grid.add_point_data("mean_error", vertex_mean).add_point_data("max_error", vertex_max);
    grid.add_point_data("relative_mean_error", (vertex_mean / diagonal).eval());
    io::write_vtu(dir / "error_heatmap.vtu", grid);
    eval::write_statistics_csv(dir / "statistics.csv", {std::filesystem::path(a.pred).stem().string()}, {stats}, diagonal);
    j["out_dir"] = dir.string();
    std::cerr << "simsr: wrote " << (dir / "statistics.csv").string() << ", frame_errors.csv/.svg, error_heatmap.vtu\n";
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
