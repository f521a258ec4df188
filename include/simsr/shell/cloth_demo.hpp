#pragma once
/// \file
/// `simsr demo --dataset sheet|disk` as a library call: the thin-shell paper's evaluation end to
/// end. The coarse/fine data (cloth_datagen.hpp; a rerun reuses finished sequences, a killed one
/// resumes), the TS-ACAP features, the network trained on the training sequences (a checkpoint
/// per epoch: a killed run resumes), and the held-out sequences synthesized from their coarse
/// frames only and compared with the fine simulation. Files:
///   OUT/data/                     the dataset (cloth_data.json, <scene>_NNN.npz, rest meshes)
///   OUT/network/model.npz         the trained network (DetailSynthesisNet::save)
///   OUT/network/train.npz         the training checkpoint
///   OUT/network/upsampling_network.npz  the core paper's network's checkpoint (the "network" baseline)
///   OUT/results/frame_errors.csv  per held-out frame: RMS distance of subdivided / synthesized / refined
///                                 and of each baseline (a column `<method>_m`)
///   OUT/results/<seq>_errors.svg  the same per held-out sequence as a plot (any browser)
///   OUT/results/compare/<seq>_<f>/  lr_input.vtu (coarse), subdivided / synthesized / refined.vtu
///                                 with their per-vertex `error` (m), truth.vtu: each held-out
///                                 sequence's frame where subdivision errs most (ParaView;
///                                 scripts/render_comparison.py --view oblique draws the panel)
///   OUT/report.json               the RMSE table (with the core paper's upsampling methods beside:
///                                 cloth_upsampling.hpp), the Table 1 timings, the training history

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "../eval/report.hpp"
#include "../io/atomic_file.hpp"
#include "../io/vtu.hpp"
#include "../interp/learned.hpp"
#include "../interp/local_linear.hpp"
#include "../interp/network_recipe.hpp"
#include "cloth_datagen.hpp"
#include "cloth_synthesis.hpp"
#include "cloth_upsampling.hpp"

namespace simsr::shell {

struct ClothDemoOptions {
  ClothDataset scene = ClothDataset::sheet;
  std::filesystem::path out = "out/sheet";
  ClothDatagenOptions data;            ///< sequences, sizes, seed of the scene
  DetailSynthesisOptions network;      ///< the supplement's sizes by default
  ClothTrainingOptions training;       ///< epochs, batch, seed (the checkpoint is OUT/network/train.npz)
  std::uint64_t network_seed = 1;      ///< the initial weights
  /// The core paper's upsampling methods evaluated beside (cloth_upsampling.hpp): "local_linear"
  /// (interp::LocalLinear, λ by leave-one-sequence-out) and "network" (interp::Learned, the face
  /// demo's recipe: residual over the local-linear map, displacements scaled to unit RMS).
  std::vector<std::string> baselines = {"local_linear", "network"};
  /// Their §3.2 upsampling neighbours per fine vertex; 0: 20, or every coarse vertex when the
  /// cloth has fewer (a reduced scene); a k above the coarse vertex count is an ArgumentError.
  Index baseline_k = 0;
  interp::NetworkRecipe baseline_network = [] {
    interp::NetworkRecipe r;
    r.epochs = 8;
    r.lr_decay_epochs = 10;  // as measured (never within 8 epochs; the finished stages' fingerprints kept)
    r.residual_base = "local_linear";
    return r;
  }();
};

/// ArgumentError unless every name is a baseline run_cloth_demo knows.
inline void check_cloth_baselines(const std::vector<std::string>& names) {
  for (const auto& b : names)
    if (b != "local_linear" && b != "network") throw ArgumentError("cloth demo: unknown baseline '" + b + "' (local_linear, network)");
}

/// The demo's baselines (o.baselines) on the held-out sequences: the problem and the training
/// frames built once for all of them; the network checkpointed in `net_dir` and resumed.
template <exec::HostPolicy P>
std::vector<ClothUpsamplingEvaluation> run_cloth_baselines(P policy, const ClothDemoOptions& o, const ClothData& data,
                                                           const std::filesystem::path& net_dir, const std::function<void(const std::string&)>& tell) {
  std::vector<ClothUpsamplingEvaluation> out;
  if (o.baselines.empty()) return out;
  const Index k = o.baseline_k > 0 ? o.baseline_k : std::min<Index>(20, data.num_coarse());
  tell("baselines: the core paper's upsampling neighbourhoods (k = " + std::to_string(k) + ")");
  interp::UpsamplingProblem<> problem = cloth_upsampling_problem(policy, data, k);
  const data::PairedFrames<> train = cloth_paired_frames(data, false);
  for (const auto& name : o.baselines) {
    tell("baselines: " + name);
    if (name == "local_linear") {
      interp::LocalLinear<> m({.k = k});
      out.push_back(evaluate_upsampling(policy, data, problem, train, m, name));
      continue;
    }
    // the network: its interpolation neighbours the recipe's (else the preset's: official 10,
    // paper 20), at most the k computed; its displacement scale from the training frames
    interp::NetworkRecipe recipe = o.baseline_network;
    if (recipe.up_k <= 0) recipe.up_k = std::min<Index>(nn::NetworkConfig::preset(recipe.profile).up_k, k);
    nn::NetworkConfig cfg = recipe.config(data::displacements(train, problem.lr.V, problem.hr.V));
    cfg.residual_base_k = k;
    interp::Learned<> net(cfg, recipe.seed);
    interp::NetworkTrainOptions to;
    to.trainer.seed = recipe.seed;
    to.trainer.lr_decay_epochs = recipe.lr_decay_epochs;
    to.trainer.progress = false;
    to.trainer.on_epoch = [&](const nn::EpochReport& r) {
      tell("baselines: network epoch " + std::to_string(r.epoch) + "/" + std::to_string(cfg.epochs) + " loss " + std::to_string(r.loss));
    };
    to.checkpoint = net_dir / "upsampling_network.npz";
    if (std::filesystem::exists(to.checkpoint)) to.resume = to.checkpoint;  // refused, naming what differs, when of another run
    out.push_back(evaluate_upsampling(policy, data, problem, train, net, "upsampling_network", to));
  }
  return out;
}

/// Runs the demo (see the file comment); `say` receives progress lines. Returns OUT/report.json.
/// Linear is the data's Newton linear solver (generate_cloth_data: CholmodCholesky where built
/// with CHOLMOD is ~3× faster at the paper's sizes; the data is the same to round-off).
template <class Linear = physics::SparseCholesky<>, exec::HostPolicy P>
nlohmann::ordered_json run_cloth_demo(P policy, const ClothDemoOptions& o, const std::function<void(const std::string&)>& say = {}) {
  auto tell = [&](const std::string& s) {
    if (say) say(s);
  };
  check_cloth_baselines(o.baselines);
  const auto data_dir = o.out / "data", net_dir = o.out / "network", results = o.out / "results";
  std::filesystem::create_directories(net_dir);
  std::filesystem::create_directories(results);

  ClothDatagenOptions gen = o.data;
  // a progress line every 20th frame of each sequence and of the settling before them
  auto progress = [&](const ClothDatagenOptions::FrameCallback& user) {
    return [&, user](const std::string& s, Index f, Index F, const ClothFrameReport& c, const ClothFrameReport& fi, double sc, double sf) {
      if (user) user(s, f, F, c, fi, sc, sf);
      if ((f + 1) % 20 == 0 || f + 1 == F) {
        char buf[240];
        std::snprintf(buf, sizeof buf, "data: %s frame %lld/%lld (this frame: coarse %.3f s, fine %.3f s, %lld Newton iterations, %lld steps halved)",
                      s.c_str(), (long long)(f + 1), (long long)F, sc, sf, (long long)fi.newton_iterations, (long long)fi.halvings);
        tell(buf);
      }
    };
  };
  gen.on_frame = progress(gen.on_frame);
  gen.on_settle_frame = progress(gen.on_settle_frame);
  tell("data: " + data_dir.string());
  generate_cloth_data<Linear>(policy, o.scene, data_dir, gen);
  const ClothData data = read_cloth_data(data_dir);

  tell("features: TS-ACAP of every frame (coarse " + std::to_string(data.num_coarse()) + ", fine " + std::to_string(data.num_fine()) +
       " vertices)");
  ClothSynthesis<Linear> run(policy, data, o.network, o.network_seed,
                             [&](const std::string& s, Index done, Index total) { tell("features: " + s + " (" + std::to_string(done) + "/" + std::to_string(total) + ")"); });
  run.on_epoch = [&](const ClothEpochReport& r) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "train: epoch %lld/%lld lr %.1e loss synthesis %.4f reconstruction %.4f latent %.4f (%.1f s)", (long long)r.epoch,
                  (long long)r.epochs, r.lr, r.loss.synthesis, r.loss.reconstruction, r.loss.latent, r.seconds);
    tell(buf);
  };
  ClothTrainingOptions t = o.training;
  t.checkpoint = net_dir / "train.npz";
  const std::vector<ClothEpochReport> history = run.train(policy, t);
  run.network().save(net_dir / "model.npz");

  tell("evaluate: the held-out sequences from their coarse frames");
  // Fig.-6-style views of each held-out sequence's frame where the subdivided mesh errs most,
  // written from the frames the evaluation synthesized
  const ClothEvaluation e = run.evaluate(policy, [&](Index q, const std::vector<Points<>>& raw, const std::vector<Points<>>& refined,
                                                     const ClothSequenceEvaluation& ev) {
    const ClothSequenceFrames& s = data.sequences[std::size_t(q)];
    const auto worst = std::size_t(std::max_element(ev.frame_subdivided.begin(), ev.frame_subdivided.end()) - ev.frame_subdivided.begin());
    const auto dir = results / "compare" / (s.name + "_" + std::to_string(worst));
    std::filesystem::create_directories(dir);
    io::VtuGrid lr;
    lr.set_points(s.coarse[worst]).set_triangles(data.pair.coarse.F);
    io::write_vtu(dir / "lr_input.vtu", lr);
    const Points<>& truth = s.fine[worst];
    auto view = [&](const char* name, const Points<>& x) {
      io::VtuGrid g;
      g.set_points(x).set_triangles(data.pair.fine.F);
      g.add_point_data("error", VecX<double>((x - truth).rowwise().norm()));
      io::write_vtu(dir / (std::string(name) + ".vtu"), g);
    };
    view("truth", truth);
    view("subdivided", Points<>(data.pair.subdivision * s.coarse[worst]));
    view("synthesized", raw[worst]);
    view("refined", refined[worst]);
  });

  // the core paper's upsampling methods on the same held-out sequences
  const std::vector<ClothUpsamplingEvaluation> baselines = run_cloth_baselines(policy, o, data, net_dir, tell);

  // per held-out frame, every method: the CSV and one plot per sequence
  std::ostringstream csv;
  csv.precision(17);
  csv << "sequence,frame,subdivided_m,synthesized_m,refined_m";
  for (const auto& b : baselines) csv << ',' << b.method << "_m";
  csv << '\n';
  for (std::size_t q = 0; q < e.sequences.size(); ++q) {
    const ClothSequenceEvaluation& s = e.sequences[q];
    for (Index f = 0; f < s.frames; ++f) {
      const auto i = std::size_t(f);
      csv << s.name << ',' << f << ',' << s.frame_subdivided[i] << ',' << s.frame_synthesized[i] << ',' << s.frame_refined[i];
      for (const auto& b : baselines) csv << ',' << b.sequences[q].frame_rmse[i];
      csv << '\n';
    }
    std::vector<eval::Series> series{
        {"subdivided", s.frame_subdivided}, {"synthesized", s.frame_synthesized}, {"refined", s.frame_refined}};
    for (const auto& b : baselines) series.push_back({b.method, b.sequences[q].frame_rmse});
    eval::write_svg_plot(results / (s.name + "_errors.svg"), series, s.name + ": RMS distance to the fine simulation per frame", "RMS distance (m)");
  }
  io::write_file_atomic(results / "frame_errors.csv", csv.str());

  // the simulation's cost per frame, from the dataset's summary (frames simulated in any run)
  const nlohmann::json summary = nlohmann::json::parse(io::read_text_file(data_dir / "cloth_data.json"));
  // (the fine cloth's only where it was simulated, not taken from another dataset)
  double coarse_s = 0, fine_s = 0, weight = 0, fine_weight = 0;
  for (const auto& s : summary.at("sequences"))
    if (s.contains("coarse_seconds_per_frame")) {
      const double w = s.at("simulated").get<double>();
      coarse_s += w * s.at("coarse_seconds_per_frame").get<double>();
      weight += w;
      if (s.value("fine_reused", false)) continue;
      fine_s += w * s.at("fine_seconds_per_frame").get<double>();
      fine_weight += w;
    }

  nlohmann::ordered_json r;
  r["scene"] = to_string(o.scene);
  r["coarse_vertices"] = data.num_coarse();
  r["fine_vertices"] = data.num_fine();
  // the supplement's scale factor (Table 3: ×16, ×64, ×256): fine over coarse triangles
  r["face_scale_factor"] = double(data.pair.fine.F.rows()) / double(data.pair.coarse.F.rows());
  r["test_frames"] = e.frames;
  r["rmse_m"] = {{"subdivided", e.subdivided_rmse}, {"synthesized", e.synthesized_rmse}, {"synthesized_refined", e.refined_rmse},
                  {"decoded_truth", e.decoded_truth_rmse}, {"decoded_subdivided", e.decoded_subdivided_rmse}};
  for (const auto& b : baselines) r["rmse_m"][b.method] = b.rmse;
  r["fine_target"] = fine_target_name(o.network.fine_target);
  if (o.network.fine_target == FineTarget::residual) r["residual_lift"] = residual_lift_name(o.network.residual_lift);
  nlohmann::ordered_json seqs = nlohmann::ordered_json::array();
  for (const auto& s : e.sequences)
    seqs.push_back({{"name", s.name}, {"frames", s.frames}, {"subdivided_m", s.subdivided_rmse}, {"synthesized_m", s.synthesized_rmse},
                    {"refined_m", s.refined_rmse}, {"decoded_truth_m", s.decoded_truth_rmse},
                    {"decoded_subdivided_m", s.decoded_subdivided_rmse}, {"inside_before_vertex_frames", s.inside_before}, {"projected_vertex_frames", s.projected},
                    {"deepest_before_m", s.deepest_before}, {"deepest_after_m", s.deepest_after}});
  for (const auto& b : baselines)
    for (std::size_t q = 0; q < b.sequences.size(); ++q) seqs[q][b.method + "_m"] = b.sequences[q].rmse;
  r["sequences"] = seqs;
  nlohmann::ordered_json bt = nlohmann::ordered_json::object();
  for (const auto& b : baselines) bt[b.method] = {{"fit_seconds", b.fit_seconds}, {"seconds_per_frame", b.seconds_per_frame}};
  r["baseline_timings"] = bt;
  const FeatureJumps& j = run.feature_jumps();
  auto counts = [](const FeatureJumps::Counts& c) {
    return nlohmann::ordered_json{{"temporal", c.temporal}, {"spatial", c.spatial}, {"vertex_frames", c.vertex_frames},
                                  {"edge_frames", c.edge_frames}, {"largest_angle_rad", c.largest_angle}};
  };
  r["feature_jumps"] = {{"coarse", counts(j.coarse)}, {"fine", counts(j.fine)}};
  if (o.network.fine_target == FineTarget::residual)
    r["feature_jumps"]["residual_beyond_pi"] = {{"own", j.residual_own}, {"trained", j.residual_trained}, {"vertex_frames", j.residual_vertex_frames}};
  nlohmann::ordered_json tt{{"ts_acap_extraction", e.timings.ts_acap}, {"synthesis", e.timings.synthesis}, {"collision_refinement", e.timings.refinement}};
  if (weight > 0) tt["coarse_simulation"] = coarse_s / weight;
  if (fine_weight > 0) tt["fine_simulation"] = fine_s / fine_weight;
  r["seconds_per_frame"] = tt;
  nlohmann::ordered_json hist = nlohmann::ordered_json::array();
  for (const auto& h : history)
    hist.push_back({{"epoch", h.epoch}, {"lr", h.lr}, {"synthesis", h.loss.synthesis}, {"reconstruction", h.loss.reconstruction}, {"latent", h.loss.latent},
                    {"seconds", h.seconds}});
  r["training"] = hist;
  io::write_file_atomic(o.out / "report.json", r.dump(2) + "\n");
  return r;
}

/// The RMSE and timing tables of a report as text.
inline std::string cloth_report_text(const nlohmann::ordered_json& r) {
  char buf[512];
  std::string s;
  std::snprintf(buf, sizeof buf, "%s: %lld coarse / %lld fine vertices (x%g faces), %lld held-out frames\n\n", r.at("scene").get<std::string>().c_str(),
                (long long)r.at("coarse_vertices").get<Index>(), (long long)r.at("fine_vertices").get<Index>(), r.value("face_scale_factor", 0.0),
                (long long)r.at("test_frames").get<Index>());
  s += buf;
  s += "RMSE to the fine simulation (m; network's fine side: " + r.at("fine_target").get<std::string>() +
       "; decoded_truth: the true fine features decoded, the features' floor; decoded_subdivided: the subdivided mesh's features "
       "decoded, a residual network's start; local_linear, upsampling_network: the core paper's methods)\n";
  for (const auto& [k, v] : r.at("rmse_m").items()) {
    std::snprintf(buf, sizeof buf, "  %-22s %.5f\n", k.c_str(), v.get<double>());
    s += buf;
  }
  const auto& j = r.at("feature_jumps");
  std::snprintf(buf, sizeof buf, "\nrotation-feature jumps > pi (the integer steps' misses): coarse %lld temporal / %lld spatial, fine %lld / %lld (largest |angle| %.2f rad)\n",
                (long long)j.at("coarse").at("temporal").get<Index>(), (long long)j.at("coarse").at("spatial").get<Index>(),
                (long long)j.at("fine").at("temporal").get<Index>(), (long long)j.at("fine").at("spatial").get<Index>(),
                j.at("fine").at("largest_angle_rad").get<double>());
  s += buf;
  if (j.contains("residual_beyond_pi")) {
    const auto& q = j.at("residual_beyond_pi");
    std::snprintf(buf, sizeof buf, "residual rotations > pi from the subdivided mesh's: %lld as lifted alone, %lld trained on (%s), of %lld vertex-frames\n",
                  (long long)q.at("own").get<Index>(), (long long)q.at("trained").get<Index>(), r.value("residual_lift", std::string("own")).c_str(),
                  (long long)q.at("vertex_frames").get<Index>());
    s += buf;
  }
  s += "\nseconds per frame (Table 1's stages)\n";
  for (const auto& [k, v] : r.at("seconds_per_frame").items()) {
    std::snprintf(buf, sizeof buf, "  %-22s %.5f\n", k.c_str(), v.get<double>());
    s += buf;
  }
  return s;
}

}  // namespace simsr::shell
