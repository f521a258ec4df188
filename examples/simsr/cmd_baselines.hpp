#pragma once
// `simsr baselines --lr-rest L --hr-rest H --frames F.npz --out-dir DIR`: every interpolation
// baseline on held-out frames of one paired data set (the bunny example by default in
// scripts/run.sh). Frames f with f % holdout == 0 are held out; the others train the ridge
// baseline. Writes DIR/statistics.csv (Table 1: raw, relative to the bbox diagonal, normalized to
// the largest), DIR/frame_errors.csv and .svg (Fig. 5), and DIR/heatmaps.pvd (per held-out frame,
// the true HR surface with each method's per-vertex error: open it in ParaView).
#include <simsr/eval/eval.hpp>
#include <simsr/io/vtu.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cmd_neighbors.hpp"
#include "methods.hpp"

namespace simsr::cli {

struct BaselinesArgs {
  std::string lr, hr, frames, out_dir, neighbors;
  std::vector<std::string> methods{"embedded", "idw", "mls", "rbf", "ridge"};
  Index holdout = 4;
  MethodArgs params;
};

inline int baselines(const BaselinesArgs& a) {
  using clock = std::chrono::steady_clock;
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  if (a.holdout < 2) throw ArgumentError("--holdout-every must be at least 2 (got " + std::to_string(a.holdout) + ")");
  const std::filesystem::path dir(a.out_dir);
  std::filesystem::create_directories(dir);

  interp::UpsamplingProblem<double> problem{read_lr_rest(a.lr), read_hr_rest(a.hr), std::nullopt};
  if (!a.neighbors.empty()) problem.neighborhoods = neighbors::load_upsampling_neighborhoods(a.neighbors);
  io::NpzReader z(a.frames);
  const auto low = read_frames(z, a.frames, "lowres", problem.num_lr());
  const auto high = read_frames(z, a.frames, "highres", problem.num_hr());
  if (low.num_frames() != high.num_frames()) throw ShapeError(a.frames + ": highres frames", {low.num_frames(), problem.num_hr(), 3}, high.shape);
  std::vector<Index> train, test;
  for (Index f = 0; f < low.num_frames(); ++f) (f % a.holdout == 0 ? test : train).push_back(f);
  const auto train_lr = frame_displacements(low, train, problem.lr.V);
  const auto train_hr = frame_displacements(high, train, problem.hr.V);

  std::vector<AnyMethod> methods;
  std::vector<double> fit_ms;
  for (const auto& name : a.methods) {
    methods.push_back(make_method(name, a.params));
    const auto t0 = clock::now();
    if (needs_neighborhoods(methods.back())) problem.ensure_neighborhoods(a.params.k, exec::omp);
    fit_method(methods.back(), problem, train_lr, train_hr, Index(train.size()));
    fit_ms.push_back(ms(clock::now() - t0));
    std::fprintf(stderr, "simsr: fitted %-9s %9.1f ms\n", name.c_str(), fit_ms.back());
  }

  const Index m = problem.num_hr();
  std::vector<eval::ErrorAccumulator> acc(methods.size(), eval::ErrorAccumulator(problem.hr.V));
  std::vector<double> apply_ms(methods.size(), 0.0);
  io::PvdWriter heatmaps(dir / "heatmaps.pvd");
  Points<double> lr_disp(problem.num_lr(), 3), hr_disp(m, 3);
  for (std::size_t t = 0; t < test.size(); ++t) {
    const Index f = test[t];
    lr_disp = low.frame_points<double>(f) - problem.lr.V;
    const Points<double> truth = high.frame_points<double>(f);
    io::VtuGrid grid;
    grid.set_points(truth).set_triangles(problem.hr.F);
    for (std::size_t k = 0; k < methods.size(); ++k) {
      const auto s = clock::now();
      apply_method(methods[k], lr_disp, hr_disp);
      apply_ms[k] += ms(clock::now() - s);
      acc[k].add_frame(problem.hr.V + hr_disp, truth);
      grid.add_point_data("error_" + a.methods[k], acc[k].last_frame_errors());
    }
    heatmaps.add(double(f), grid);
    if ((t + 1) % 16 == 0 || t + 1 == test.size()) std::fprintf(stderr, "simsr: held-out frames %zu/%zu\n", t + 1, test.size());
  }

  std::vector<eval::ErrorStatistics> stats;
  std::vector<eval::Series> series;
  for (std::size_t k = 0; k < methods.size(); ++k) {
    stats.push_back(acc[k].statistics());
    eval::Series s{a.methods[k], acc[k].frame_means()};
    for (double& v : s.values) v /= acc[k].diagonal();
    series.push_back(std::move(s));
  }
  const double diagonal = acc.front().diagonal();
  eval::write_statistics_csv(dir / "statistics.csv", a.methods, stats, diagonal);
  std::vector<long long> ids(test.begin(), test.end());
  eval::write_frame_csv(dir / "frame_errors.csv", series, ids);
  eval::write_svg_plot(dir / "frame_errors.svg", series, "Mean per-vertex error on held-out frames (log scale)",
                       "mean error / bbox diagonal", true, "held-out frame (index)");

  const auto norm = eval::normalized_to_largest(stats);
  std::ostringstream table;
  table << "method     mean/diag   median/diag  max/diag    norm.mean  fit ms     apply ms/frame\n";
  nlohmann::ordered_json j;
  j["frames"] = low.num_frames();
  j["train_frames"] = train.size();
  j["test_frames"] = test.size();
  j["bbox_diagonal"] = diagonal;
  for (std::size_t k = 0; k < methods.size(); ++k) {
    const auto r = stats[k].scaled(diagonal);
    char line[256];
    std::snprintf(line, sizeof line, "%-10s %-11.4e %-12.4e %-11.4e %-10.4f %-10.1f %.3f\n", a.methods[k].c_str(), r.mean, r.median,
                  r.max, norm[k].mean, fit_ms[k], apply_ms[k] / double(test.size()));
    table << line;
    j["methods"][a.methods[k]] = {{"relative_mean", r.mean}, {"relative_median", r.median}, {"relative_std", r.std},
                                  {"relative_max", r.max},   {"fit_ms", fit_ms[k]},       {"apply_ms_per_frame", apply_ms[k] / double(test.size())}};
  }
  std::cerr << table.str();
  std::cerr << "simsr: wrote " << (dir / "statistics.csv").string() << ", frame_errors.csv/.svg, heatmaps.pvd\n";
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_baselines(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("baselines", "Every interpolation baseline on held-out frames: statistics, frame-wise errors, heatmaps");
  auto a = std::make_shared<BaselinesArgs>();
  cmd->add_option("--lr-rest", a->lr, "LR rest tet mesh")->required();
  cmd->add_option("--hr-rest", a->hr, "HR rest surface")->required();
  cmd->add_option("--frames", a->frames, ".npz with lowres (F×N×3) and highres (F×M×3) absolute positions")->required();
  cmd->add_option("--out-dir", a->out_dir, "folder for statistics.csv, frame_errors.csv/.svg, heatmaps.pvd")->required();
  cmd->add_option("--neighbors", a->neighbors, "precomputed neighbourhoods (simsr neighbors)");
  cmd->add_option("--methods", a->methods, "methods to compare (default: embedded idw mls rbf ridge)");
  cmd->add_option("--holdout-every", a->holdout, "frames f with f % n == 0 are held out for testing (default 4)");
  a->params.add_options(cmd);
  cmd->callback([&action, a] { action = [a] { return baselines(*a); }; });
}

}  // namespace simsr::cli
