#pragma once
// `simsr baselines --lr-rest L --hr-rest H --frames F.npz --out-dir DIR`: every interpolation
// baseline on held-out frames of one paired data set (the bunny example by default in
// scripts/run.sh). Frames f with f % holdout == 0 are held out; the others train the ridge
// baseline. Several --frames files (e.g. one per face performance) are read as one set, each
// file's frames a sequence named after it; `--test-sequences anger,fear` then holds those out
// (the paper's protocol: train on some performances, test on others). Writes DIR/statistics.csv (Table 1: raw, relative to the bbox diagonal, normalized to
// the largest), DIR/frame_errors.csv and .svg (Fig. 5), and DIR/heatmaps.pvd (per held-out frame,
// the true HR surface with each method's per-vertex error: open it in ParaView).
//
// Opt-in (not in the default set: training takes minutes): `--methods …,beta_vae` adds the β-VAE
// baseline of appendix A.4 (nn::BetaVae, paper sizes), trained on the same training frames with
// `--vae-epochs E` epochs and `--seed S` (interp::BetaVaeBaseline), predicting held-out frames in eval
// mode (z = μ); its row joins the others in every output.
#include <simsr/data/data.hpp>
#include <simsr/eval/comparison.hpp>
#include <simsr/eval/evaluate.hpp>
#include <simsr/interp/interp.hpp>

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

#include "methods.hpp"

namespace simsr::cli {

struct BaselinesArgs {
  std::string lr, hr, out_dir, neighbors;
  std::vector<std::string> frames, test_sequences;
  std::vector<std::string> methods{"embedded", "idw", "mls", "rbf", "ridge"};
  Index holdout = 4;
  MethodArgs params;
};

/// What the β-VAE's training did (the other methods report none).
inline nlohmann::ordered_json training_json(const interp::BetaVaeBaseline<>& vae, const interp::BetaVaeTrainOptions& o) {
  const auto& h = vae.history();
  return {{"epochs", o.epochs},         {"batch_size", o.batch_size}, {"lr", o.lr}, {"beta", o.network.beta}, {"seed", o.seed}, {"scale", vae.scale()},
          {"parameters", vae.num_parameters()},
          {"final_loss", h.empty() ? 0.0 : h.back().loss}, {"final_recon", h.empty() ? 0.0 : h.back().recon},
          {"final_kl", h.empty() ? 0.0 : h.back().kl}};
}
template <class Method, class... Options>
nlohmann::ordered_json training_json(const Method&, const Options&...) {
  return nullptr;
}

inline int baselines(const BaselinesArgs& a) {
  if (a.holdout < 2) throw ArgumentError("--holdout-every must be at least 2 (got " + std::to_string(a.holdout) + ")");
  interp::UpsamplingProblem<> problem{data::read_lr_rest(a.lr), data::read_hr_rest(a.hr), {}, {}};
  if (!a.neighbors.empty()) problem.neighborhoods = neighbors::load_upsampling_neighborhoods(a.neighbors);
  data::PairedFrames<> frames;
  if (a.frames.size() == 1) {
    frames = data::read_paired_frames(a.frames[0], problem.num_lr(), problem.num_hr());
  } else {  // one sequence per file (its own label if it has one); controls dropped: their columns may differ
    std::vector<data::PairedFrames<>> parts;
    std::vector<std::string> names;
    for (const auto& f : a.frames) {
      parts.push_back(data::read_paired_frames(f, problem.num_lr(), problem.num_hr()));
      names.push_back(std::filesystem::path(f).stem().string());
    }
    frames = data::concatenate(std::span<const data::PairedFrames<>>(parts), std::span<const std::string>(names), data::FrameIds::renumber,
                               data::FrameControls::drop);
  }
  const auto split = a.test_sequences.empty() ? data::holdout_every(frames.num_frames(), a.holdout)
                                              : data::by_sequence(frames, std::span<const std::string>(a.test_sequences));
  const auto train = frames.select(split.train), test = frames.select(split.test);

  eval::MethodComparison table(problem.hr.V, problem.hr.F, test);
  nlohmann::ordered_json j;
  j["frames"] = frames.num_frames();
  j["train_frames"] = train.num_frames();
  j["test_frames"] = test.num_frames();
  if (!a.test_sequences.empty()) j["test_sequences"] = a.test_sequences;
  j["bbox_diagonal"] = table.diagonal();
  for (const auto& name : a.methods) {
    with_method(name, a.params, [&](auto& method, const auto&... train_options) {
      const auto t0 = std::chrono::steady_clock::now();
      if constexpr (sizeof...(train_options) > 0)
        interp::prepare(exec::omp, method, problem, train, train_options..., a.params.k);
      else
        interp::prepare(exec::omp, method, problem, a.params.k);
      const double fit_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      eval::Evaluation r = eval::evaluate(exec::omp, method, problem.lr.V, problem.hr.V, test);
      const auto rel = r.errors.relative_statistics();
      auto& m = j["methods"][name];
      m = {{"relative_mean", rel.mean}, {"relative_median", rel.median}, {"relative_std", rel.std},
           {"relative_max", rel.max},   {"fit_ms", fit_ms},              {"apply_ms_per_frame", r.seconds_per_frame * 1e3}};
      if (auto t = training_json(method, train_options...); !t.is_null()) m["training"] = t;
      std::fprintf(stderr, "simsr: %-9s fit %9.1f ms, held-out mean error / diagonal %.4e\n", name.c_str(), fit_ms, rel.mean);
      table.add(name, std::move(r));
    });
  }
  table.write(a.out_dir);
  std::cerr << "simsr: wrote " << (std::filesystem::path(a.out_dir) / "statistics.csv").string() << ", frame_errors.csv/.svg, heatmaps.pvd\n";
  std::cout << j.dump() << '\n';
  return 0;
}

inline void add_baselines(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("baselines", "Every interpolation baseline on held-out frames: statistics, frame-wise errors, heatmaps");
  auto a = std::make_shared<BaselinesArgs>();
  cmd->add_option("--lr-rest", a->lr, "LR rest tet mesh")->required();
  cmd->add_option("--hr-rest", a->hr, "HR rest surface")->required();
  cmd->add_option("--frames", a->frames,
                  ".npz with lowres (F×N×3) and highres (F×M×3) absolute positions; several (space- or comma-separated) are one set, "
                  "one sequence per file")
      ->required()
      ->delimiter(',');
  cmd->add_option("--out-dir", a->out_dir, "folder for statistics.csv, frame_errors.csv/.svg, heatmaps.pvd")->required();
  cmd->add_option("--neighbors", a->neighbors, "precomputed neighbourhoods (simsr neighbors)");
  cmd->add_option("--methods", a->methods,
                  "methods to compare, space- or comma-separated (default: embedded idw mls rbf ridge; opt-in: beta_vae, the A.4 "
                  "beta-VAE, trained here)")
      ->delimiter(',');
  auto* every = cmd->add_option("--holdout-every", a->holdout, "frames f with f % n == 0 are held out for testing (default 4)");
  cmd->add_option("--test-sequences", a->test_sequences, "hold out these sequences (e.g. anger,fear: performances never trained on) instead")
      ->delimiter(',')
      ->excludes(every);
  a->params.add_options(cmd);
  a->params.add_vae_options(cmd);
  cmd->callback([&action, a] { action = [a] { return baselines(*a); }; });
}

}  // namespace simsr::cli
