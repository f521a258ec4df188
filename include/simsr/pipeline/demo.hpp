#pragma once
/// \file
/// The paper's evaluation end to end (§5, Table 1, Fig. 5), as stages a rerun reuses
/// (pipeline/stages.hpp): on the face, the paired data (scenario::generate_face_dataset), the §3.2
/// neighbourhoods, every baseline fitted (Embedded, IDW, RBF, MLS, ridge; the β-VAE trained), the
/// super-resolution network trained on the training performances (resumable from its checkpoint),
/// every method run on the test performances, and the results: Table 1 (statistics.csv and the
/// JSON report), frame-wise errors (CSV + SVG), per-vertex error heatmaps (VTU), every method's
/// predictions (npz, for renders and the report page), Fig. 6's views and, on the face, Fig. 7's:
/// the unseen-force frames through Embedded and the network (unseen_views.hpp). On the bunny, the authors' frames with every
/// 4th held out, as `simsr train` does.
///
///     pipeline::DemoOptions o;  o.out = "out/demo";
///     nlohmann::ordered_json report = pipeline::run_demo(exec::omp, o, log);   // DIR/report.json too
///
/// Layout of DIR: data/ (face data set), neighbors.npz, predictions/<method>.npz, network/ (model,
/// checkpoint, training history), results/ (Table 1, frame errors, heatmaps, compare/: Fig. 6, unseen/: Fig. 7), report/ (the page
/// people open: report_page.hpp), stages/ (markers), report.json.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "../data/data.hpp"
#include "../eval/comparison.hpp"
#include "../eval/evaluate.hpp"
#include "../eval/intersections.hpp"
#include "../eval/training_history.hpp"
#include "../interp/by_name.hpp"
#include "../interp/embedded.hpp"
#include "../interp/learned.hpp"
#include "../interp/network_recipe.hpp"
#include "../data/contact_patches_file.hpp"
#include "../scenario/face/face_dataset.hpp"
#include "report_page.hpp"
#include "stages.hpp"
#include "unseen_views.hpp"

namespace simsr::pipeline {

struct DemoOptions {
  std::string dataset = "face";                       ///< face | bunny
  std::filesystem::path data = "../shared/data";      ///< the shared data folder (ict_face/, bunny/)
  std::filesystem::path out = "out/demo";
  scenario::FaceDatasetOptions face;                  ///< its kit is always data/ict_face
  std::vector<std::string> train_sequences{"amazement", "pain"};  ///< face: §5's split
  std::vector<std::string> test_sequences{"anger", "fear"};
  Index bunny_holdout_every = 4;                      ///< bunny: frames f with f % n == 0 are the test frames
  std::vector<std::string> methods{"embedded", "idw", "rbf", "mls", "ridge", "local_linear", "beta_vae"};
  /// k = 20: the paper's neighbourhoods. RBF over Euclidean distances, λ = 1e-8: the geodesic
  /// reading (each LR vertex placed at its assigned HR surface vertex) puts the face's 2.3k interior
  /// lattice nodes on the skin, and the interpolant between them blows up (held-out mean error 3.5×
  /// the bounding-box diagonal, still 5.6e-3 of it at λ = 1e-2); Euclidean distances need a tiny λ
  /// for the lattice nodes duplicated at the lips (two nodes, one position) and then give 1.1e-3,
  /// between Embedded and MLS as in the paper's Table 1.
  interp::MethodParameters method_parameters = [] {
    interp::MethodParameters p;
    p.rbf_distance = "euclidean";
    p.rbf_regularization = 1e-8;
    return p;
  }();
  bool network = true;                                ///< train and evaluate the super-resolution network
  /// The network's recipe: NetworkRecipe's (simsr train's) but for the face's measured choices
  /// (README, "The network on the face"): 8 epochs, the time the main job's 50-minute budget leaves
  /// on 2 cores, and the residual over the local-linear map fitted on the training frames instead
  /// of over Embedded (the "residual composition"). Its displacements at unit RMS were
  /// measured on the face too (σ = 0.05 m leaves its millimetre displacements at 0.035 in network
  /// units; after 3 epochs the held-out error is 7.11e-4 of the diagonal with the scale, 8.02e-4
  /// without). The rate halves every 10 epochs as when it was measured: never within 8 epochs,
  /// and the stages finished before keep their fingerprints.
  interp::NetworkRecipe recipe = [] {
    interp::NetworkRecipe r;
    r.epochs = 8;
    r.lr_decay_epochs = 10;
    r.residual_base = "local_linear";
    return r;
  }();
  std::string network_name = "network";               ///< its name in the tables (an ablation: another name)
  bool progress = true;                               ///< training progress lines (network, β-VAE) on stderr
  /// three's npm package folder (node_modules) for the report page's viewer (report_page.hpp);
  /// the tool passes the one its build vendored. Empty: the page without the viewer.
  std::filesystem::path vendor_dir;
  Index viewer_frames = 15;                           ///< frames of each test sequence the viewer plays
};

/// The frames a demo trains and tests on, and the problem they belong to.
struct DemoData {
  interp::UpsamplingProblem<> problem;
  data::PairedFrames<> train, test;
  std::string fingerprint;  ///< of the data's options (the files themselves are checked by their producers)
  std::vector<std::string> test_names;  ///< per test frame: its sequence (face) or "holdout"
  ContactPatches lips;      ///< face: the lips as contact patches of the HR surface (data/hr_lips.npz); bunny: none
  nlohmann::ordered_json summary;

  /// The distinct test sequences, in the order their frames come.
  std::vector<std::string> test_sequences() const {
    std::vector<std::string> out;
    for (const auto& n : test_names)
      if (std::find(out.begin(), out.end(), n) == out.end()) out.push_back(n);
    return out;
  }
};

namespace detail {

inline data::PairedFrames<> read_sequences(const std::filesystem::path& dir, const std::vector<std::string>& names, Index n, Index m) {
  std::vector<data::PairedFrames<>> parts;
  for (const auto& name : names) parts.push_back(data::read_paired_frames(dir / (name + ".npz"), n, m));
  return data::concatenate(std::span<const data::PairedFrames<>>(parts), std::span<const std::string>(names), data::FrameIds::renumber,
                           data::FrameControls::drop);
}

/// The face data set (stage "data"), then its rest shapes and the two splits.
template <exec::HostPolicy P>
DemoData face_data(P policy, Stages& stages, const DemoOptions& o) {
  auto fo = o.face;
  fo.kit = o.data / "ict_face";
  std::vector<std::string> wanted = o.train_sequences;
  wanted.insert(wanted.end(), o.test_sequences.begin(), o.test_sequences.end());
  for (const auto& w : wanted) {
    const auto names = scenario::face_performance_names(fo);
    if (std::find(names.begin(), names.end(), w) == names.end())
      throw ArgumentError("demo: sequence '" + w + "' is not one of the performances simulated (" + std::to_string(names.size()) + " asked for)");
  }
  nlohmann::json options;
  options["kit"] = fo.kit.string();
  options["lr_cell"] = fo.model.lr_cell;
  options["skull_lattice"] = fo.model.skull_lattice;
  options["hr_max_volume"] = fo.model.hr.max_volume;
  options["performances"] = fo.performances;
  options["frames"] = fo.frames;
  options["seed"] = fo.seed;
  options["unseen_frames"] = fo.unseen_forces ? fo.unseen_frames : 0;
  const auto dir = stages.dir() / "data";
  DemoData d;
  d.fingerprint = fingerprint_of(options);
  d.summary = stages.run("data", d.fingerprint, [&] { return nlohmann::json(scenario::generate_face_dataset(policy, fo, dir, [&](const std::string& s) { stages.say(s); })); });
  d.problem = interp::UpsamplingProblem<>{data::read_lr_rest(dir / "lr_rest.msh"), data::read_hr_rest(dir / "hr_rest.obj"), {}, {}};
  d.train = read_sequences(dir, o.train_sequences, d.problem.num_lr(), d.problem.num_hr());
  d.test = read_sequences(dir, o.test_sequences, d.problem.num_lr(), d.problem.num_hr());
  for (Index f = 0; f < d.test.num_frames(); ++f) d.test_names.push_back(d.test.sequence_name(f));
  const auto lips_file = dir / "hr_lips.npz";
  if (!std::filesystem::exists(lips_file)) {  // data written before datagen wrote the lips: the model has them
    stages.say("data: no " + lips_file.string() + " (data of an earlier version): building the face model for its lips");
    const auto face = scenario::build_face_model(policy, scenario::read_ict_kit(fo.kit), fo.model, dir / "mesh");
    if (face.surface.num_vertices() != d.problem.num_hr() || (face.surface.V - d.problem.hr.V).cwiseAbs().maxCoeff() > 1e-6)
      throw ArgumentError(dir.string() + ": hr_rest.obj is not the surface of the face model these options build: regenerate the data");
    data::write_contact_patches(lips_file, scenario::face_lip_patches(face), face.surface.num_vertices());
  }
  d.lips = data::read_contact_patches(lips_file, d.problem.num_hr());
  return d;
}

/// The authors' bunny frames, every n-th held out.
inline DemoData bunny_data(const DemoOptions& o) {
  const auto dir = o.data / "bunny";
  DemoData d;
  d.problem = interp::UpsamplingProblem<>{data::read_lr_rest(dir / "lrestshape.obj"), data::read_hr_rest(dir / "hrestshape.obj"), {}, {}};
  const auto frames = data::read_paired_frames(dir / "train_frames.npz", d.problem.num_lr(), d.problem.num_hr());
  if (o.bunny_holdout_every < 2) throw ArgumentError("demo: the bunny's hold-out needs every n-th frame with n >= 2 (got " + std::to_string(o.bunny_holdout_every) + ")");
  const auto split = data::holdout_every(frames.num_frames(), o.bunny_holdout_every);
  d.train = frames.select(split.train);
  d.test = frames.select(split.test);
  d.test_names.assign(std::size_t(d.test.num_frames()), "holdout");
  d.fingerprint = fingerprint_of({{"bunny", fingerprint_of_file(dir / "train_frames.npz")}, {"every", o.bunny_holdout_every}});
  d.summary = {{"frames", frames.num_frames()}, {"holdout_every", o.bunny_holdout_every}};
  return d;
}

inline std::filesystem::path prediction_file(const Stages& s, const std::string& method) { return s.dir() / "predictions" / (method + ".npz"); }

/// Runs a fitted method on the test frames and writes its predictions (absolute HR positions,
/// the test frames' ids); returns the apply time per frame.
template <exec::HostPolicy P, class Method>
double predict_test(P policy, const Method& method, const DemoData& d, const std::filesystem::path& file) {
  data::FrameSet pred;
  pred.has_ids = true;
  pred.ids = d.test.ids;
  pred.positions.resize(d.test.num_frames(), 3 * d.problem.num_hr());
  const auto r = eval::evaluate(policy, method, d.problem.lr.V, d.problem.hr.V, d.test, [&](Index f, const Points<Scalar>& x) {
    pred.positions.row(f) = Eigen::Map<const Eigen::Matrix<Scalar, 1, Eigen::Dynamic>>(x.data(), x.size());
  });
  std::filesystem::create_directories(file.parent_path());
  data::write_frame_set(file, "highres", pred);
  return r.seconds_per_frame;
}

/// Per test frame, the intersecting lip triangle pairs of the truth and of every method's
/// prediction (exact test), written as CSV (frame, sequence, truth, methods…); returns the summary
/// per column.
template <exec::HostPolicy P>
nlohmann::ordered_json write_lip_intersections(P policy, const std::filesystem::path& csv, const DemoData& d, const std::vector<std::string>& names,
                                               const std::vector<data::FrameSet>& predictions) {
  std::vector<std::vector<std::int64_t>> counts{eval::intersecting_pairs_per_frame(policy, d.test.highres, d.lips)};
  for (const auto& p : predictions) counts.push_back(eval::intersecting_pairs_per_frame(policy, p.positions, d.lips));
  std::ostringstream text;
  text.imbue(std::locale::classic());
  text << "frame,sequence,truth";
  for (const auto& n : names) text << ',' << n;
  text << '\n';
  for (Index f = 0; f < d.test.num_frames(); ++f) {
    text << d.test.ids[std::size_t(f)] << ',' << d.test_names[std::size_t(f)];
    for (const auto& c : counts) text << ',' << c[std::size_t(f)];
    text << '\n';
  }
  std::filesystem::create_directories(csv.parent_path());
  io::write_file_atomic(csv, text.str());
  nlohmann::ordered_json j;
  j["upper_triangles"] = d.lips.a.rows();
  j["lower_triangles"] = d.lips.b.rows();
  for (std::size_t k = 0; k < counts.size(); ++k) {
    const auto s = eval::summarize_intersections(counts[k]);
    j["methods"][k == 0 ? std::string("truth") : names[k - 1]] = {
        {"frames", s.frames}, {"frames_with_intersections", s.frames_with_intersections}, {"pairs_total", s.pairs_total}, {"pairs_max", s.pairs_max}};
  }
  j["csv"] = csv.string();
  return j;
}

}  // namespace detail

/// Fig. 6's material for every test sequence: on its frame where the first method (Embedded in
/// the default list) errs most, `dir/<sequence>_<frame id>/` gets lr_input.vtu (the LR simulation
/// mesh), truth.vtu (the HR surface) and <method>.vtu (each method's predicted surface with its
/// per-vertex `error`, mesh units), for ParaView and scripts/render_comparison.py. Returns the
/// folders written.
inline std::vector<std::string> write_comparison_views(const std::filesystem::path& dir, const DemoData& d, const eval::MethodComparison& table,
                                                       const std::vector<data::FrameSet>& predictions) {
  const auto& names = table.names();
  std::vector<std::string> written;
  const auto& first = table.evaluations().front().errors.frame_means();
  for (const auto& seq : d.test_sequences()) {
    Index worst = -1;
    for (Index f = 0; f < d.test.num_frames(); ++f)
      if (d.test_names[std::size_t(f)] == seq && (worst < 0 || first[std::size_t(f)] > first[std::size_t(worst)])) worst = f;
    const std::string folder = seq + "_" + std::to_string(d.test.ids[std::size_t(worst)]);
    const auto out = dir / folder;
    std::filesystem::create_directories(out);
    io::VtuGrid lr;
    lr.set_points(Points<Scalar>(d.test.lr(worst))).set_tets(d.problem.lr.T);
    io::write_vtu(out / "lr_input.vtu", lr);
    const Points<Scalar> truth = d.test.hr(worst);
    io::VtuGrid t;
    t.set_points(truth).set_triangles(d.problem.hr.F);
    t.add_point_data("error", VecX<double>(VecX<double>::Zero(truth.rows())));
    io::write_vtu(out / "truth.vtu", t);
    for (std::size_t k = 0; k < names.size(); ++k) {
      const Points<Scalar> x = predictions[k].frame(worst);
      io::VtuGrid g;
      g.set_points(x).set_triangles(d.problem.hr.F);
      g.add_point_data("error", VecX<double>((x - truth).rowwise().norm()));
      io::write_vtu(out / (names[k] + ".vtu"), g);
    }
    written.push_back(folder);
  }
  return written;
}

namespace detail {

/// ArgumentError unless `name` can name a network's stage, folder and prediction file.
inline void check_network_name(const std::string& name, const std::vector<std::string>& methods) {
  const bool plain_name = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
  if (!plain_name || std::find(methods.begin(), methods.end(), name) != methods.end() || name == "data" || name == "results" || name == "predictions" ||
      name == "stages" || name == "report" || name == "ablations")
    throw ArgumentError("demo: network name '" + name + "' must be letters, digits, _ or - and not a method's or a folder's name");
}

/// The data set (stage "data" on the face) and the §3.2 neighbourhoods (stage "neighbors"), used
/// by the problem; `nb_fingerprint` and `nb_result` receive that stage's fingerprint and result.
template <exec::HostPolicy P>
DemoData prepared_data(P policy, Stages& stages, const DemoOptions& o, std::string& nb_fingerprint, nlohmann::json& nb_result) {
  if (o.dataset != "face" && o.dataset != "bunny") throw ArgumentError("demo: --dataset must be face or bunny (got '" + o.dataset + "')");
  DemoData d = o.dataset == "face" ? face_data(policy, stages, o) : bunny_data(o);
  const auto& mp = o.method_parameters;
  // §3.2 neighbourhoods and the LR graph, shared by IDW, MLS, RBF and the network.
  const auto nb_file = o.out / "neighbors.npz";
  nb_fingerprint = fingerprint_of({{"data", d.fingerprint}, {"k", mp.k}});
  nb_result = stages.run("neighbors", nb_fingerprint, [&] {
    const auto nb = data::compute_network_neighborhoods(policy, d.problem.lr, d.problem.hr, mp.k, mp.k);
    data::save_network_neighborhoods(nb_file, nb);
    return nlohmann::json{{"k", mp.k}, {"assignment_cost", nb.upsampling.assignment_cost}, {"assignment_globally_optimal", nb.upsampling.assignment_globally_optimal}};
  });
  d.problem.use(data::read_network_neighborhoods(nb_file, d.problem.num_lr(), d.problem.num_hr()));
  return d;
}

/// Stage "network-<name>": the network of `recipe` trained on the training frames (resumed from
/// DIR/<name>/checkpoint.npz when a run of this very stage was killed), saved as
/// DIR/<name>/model.npz with its training history, and run on the test frames
/// (DIR/predictions/<name>.npz). Returns the stage's result. `d` is not const because fitting reads
/// (and may complete) the problem's LR graph.
template <exec::HostPolicy P>
nlohmann::json network_stage(P policy, Stages& stages, const DemoOptions& o, DemoData& d, const std::string& nb_fp,
                             const interp::NetworkRecipe& recipe, const std::string& name) {
  check_network_name(name, o.methods);
  const auto& mp = o.method_parameters;
  const auto train_displacements = data::displacements(d.train, d.problem.lr.V, d.problem.hr.V);
  auto cfg = recipe.config(train_displacements);
  cfg.residual_base_k = mp.k;  // the local-linear base is the demo's local_linear method, on the same neighbourhoods
  const auto net_dir = o.out / name;
  const std::string fp = fingerprint_of({{"neighbors", nb_fp}, {"recipe", recipe.to_json()}});
  return stages.run("network-" + name, fp, [&] {
    std::filesystem::create_directories(net_dir);
    interp::Learned<> net(cfg, recipe.seed);
    interp::prepare(policy, net, d.problem, mp.k);
    interp::NetworkTrainOptions to;
    to.trainer.seed = recipe.seed;
    to.trainer.progress = o.progress;
    to.trainer.lr_decay_epochs = recipe.lr_decay_epochs;
    to.checkpoint = net_dir / "checkpoint.npz";
    if (cfg.w_contact > 0) {
      if (d.lips.empty()) throw ArgumentError("demo: the contact term (--w-contact) needs contact patches: the face's lips (the " + o.dataset + " data has none)");
      to.contact = d.lips;
    }
    // A checkpoint of this very stage (same fingerprint; its marker is missing: the run was
    // killed) is resumed; one written under other options is not: training starts over and
    // replaces it. (The trainer itself refuses a checkpoint of other data or options.)
    const auto fp_file = net_dir / "checkpoint.fingerprint";
    if (std::filesystem::exists(to.checkpoint) && std::filesystem::exists(fp_file)) {
      std::ifstream in(fp_file);
      std::string old;
      in >> old;
      if (old == fp) {
        to.resume = to.checkpoint;
        stages.say(name + ": resuming from " + to.checkpoint.string());
      }
    }
    io::write_file_atomic(fp_file, fp + "\n");
    const auto t = std::chrono::steady_clock::now();
    net.train(policy, train_displacements, to);
    const double train_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    net.save(net_dir / "model.npz");
    const double diag = eval::bbox_diagonal(d.problem.hr.V);
    eval::write_training_history(net_dir, net.history(), diag, -1);
    nlohmann::json r;
    r["model"] = (net_dir / "model.npz").string();
    r["parameters"] = net.network().store().num_parameters();
    r["epochs"] = net.epoch();
    r["steps"] = net.steps();
    r["train_seconds"] = train_seconds;
    r["recipe"] = recipe.to_json();
    r["displacement_scale"] = cfg.displacement_scale;
    if (const auto* b = net.base_info()) r["residual_base"] = b->to_json();
    r["apply_seconds_per_frame"] = predict_test(policy, net, d, prediction_file(stages, name));
    return r;
  });
}

}  // namespace detail

/// Runs (or reuses) every stage and writes the results; returns the report (also DIR/report.json).
template <exec::HostPolicy P>
nlohmann::ordered_json run_demo(P policy, const DemoOptions& o, const Log& log = {}) {
  if (o.dataset != "face" && o.dataset != "bunny") throw ArgumentError("demo: --dataset must be face or bunny (got '" + o.dataset + "')");
  if (o.methods.empty() && !o.network) throw ArgumentError("demo: no method and no network: nothing to evaluate");
  if (o.network) detail::check_network_name(o.network_name, o.methods);
  const auto t0 = std::chrono::steady_clock::now();
  Stages stages(o.out, log);
  std::string nb_fp;
  nlohmann::json nb_result;
  DemoData d = detail::prepared_data(policy, stages, o, nb_fp, nb_result);
  const auto& mp = o.method_parameters;

  nlohmann::ordered_json methods_json;
  std::vector<std::string> names;
  for (const auto& name : o.methods) {
    auto params = mp;
    params.progress = o.progress;
    // Only the parameters this method reads: changing another method's leaves its stage alone.
    nlohmann::json opts = nlohmann::json::object();
    if (name == "idw") opts["k"] = params.k, opts["power"] = params.power;
    if (name == "mls") opts["k"] = params.k, opts["sigma"] = params.sigma, opts["mls_basis"] = params.mls_basis;
    if (name == "rbf")
      opts["sigma"] = params.sigma, opts["degree"] = params.degree, opts["rbf_distance"] = params.rbf_distance,
      opts["rbf_regularization"] = params.rbf_regularization;
    if (name == "beta_vae") opts["vae_epochs"] = params.vae_epochs, opts["seed"] = params.seed;
    const std::string fp = fingerprint_of({{"neighbors", nb_fp}, {"method", name}, {"options", opts}});
    methods_json[name] = stages.run("method-" + name, fp, [&] {
      nlohmann::json r;
      interp::with_method(name, params, [&](auto& method, const auto&... train_options) {
        const auto t = std::chrono::steady_clock::now();
        if constexpr (sizeof...(train_options) > 0)
          interp::prepare(policy, method, d.problem, d.train, train_options..., params.k);
        else
          interp::prepare(policy, method, d.problem, params.k);
        r["fit_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
        r["apply_seconds_per_frame"] = detail::predict_test(policy, method, d, detail::prediction_file(stages, name));
      });
      return r;
    });
    names.push_back(name);
  }

  nlohmann::ordered_json network_json;
  if (o.network) {
    network_json = detail::network_stage(policy, stages, o, d, nb_fp, o.recipe, o.network_name);
    methods_json[o.network_name] = network_json;
    names.push_back(o.network_name);
  }

  // The results (cheap: always rewritten from the stored predictions).
  stages.say("results: Table 1, frame errors, heatmaps");
  eval::MethodComparison table(d.problem.hr.V, d.problem.hr.F, d.test);
  const auto truth = [&] {
    data::FrameSet t;
    t.has_ids = true;
    t.ids = d.test.ids;
    t.positions = d.test.highres;
    return t;
  }();
  std::vector<data::FrameSet> predictions;
  for (const auto& name : names) {
    const auto file = detail::prediction_file(stages, name);
    predictions.push_back(data::read_frame_set(file, "highres", d.problem.num_hr()));
    auto r = eval::evaluate_predictions(d.problem.hr.V, predictions.back(), truth, file.string());
    r.seconds_per_frame = methods_json[name].value("apply_seconds_per_frame", 0.0);
    table.add(name, std::move(r));
  }
  table.write(o.out / "results");
  const auto views = write_comparison_views(o.out / "results" / "compare", d, table, predictions);

  nlohmann::ordered_json report;
  report["dataset"] = o.dataset;
  report["bbox_diagonal"] = table.diagonal();
  report["train_frames"] = d.train.num_frames();
  report["test_frames"] = d.test.num_frames();
  if (o.dataset == "face") {
    report["train_sequences"] = o.train_sequences;
    report["test_sequences"] = o.test_sequences;
  }
  report["data"] = d.summary;
  report["neighbors"] = nb_result;
  const auto raw = table.statistics();
  const auto norm = eval::normalized_to_largest(raw);
  auto stats_json = [](const eval::ErrorStatistics& s) { return nlohmann::ordered_json{{"mean", s.mean}, {"median", s.median}, {"std", s.std}, {"max", s.max}, {"min", s.min}}; };
  for (std::size_t i = 0; i < names.size(); ++i) {
    auto& m = report["table1"][names[i]];
    m["raw"] = stats_json(raw[i]);
    m["relative"] = stats_json(raw[i].scaled(table.diagonal()));
    m["normalized"] = stats_json(norm[i]);
    m["details"] = methods_json[names[i]];
  }
  report["comparison_views"] = views;
  if (!d.lips.empty()) {  // issue #12 item 7: do the predicted lips pass through each other?
    stages.say("results: intersecting lip triangle pairs per frame (truth and every method)");
    report["lip_intersections"] = detail::write_lip_intersections(policy, o.out / "results" / "lip_intersections.csv", d, names, predictions);
  }
  // Fig. 7 (§5.3): the LR-only unseen-force frames through Embedded and the network
  const auto unseen_dir = o.out / "data" / "unseen";
  if (o.dataset == "face" && o.network && std::filesystem::is_directory(unseen_dir)) {
    stages.say("results: Fig. 7, the unseen forces through Embedded and the network");
    interp::Embedded<> embedded;
    embedded.fit(policy, d.problem);
    const auto net = interp::Learned<>::from_model_file(o.out / o.network_name / "model.npz");
    const std::vector<NamedApply> apply{{"embedded", [&](const Points<Scalar>& in, Points<Scalar>& out) { embedded.apply(policy, in, out); }},
                                        {o.network_name, [&](const Points<Scalar>& in, Points<Scalar>& out) { net.apply(policy, in, out); }}};
    report["unseen_forces"] = write_unseen_force_views(unseen_dir, o.out / "results" / "unseen", d.problem, apply);
  }
  {
    ViewerData v;
    v.rest = d.problem.hr.V;
    v.faces = d.problem.hr.F;
    for (const auto& seq : d.test_sequences()) {
      std::vector<Index> rows;
      for (Index f = 0; f < d.test.num_frames(); ++f)
        if (d.test_names[std::size_t(f)] == seq) rows.push_back(f);
      const std::size_t every = std::max<std::size_t>(1, (rows.size() + std::size_t(std::max<Index>(1, o.viewer_frames)) - 1) / std::size_t(std::max<Index>(1, o.viewer_frames)));
      std::vector<Index> shown;
      for (std::size_t i = 0; i < rows.size(); i += every) shown.push_back(rows[i]);
      ViewerData::Sequence s;
      s.name = seq;
      s.truth.resize(Index(shown.size()), 3 * d.problem.num_hr());
      for (std::size_t i = 0; i < shown.size(); ++i) {
        s.frame_ids.push_back(d.test.ids[std::size_t(shown[i])]);
        s.truth.row(Index(i)) = d.test.highres.row(shown[i]);
      }
      for (std::size_t k = 0; k < names.size(); ++k) {
        s.methods.push_back(names[k]);
        data::FrameMatrix<Scalar> p(Index(shown.size()), 3 * d.problem.num_hr());
        for (std::size_t i = 0; i < shown.size(); ++i) p.row(Index(i)) = predictions[k].positions.row(shown[i]);
        s.predicted.push_back(std::move(p));
      }
      v.sequences.push_back(std::move(s));
    }
    report["report_page"] = (o.out / "report" / "index.html").string();
    const std::string note = write_report_page(o.out / "report", report, v, o.vendor_dir, o.out / "results" / "frame_errors.svg");
    if (!note.empty()) stages.say("warning: " + note);
  }
  report["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  io::write_file_atomic(o.out / "report.json", report.dump(2) + "\n");
  return report;
}

/// The lip-intersection summary of the report (empty when it has none): one line per column.
inline std::string lip_intersections_text(const nlohmann::ordered_json& report) {
  if (!report.contains("lip_intersections")) return "";
  std::string out = "Intersecting lip triangle pairs (exact test, every test frame):\n";
  char buf[256];
  std::snprintf(buf, sizeof buf, "%-12s %10s %12s %10s\n", "", "frames", "pairs total", "max/frame");
  out += buf;
  for (const auto& [name, m] : report.at("lip_intersections").at("methods").items()) {
    std::snprintf(buf, sizeof buf, "%-12s %4lld/%-5lld %12lld %10lld\n", name.c_str(), (long long)m.at("frames_with_intersections").get<std::int64_t>(),
                  (long long)m.at("frames").get<std::int64_t>(), (long long)m.at("pairs_total").get<std::int64_t>(), (long long)m.at("pairs_max").get<std::int64_t>());
    out += buf;
  }
  return out + "\n";
}

/// Table 1 as aligned text (mean, median, std, max, min): raw, relative to the bounding-box
/// diagonal and normalized to the largest, one block each.
inline std::string table1_text(const nlohmann::ordered_json& report) {
  std::string out;
  char buf[256];
  for (const char* kind : {"raw", "relative", "normalized"}) {
    std::snprintf(buf, sizeof buf, "%-12s %12s %12s %12s %12s %12s   (%s)\n", "method", "mean", "median", "std", "max", "min", kind);
    out += buf;
    for (const auto& [name, m] : report.at("table1").items()) {
      const auto& s = m.at(kind);
      std::snprintf(buf, sizeof buf, "%-12s %12.4e %12.4e %12.4e %12.4e %12.4e\n", name.c_str(), s.at("mean").get<double>(), s.at("median").get<double>(),
                    s.at("std").get<double>(), s.at("max").get<double>(), s.at("min").get<double>());
      out += buf;
    }
    out += "\n";
  }
  return out;
}

}  // namespace simsr::pipeline
