#pragma once
/// \file
/// The core paper's ablations (§5.4, Table 2 and Fig. 9) as one sweep over the demo's data: the
/// network without feature embedding (w/o FE), without coordinate-based upsampling (w/o CU), with
/// 1/3/5/10/20 interpolation neighbours and with EdgeConv k = 1…10 — every variant the demo's
/// recipe with one field changed, trained on the training performances and evaluated on the test
/// ones. Each variant is a stage of the demo's folder ("network-abl_<variant>"), so the data, the
/// neighbourhoods and every finished variant are reused, and a killed sweep resumes.
///
///     pipeline::DemoOptions o;  o.out = "out/demo";
///     pipeline::AblationOptions a;  a.epochs = 2;
///     nlohmann::ordered_json r = pipeline::run_ablations(exec::omp, o, a, log);
///
/// Writes DIR/results/ablations.csv (one row per variant: test mean error, absolute and relative
/// to the bounding-box diagonal, inference and training time), DIR/results/table2.txt (full,
/// w/o FE, w/o CU, normalized to the largest as the paper's Table 2), DIR/results/fig9_upk.svg and
/// DIR/results/fig9_knn.svg (test error against the swept value, Embedded's beside it) and
/// DIR/results/ablations.json (also returned).

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../eval/report.hpp"
#include "demo.hpp"

namespace simsr::pipeline {

/// What the sweep trains. Every variant is the demo's recipe (DemoOptions::recipe) with `epochs`
/// epochs and one field changed.
struct AblationOptions {
  Index epochs = 2;                             ///< per variant (the demo's network trains 8)
  bool table2 = true;                           ///< full, w/o FE, w/o CU
  std::vector<Index> up_k{1, 3, 5, 10, 20};     ///< interpolation neighbours (Fig. 9, left); each ≤ the neighbourhoods' k
  std::vector<Index> knn{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};  ///< EdgeConv k (Fig. 9, right)
};

/// One variant of the sweep.
struct AblationVariant {
  std::string name;    ///< its stage and folder: abl_<name>
  std::string group;   ///< table2 | upk | knn
  double value = 0;    ///< the swept value (upk, knn), 0 in table2
  interp::NetworkRecipe recipe;
};

/// The variants `a` asks for, in order: Table 2's, then upK's, then k's.
inline std::vector<AblationVariant> ablation_variants(const interp::NetworkRecipe& base, const AblationOptions& a, Index neighborhood_k) {
  if (a.epochs < 1) throw ArgumentError("ablations: epochs must be >= 1 (got " + std::to_string(a.epochs) + ")");
  interp::NetworkRecipe r = base;
  r.epochs = a.epochs;
  {  // the preset's k and upK spelled out, so that the variants equal to the full network are seen to be
    const auto c = r.config();
    r.knn = c.knn;
    r.up_k = c.up_k;
  }
  std::vector<AblationVariant> v;
  if (a.table2) {
    v.push_back({"full", "table2", 0, r});
    auto fe = r;
    fe.without_fe = true;
    v.push_back({"wo_fe", "table2", 0, fe});
    auto cu = r;
    cu.without_cu = true;
    v.push_back({"wo_cu", "table2", 0, cu});
  }
  for (std::size_t i = 0; i < a.up_k.size(); ++i) {
    const Index k = a.up_k[i];
    if (k < 1 || k > neighborhood_k)
      throw ArgumentError("ablations: interpolation neighbours " + std::to_string(k) + " outside [1, " + std::to_string(neighborhood_k) + "] (the neighbourhoods' k)");
    if (i > 0 && k <= a.up_k[i - 1]) throw ArgumentError("ablations: the interpolation neighbours must ascend");
    auto x = r;
    x.up_k = k;
    v.push_back({"upk" + std::to_string(k), "upk", double(k), x});
  }
  for (std::size_t i = 0; i < a.knn.size(); ++i) {
    const Index k = a.knn[i];
    if (k < 1 || k > 64) throw ArgumentError("ablations: EdgeConv k " + std::to_string(k) + " outside [1, 64]");
    if (i > 0 && k <= a.knn[i - 1]) throw ArgumentError("ablations: the EdgeConv k values must ascend");
    auto x = r;
    x.knn = k;
    v.push_back({"knn" + std::to_string(k), "knn", double(k), x});
  }
  for (auto& x : v) x.recipe.config();  // every variant valid before anything trains
  return v;
}

/// Trains (or reuses) every variant and writes the files of the file comment; returns the summary.
template <exec::HostPolicy P>
nlohmann::ordered_json run_ablations(P policy, const DemoOptions& o, const AblationOptions& a, const Log& log = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  Stages stages(o.out, log);
  std::string nb_fp;
  nlohmann::json nb_result;
  DemoData d = detail::prepared_data(policy, stages, o, nb_fp, nb_result);
  const auto variants = ablation_variants(o.recipe, a, o.method_parameters.k);
  const double diag = eval::bbox_diagonal(d.problem.hr.V);
  data::FrameSet truth;
  truth.has_ids = true;
  truth.ids = d.test.ids;
  truth.positions = d.test.highres;

  // Embedded on the same frames: the line every variant is compared with.
  double embedded_mean = 0;
  {
    interp::Embedded<> embedded;
    embedded.fit(policy, d.problem);
    embedded_mean = eval::evaluate(policy, embedded, d.problem.lr.V, d.problem.hr.V, d.test).errors.statistics().mean;
  }

  nlohmann::ordered_json out;
  out["epochs"] = a.epochs;
  out["recipe"] = o.recipe.to_json();
  out["bbox_diagonal"] = diag;
  out["embedded"] = {{"mean", embedded_mean}, {"relative_mean", embedded_mean / diag}};
  std::string csv = "variant,group,value,epochs,mean_error,relative_mean_error,apply_ms_per_frame,train_seconds,same_as\n";
  std::vector<std::pair<std::string, std::string>> done;  // each trained variant and its recipe (JSON text)
  std::size_t index = 0;
  for (const auto& v : variants) {
    ++index;
    const std::string name = "abl_" + v.name;
    // A variant whose recipe another one already has (k = 5 and upK = 10 are the full network's)
    // is that one: trained once.
    std::string same_as;
    for (const auto& [other, recipe] : done)
      if (recipe == v.recipe.to_json().dump()) same_as = other;
    const std::string trained = same_as.empty() ? name : same_as;
    stages.say("ablation " + std::to_string(index) + "/" + std::to_string(variants.size()) + ": " + v.name + (same_as.empty() ? "" : " (= " + same_as + ")"));
    const nlohmann::json r = detail::network_stage(policy, stages, o, d, nb_fp, v.recipe, trained);
    if (same_as.empty()) done.emplace_back(name, v.recipe.to_json().dump());
    const auto file = detail::prediction_file(stages, trained);
    const auto e = eval::evaluate_predictions(d.problem.hr.V, data::read_frame_set(file, "highres", d.problem.num_hr()), truth, file.string());
    const double mean = e.errors.statistics().mean;
    const double apply_ms = 1e3 * r.value("apply_seconds_per_frame", 0.0);
    auto& j = out["variants"][v.name];
    j = {{"group", v.group},         {"value", v.value},       {"network", trained}, {"mean_error", mean}, {"relative_mean_error", mean / diag},
         {"apply_ms_per_frame", apply_ms}, {"train_seconds", r.value("train_seconds", 0.0)}, {"recipe", v.recipe.to_json()}};
    char line[512];
    std::snprintf(line, sizeof line, "%s,%s,%g,%lld,%.9e,%.9e,%.6g,%.6g,%s\n", v.name.c_str(), v.group.c_str(), v.value, (long long)a.epochs, mean, mean / diag,
                  apply_ms, r.value("train_seconds", 0.0), same_as.empty() ? "" : same_as.substr(4).c_str());
    csv += line;
  }
  const auto results = o.out / "results";
  std::filesystem::create_directories(results);
  io::write_file_atomic(results / "ablations.csv", csv);

  // Table 2: full, w/o FE, w/o CU — relative mean error, normalized to the largest, inference ms
  if (a.table2) {
    double largest = 0;
    for (const char* n : {"full", "wo_fe", "wo_cu"}) largest = std::max(largest, out["variants"][n]["mean_error"].get<double>());
    std::string t = "Table 2 (§5.4) on the test frames, " + std::to_string(a.epochs) + " epochs each\n";
    char line[256];
    std::snprintf(line, sizeof line, "%-10s %14s %12s %14s\n", "variant", "mean/diagonal", "normalized", "ms per frame");
    t += line;
    for (const char* n : {"full", "wo_fe", "wo_cu"}) {
      const auto& j = out["variants"][n];
      std::snprintf(line, sizeof line, "%-10s %14.4e %12.3f %14.1f\n", n, j["relative_mean_error"].get<double>(), j["mean_error"].get<double>() / largest,
                    j["apply_ms_per_frame"].get<double>());
      t += line;
    }
    std::snprintf(line, sizeof line, "%-10s %14.4e\n", "embedded", embedded_mean / diag);
    t += line;
    io::write_file_atomic(results / "table2.txt", t);
    out["table2"] = t;
  }
  // Fig. 9: the test error against each swept value, Embedded's beside it
  for (const char* group : {"upk", "knn"}) {
    std::vector<double> x;
    eval::Series net{"network (" + std::to_string(a.epochs) + " epochs)", {}}, emb{"Embedded", {}};
    for (const auto& v : variants)
      if (v.group == group) {
        x.push_back(v.value);
        net.values.push_back(out["variants"][v.name]["relative_mean_error"].get<double>());
        emb.values.push_back(embedded_mean / diag);
      }
    if (x.empty()) continue;
    const bool upk = std::string(group) == "upk";
    eval::write_svg_xy_plot(results / (std::string("fig9_") + group + ".svg"), x, {net, emb},
                            upk ? "Fig. 9: interpolation neighbours (upK)" : "Fig. 9: EdgeConv k", "test mean error / bbox diagonal",
                            upk ? "interpolation neighbours" : "EdgeConv k");
  }
  out["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  io::write_file_atomic(results / "ablations.json", out.dump(2) + "\n");
  return out;
}

}  // namespace simsr::pipeline
