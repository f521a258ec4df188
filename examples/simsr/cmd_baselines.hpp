#pragma once
// `simsr baselines --lr-rest L --hr-rest H --frames F.npz --out-dir DIR`: every interpolation
// baseline on held-out frames of one paired data set (the bunny example by default in
// scripts/run.sh). Frames f with f % holdout == 0 are held out; the others train the ridge
// baseline. Writes DIR/statistics.csv (Table 1: raw, relative to the bbox diagonal, normalized to
// the largest), DIR/frame_errors.csv and .svg (Fig. 5), and DIR/heatmaps.pvd (per held-out frame,
// the true HR surface with each method's per-vertex error: open it in ParaView).
//
// Opt-in (not in the default set: training takes minutes): `--methods …,beta_vae` adds the β-VAE
// baseline of appendix A.4 (nn::BetaVae, paper sizes), trained on the same training frames with
// `--vae-epochs E` epochs and `--seed S` (see VaeBaseline below), predicting held-out frames in eval
// mode (z = μ); its row joins the others in every output.
#include <simsr/eval/eval.hpp>
#include <simsr/io/vtu.hpp>
#include <simsr/nn/adam.hpp>
#include <simsr/nn/beta_vae.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cmd_neighbors.hpp"
#include "methods.hpp"

namespace simsr::cli {

/// The β-VAE baseline of appendix A.4 as a `baselines` method: nn::BetaVae<float> (A.4's sizes:
/// 3N→1024→512→2·128, 128→256→1024→4096→3M, β = 0.01) mapping one frame's LR displacements from
/// rest, flattened vertex-major (3N), to its HR displacements (3M).
///
/// Normalization: inputs and targets are both divided by one scalar s, the RMS of every entry of
/// the training frames' LR and HR displacements pooled, and predictions multiplied back by s. Why
/// not the official σ = ½(0.04998 + 0.05092): that constant normalizes bunny *positions*; applied
/// to displacements it leaves them at ≈ 0.13 RMS on the bunny (and at an arbitrary scale on any other
/// data), and since the loss is MSE + β·KL, the target scale sets how much β = 0.01 weighs: at RMS
/// 0.13 the reconstruction term starts ≈ 55 times smaller than at unit RMS, so the KL term weighs
/// ≈ 55 times more (a push towards posterior collapse). Unit-RMS data makes β = 0.01 mean the same
/// thing on every data set. s is a statistic of the training frames only (held-out frames never enter it).
///
/// Training: Adam (lr 1e-4, A.4), batch size 8 (the last batch of an epoch may be smaller),
/// `epochs` epochs, each a fresh Fisher–Yates permutation of the training frames (as
/// nn::Trainer). One nn::Rng seeded with `seed` draws, in order, the initial weights (PyTorch's
/// default init), then per epoch the permutation and per step the reparameterization noise; with
/// BetaVae's policy-independent kernels a seed fixes the run, statistics included. Progress (epoch,
/// loss = recon + β·KL, both terms, seconds) goes to stderr, one line per epoch.
class VaeBaseline {
 public:
  struct Options {
    Index epochs = 4;  // 25–45 s per epoch on the bunny (192 training frames, 2 threads, loaded machine): ≲ 3 min
    Index batch_size = 8;
    double lr = 1e-4;
    double beta = 0.01;
    std::uint64_t seed = 0;
  };

  explicit VaeBaseline(Options o) : opt_(o) {
    if (opt_.epochs < 0) throw ArgumentError("--vae-epochs must be >= 0 (got " + std::to_string(opt_.epochs) + ")");
  }

  /// Trains on `frames` frames of train_lr (frames×N×3) / train_hr (frames×M×3) displacements.
  void train(const std::vector<double>& train_lr, const std::vector<double>& train_hr, Index frames, Index n, Index m) {
    if (frames < 1) throw ArgumentError("beta_vae needs training frames (every frame is held out)");
    n_ = n, m_ = m;
    double sq = 0;
    for (double v : train_lr) sq += v * v;
    for (double v : train_hr) sq += v * v;
    scale_ = std::sqrt(sq / double(train_lr.size() + train_hr.size()));
    if (!std::isfinite(scale_)) throw ArgumentError("beta_vae: the training displacements are not finite");
    if (scale_ == 0) scale_ = 1;  // no motion at all: any scale will do
    const nn::Matrix<float> X = (nn::ConstMatrixMap<double>(train_lr.data(), frames, 3 * n) / scale_).cast<float>();
    const nn::Matrix<float> Y = (nn::ConstMatrixMap<double>(train_hr.data(), frames, 3 * m) / scale_).cast<float>();

    nn::Rng rng(opt_.seed);
    typename nn::BetaVae<float>::Config cfg;
    cfg.beta = opt_.beta;
    vae_.emplace(store_, n, m, rng, cfg);
    nn::Adam<float> adam(store_, {.lr = opt_.lr});
    const Index bs = std::min(opt_.batch_size, frames), nb = (frames + bs - 1) / bs;
    std::fprintf(stderr, "simsr: beta_vae: %lld parameters, %lld training frames, batch %lld, lr %g, beta %g, scale %.6g, seed %llu\n",
                 (long long)vae_->num_parameters(), (long long)frames, (long long)bs, opt_.lr, opt_.beta, scale_,
                 (unsigned long long)opt_.seed);
    std::vector<Index> order(static_cast<std::size_t>(frames));
    nn::Matrix<float> xb, yb;
    const auto t_start = std::chrono::steady_clock::now();
    for (Index e = 0; e < opt_.epochs; ++e) {
      const auto t0 = std::chrono::steady_clock::now();
      for (Index i = 0; i < frames; ++i) order[std::size_t(i)] = i;
      for (Index i = frames - 1; i > 0; --i) std::swap(order[std::size_t(i)], order[std::size_t(uniform_index(rng, i + 1))]);
      double loss = 0, recon = 0, kl = 0;
      for (Index b = 0; b < nb; ++b) {
        const Index first = b * bs, count = std::min(bs, frames - first);
        nn::ensure_shape(xb, count, X.cols());
        nn::ensure_shape(yb, count, Y.cols());
        for (Index i = 0; i < count; ++i) {
          xb.row(i) = X.row(order[std::size_t(first + i)]);
          yb.row(i) = Y.row(order[std::size_t(first + i)]);
        }
        store_.zero_grad();
        const auto l = vae_->loss_and_backward(exec::omp, xb, yb, rng);
        adam.step(exec::omp);
        if (!std::isfinite(l.total)) throw ConvergenceError("beta_vae training", std::int64_t(adam.steps()), l.total);
        loss += l.total / double(nb), recon += l.recon / double(nb), kl += l.kl / double(nb);
      }
      const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fprintf(stderr, "simsr: beta_vae epoch %lld/%lld  loss %.6f (recon %.6f  kl %.4f)  %.2f s\n", (long long)(e + 1),
                   (long long)opt_.epochs, loss, recon, kl, sec);
      last_loss_ = loss, last_recon_ = recon, last_kl_ = kl;
    }
    seconds_per_epoch_ = opt_.epochs > 0 ? std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count() / double(opt_.epochs) : 0;
  }

  /// Eval mode (z = μ): hr (M×3) = s · decoder(μ(lr / s)) for one frame's LR displacements (N×3).
  void apply(const Points<double>& lr, Points<double>& hr) {
    in_ = (nn::ConstMatrixMap<double>(lr.data(), 1, 3 * n_) / scale_).cast<float>();
    vae_->predict(exec::omp, in_, out_);
    hr.resize(m_, 3);
    nn::MatrixMap<double>(hr.data(), 1, 3 * m_) = out_.cast<double>() * scale_;
  }

  nlohmann::ordered_json summary() const {
    return {{"epochs", opt_.epochs}, {"batch_size", opt_.batch_size}, {"lr", opt_.lr},
            {"beta", opt_.beta},     {"seed", opt_.seed},             {"scale", scale_},
            {"parameters", vae_ ? vae_->num_parameters() : 0},       {"seconds_per_epoch", seconds_per_epoch_},
            {"final_loss", last_loss_}, {"final_recon", last_recon_}, {"final_kl", last_kl_}};
  }

 private:
  /// Unbiased integer in [0, n) (rejection on the top of the 64-bit range), as nn::Trainer.
  static Index uniform_index(nn::Rng& rng, Index n) {
    const std::uint64_t un = std::uint64_t(n), limit = UINT64_MAX - UINT64_MAX % un;
    std::uint64_t x;
    do x = rng();
    while (x >= limit);
    return Index(x % un);
  }

  Options opt_;
  Index n_ = 0, m_ = 0;
  double scale_ = 1, seconds_per_epoch_ = 0, last_loss_ = 0, last_recon_ = 0, last_kl_ = 0;
  nn::ParameterStore<float> store_;  // before vae_: it must outlive the model
  std::optional<nn::BetaVae<float>> vae_;
  nn::Matrix<float> in_, out_;
};

struct BaselinesArgs {
  std::string lr, hr, frames, out_dir, neighbors;
  std::vector<std::string> methods{"embedded", "idw", "mls", "rbf", "ridge"};
  Index holdout = 4;
  MethodArgs params;
  VaeBaseline::Options vae;
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

  // One entry per method: an interpolation method, or (beta_vae) the β-VAE.
  struct Method {
    std::optional<AnyMethod> interp;
    std::unique_ptr<VaeBaseline> vae;
  };
  std::vector<Method> methods;
  std::vector<double> fit_ms;
  for (const auto& name : a.methods) {
    Method& method = methods.emplace_back();
    const auto t0 = clock::now();
    if (name == "beta_vae") {
      method.vae = std::make_unique<VaeBaseline>(a.vae);
      method.vae->train(train_lr, train_hr, Index(train.size()), problem.num_lr(), problem.num_hr());
    } else {
      method.interp = make_method(name, a.params);
      if (needs_neighborhoods(*method.interp)) problem.ensure_neighborhoods(a.params.k, exec::omp);
      fit_method(*method.interp, problem, train_lr, train_hr, Index(train.size()));
    }
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
      if (methods[k].vae)
        methods[k].vae->apply(lr_disp, hr_disp);
      else
        apply_method(*methods[k].interp, lr_disp, hr_disp);
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
    if (methods[k].vae) j["methods"][a.methods[k]]["training"] = methods[k].vae->summary();
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
  cmd->add_option("--methods", a->methods,
                  "methods to compare, space- or comma-separated (default: embedded idw mls rbf ridge; opt-in: beta_vae, the A.4 "
                  "beta-VAE, trained here)")
      ->delimiter(',');
  cmd->add_option("--holdout-every", a->holdout, "frames f with f % n == 0 are held out for testing (default 4)");
  a->params.add_options(cmd);
  cmd->add_option("--vae-epochs", a->vae.epochs, "beta_vae: training epochs (default 4, 25-45 s each on the bunny at 2 threads; Adam lr 1e-4, beta 0.01, batch 8)");
  cmd->add_option("--seed", a->vae.seed, "beta_vae: seed of the initial weights, the shuffling and the noise (default 0)");
  cmd->callback([&action, a] { action = [a] { return baselines(*a); }; });
}

}  // namespace simsr::cli
