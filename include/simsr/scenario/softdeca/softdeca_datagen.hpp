#pragma once
/// \file
/// SoftDECA's training data (softdeca supplement §1): N samples of simulation parameters and
/// expressions, each simulated on a layered template (softdeca_simulator.hpp: the ICT head of
/// ict_template.hpp, or any SoftDecaTemplate such as sphere_template.hpp's), written as
///
///     DIR/template_skin.obj           the template's skin at rest (m)
///     DIR/template_soft_tissue.msh    the soft-tissue tets, DIR/template_muscle.msh the muscle tets
///     DIR/samples/sample_NNNNNN.npz   one sample: parameters (20, parameters.hpp), expression (E),
///                                     skin and skin_at_rest (#skin×3), iterations, seconds,
///                                     inverted_tets, newton_fallbacks
///     DIR/samples/sample_NNNNNN.failed.json  a sample no solver converged: left out, its
///                                     parameters, expression and error (skip_unconverged)
///     DIR/softdeca_samples.npz        all of them: parameters N×20, parameter_names, expressions
///                                     N×E, expression_names, skin and skin_at_rest N×#skin×3,
///                                     rest_skin #skin×3 (the template's), seconds N (each
///                                     sample's simulation), sample_index N (which samples),
///                                     failed_samples (those left out), fingerprint
///     DIR/softdeca_data.json          template sizes, options, per-sample iterations and seconds
///
/// read_softdeca_dataset() (softdeca_dataset.hpp) reads softdeca_samples.npz back (the surrogate's
/// input, nn/softdeca_surrogate.hpp).
///
/// Sample i's parameters and expression depend on (seed, i) alone, and each sample file is written
/// atomically when its simulation ends, so a killed run resumes at the first missing sample and
/// produces what an uninterrupted run would. A sample file from another run (other template,
/// options, stiffness or seed: its fingerprint differs) is an Error naming it, never mixed in.
///
/// Expressions: `active_expressions` of the template's expressions, chosen at random, each with a
/// weight uniform in (0, 1] (sparse mixtures, as faces activate few muscles at once).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../../core/error.hpp"
#include "../../core/fingerprint.hpp"
#include "../../core/parallel.hpp"
#include "../../core/work_shard.hpp"
#include "../../io/atomic_file.hpp"
#include "../../io/detail/text_reader.hpp"
#include "../../io/mesh_io.hpp"
#include "../../io/npz.hpp"
#include "parameters.hpp"
#include "softdeca_dataset.hpp"
#include "softdeca_simulator.hpp"
#include "template.hpp"

namespace simsr::scenario {

/// What a SoftDECA datagen run is asked for.
struct SoftDecaDatagenOptions {
  Index samples = 100;
  std::uint64_t seed = 1;
  /// Expressions mixed per sample; unset: 3, or all of a template that has fewer (the sphere's 2).
  std::optional<Index> active_expressions;
  SoftDecaSimulationOptions simulation;
  SoftDecaStiffness stiffness;
  SoftDecaRanges ranges;
  /// A sample that neither solver brings to the tolerance (local–global, then Newton from where
  /// it stopped: SoftDecaSimulationOptions::newton_fallback) is left out and reported: its
  /// DIR/samples/sample_NNNNNN.failed.json holds the parameters and the error, the summary lists
  /// it, and softdeca_samples.npz's `sample_index` names the samples it holds. False: such a
  /// sample stops the run with the error.
  bool skip_unconverged = true;
  /// The samples this process simulates: shard `index` of `count`, a contiguous block
  /// (WorkShard::range). With more than one shard the call simulates (or finds) its block's
  /// per-sample files only and returns its part of the report; the data set's files
  /// (softdeca_samples.npz, softdeca_data.json) are written by a call for the whole run once every
  /// shard is done, which then finds every sample's file (simsr::mpi::generate_softdeca_dataset
  /// does both). Not part of the fingerprint: the samples are the same for any split.
  WorkShard shard;
};

/// Expression weights of sample `index` (see the file comment): E weights, `active` of them in (0, 1].
inline VecX<> sample_expression_weights(std::uint64_t seed, std::uint64_t index, Index E, Index active) {
  if (E < 1 || active < 0 || active > E)
    throw ArgumentError("sample_expression_weights: need 0 <= active <= E and E >= 1 (got " + std::to_string(active) + " of " + std::to_string(E) + ")");
  std::seed_seq seq{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(index), std::uint32_t(index >> 32), std::uint32_t(0xe4e55105)};
  std::mt19937_64 rng(seq);
  std::vector<Index> order(static_cast<std::size_t>(E));
  for (Index e = 0; e < E; ++e) order[std::size_t(e)] = e;
  std::shuffle(order.begin(), order.end(), rng);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  VecX<> w = VecX<>::Zero(E);
  for (Index k = 0; k < active; ++k) w[order[std::size_t(k)]] = 1.0 - u(rng);  // (0, 1]
  return w;
}

/// A template's sizes as reported in softdeca_data.json (the supplement's Table 1 counts and ours).
inline nlohmann::ordered_json softdeca_template_sizes(const SoftDecaTemplate& tpl) {
  const LayeredHead& h = tpl.head;
  return {{"wrap_vertices", h.wrap_vertices},
          {"wrap_triangles", h.outer_triangles.rows()},
          {"skin_vertices", tpl.skin.size()},
          {"skin_triangles", tpl.skin_triangles.rows()},
          {"layers_per_shell", h.layers},
          {"vertices", h.mesh.num_vertices()},
          {"tets", h.mesh.num_tets()},
          {"soft_tissue_tets", h.count(TissueLayer::soft_tissue)},
          {"muscle_tets", h.count(TissueLayer::muscle)},
          {"cranium_vertices", h.count(Bone::cranium)},
          {"jaw_vertices", h.count(Bone::jaw)},
          {"neck_vertices", h.count(Bone::neck)},
          {"thinned_vertices", h.repaired_vertices},
          {"pinched_vertices", h.collapsed_vertices},
          {"expressions", tpl.expression_names.size()}};
}

namespace detail {
inline std::string sample_file_name(Index i, const char* suffix = ".npz") {
  char buf[48];
  std::snprintf(buf, sizeof buf, "sample_%06lld%s", static_cast<long long>(i), suffix);
  return buf;
}
}  // namespace detail

/// Runs (or resumes) a SoftDECA datagen on `tpl` into `dir` (see the file comment); `name`
/// names the template in the JSON summary, `say` gets one progress line per sample. Returns the
/// JSON summary it also writes. `Simulator`: the SoftDecaSimulator, or BasicSoftDecaSimulator with
/// another linear solver (physics::CholmodCholesky: the same results to round-off, faster at the
/// ICT template's size).
template <class Simulator = SoftDecaSimulator, exec::HostPolicy P>
nlohmann::ordered_json generate_softdeca_dataset(P policy, const SoftDecaTemplate& tpl, const std::string& name, const SoftDecaDatagenOptions& o,
                                                 const std::filesystem::path& dir, const std::function<void(const std::string&)>& say = {}) {
  namespace fs = std::filesystem;
  if (o.samples < 1) throw ArgumentError("softdeca datagen: samples must be >= 1, got " + std::to_string(o.samples));
  const Index E = Index(tpl.expression_names.size());
  if (tpl.expression_deltas.rows() != E || tpl.expression_deltas.cols() != 3 * tpl.skin.size())
    throw ShapeError("softdeca datagen: the template's expression displacements", {E, 3 * tpl.skin.size()},
                     {tpl.expression_deltas.rows(), tpl.expression_deltas.cols()});
  const Index active = o.active_expressions.value_or(std::min<Index>(3, E));
  if (active < 0 || active > E)
    throw ArgumentError("softdeca datagen: active expressions must be in [0, " + std::to_string(E) + "] (the template's), got " +
                        std::to_string(active));
  o.shard.check("softdeca datagen");
  const auto [first, last] = o.shard.range(o.samples);
  const auto t0 = std::chrono::steady_clock::now();
  const auto tell = [&](const std::string& s) {
    if (say) say(s);
  };
  fs::create_directories(dir / "samples");
  const LayeredHead& h = tpl.head;
  const Index M = tpl.skin.size();
  const nlohmann::ordered_json sizes = softdeca_template_sizes(tpl);
  tell("template " + name + ": " + sizes.dump());

  // the template's files (one shard writes them: the same bytes from every process)
  if (o.shard.index == 0) {
    std::vector<VIndex> local(std::size_t(h.mesh.num_vertices()), -1);
    io::MeshData<double> skin;
    skin.V.resize(M, 3);
    for (Index k = 0; k < M; ++k) {
      local[std::size_t(tpl.skin[k])] = VIndex(k);
      skin.V.row(k) = h.mesh.V.row(tpl.skin[k]);
    }
    skin.F.resize(tpl.skin_triangles.rows(), 3);
    for (Index f = 0; f < skin.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) skin.F(f, c) = local[std::size_t(tpl.skin_triangles(f, c))];
    io::write_mesh(dir / "template_skin.obj", skin);
    for (const auto& [name, layer] : {std::pair{"template_soft_tissue.msh", TissueLayer::soft_tissue}, std::pair{"template_muscle.msh", TissueLayer::muscle}}) {
      const TetMesh<> m = h.layer_mesh(layer);
      io::MeshData<double> d;
      d.V = m.V;
      d.T = m.T;
      io::write_mesh(dir / name, d);
    }
  }

  // what makes a sample file this run's
  Fingerprint fp;
  fp.add(h.mesh.V).add(h.mesh.T).add(tpl.expression_deltas).add(o.seed).add(active).add(o.simulation.steps).add(o.simulation.time_step)
      .add(o.simulation.relative_tolerance).add(int(o.simulation.solver)).add(o.simulation.history);
  const nlohmann::ordered_json stiffness = o.stiffness.to_json();  // kept: a range-for over a temporary's items() dangles
  for (const auto& [k, v] : stiffness.items()) fp.add(double(v));
  for (double r : {o.ranges.weight_min, o.ranges.weight_max, o.ranges.volume_min, o.ranges.volume_max, o.ranges.strain_min, o.ranges.strain_max,
                   o.ranges.gravity_min, o.ranges.gravity_max, o.ranges.scale_min, o.ranges.scale_max, o.ranges.dynamics_min, o.ranges.dynamics_max})
    fp.add(r);
  const std::string print = fp.hex();

  Simulator sim(tpl, o.stiffness);
  Eigen::MatrixXd params(o.samples, SoftDecaParameters::size), expressions(o.samples, E);
  std::vector<Points<>> skins(static_cast<std::size_t>(o.samples)), rests(static_cast<std::size_t>(o.samples));
  nlohmann::ordered_json per_sample = nlohmann::ordered_json::array();
  VecX<> seconds(o.samples);
  Index simulated = 0, resumed = 0;
  double sim_seconds = 0;
  std::vector<Index> kept, failed;
  const auto foreign = [](const fs::path& f) {
    throw Error("softdeca datagen: " + f.string() + " is from another run (its template, options or seed differ): move it away or use another --out");
  };
  for (Index i = 0; i < o.samples; ++i) {
    const fs::path file = dir / "samples" / detail::sample_file_name(i), failed_file = dir / "samples" / detail::sample_file_name(i, ".failed.json");
    const SoftDecaParameters p = sample_softdeca_parameters(o.seed, std::uint64_t(i), o.ranges);
    const VecX<> w = sample_expression_weights(o.seed, std::uint64_t(i), E, active);
    params.row(i) = p.to_vector().transpose();
    expressions.row(i) = w.transpose();
    if (i < first || i >= last) continue;  // another shard's
    if (fs::exists(file)) {
      const io::NpzArrays z = io::read_npz(file);
      if (!z.contains("fingerprint") || z.at("fingerprint").to_strings() != std::vector<std::string>{print})
        foreign(file);
      skins[std::size_t(i)] = z.at("skin").to_points();
      rests[std::size_t(i)] = z.at("skin_at_rest").to_points();
      if (skins[std::size_t(i)].rows() != M || rests[std::size_t(i)].rows() != M)
        throw Error("softdeca datagen: " + file.string() + ": skin has " + std::to_string(skins[std::size_t(i)].rows()) + " vertices, the template " + std::to_string(M));
      seconds[i] = z.at("seconds").item<double>();
      per_sample.push_back({{"sample", i}, {"resumed", true}, {"seconds", seconds[i]}});
      ++resumed;
      kept.push_back(i);
      continue;
    }
    if (fs::exists(failed_file)) {  // left out by an earlier run: the same again
      nlohmann::json f;
      try {
        f = nlohmann::json::parse(io::detail::read_text_file(failed_file));
      } catch (const nlohmann::json::exception& e) {
        throw ParseError(failed_file.string(), 0, e.what());
      }
      if (!f.contains("fingerprint") || f["fingerprint"] != print)
        foreign(failed_file);
      failed.push_back(i);
      per_sample.push_back({{"sample", i}, {"resumed", true}, {"failed", f.value("error", "")}});
      ++resumed;
      continue;
    }
    SoftDecaResult r;
    try {
      r = sim.simulate(policy, p, w, o.simulation);
    } catch (const ConvergenceError& e) {
      const std::string what = "softdeca datagen: sample " + std::to_string(i) + " (" + p.to_json().dump() + "): " + e.what();
      if (!o.skip_unconverged) throw Error(what);
      nlohmann::ordered_json f{{"sample", i}, {"parameters", p.to_json()}, {"expression", std::vector<double>(w.data(), w.data() + w.size())},
                               {"error", e.what()}, {"fingerprint", print}};
      io::write_file_atomic(failed_file, f.dump(2) + "\n");
      failed.push_back(i);
      per_sample.push_back({{"sample", i}, {"failed", e.what()}});
      tell("sample " + std::to_string(i + 1) + "/" + std::to_string(o.samples) + ": no convergence, left out (" + failed_file.filename().string() + "): " + e.what());
      continue;
    } catch (const Error& e) {
      throw Error("softdeca datagen: sample " + std::to_string(i) + " (" + p.to_json().dump() + "): " + e.what());
    }
    skins[std::size_t(i)] = r.skin;
    seconds[i] = r.seconds;
    rests[std::size_t(i)] = r.skin_at_rest;
    io::NpzArrays z;
    z["parameters"] = io::make_npy(p.to_vector());
    z["expression"] = io::make_npy(w);
    z["skin"] = io::make_npy(r.skin);
    z["skin_at_rest"] = io::make_npy(r.skin_at_rest);
    std::vector<std::int64_t> its(r.iterations.begin(), r.iterations.end());
    z["iterations"] = io::make_npy<std::int64_t>({std::int64_t(its.size())}, its.data());
    z["seconds"] = io::make_npy<double>({}, &r.seconds);
    z["inverted_tets"] = io::make_npy<std::int64_t>({}, &r.inverted_tets);
    z["newton_fallbacks"] = io::make_npy<std::int64_t>({}, &r.newton_fallbacks);
    z["fingerprint"] = io::make_npy(std::vector<std::string>{print});
    io::write_npz(file, z);
    kept.push_back(i);
    ++simulated;
    sim_seconds += r.seconds;
    per_sample.push_back({{"sample", i}, {"iterations", r.iterations}, {"seconds", r.seconds}, {"inverted_tets", r.inverted_tets},
                          {"newton_fallbacks", r.newton_fallbacks}});
    const double mean = sim_seconds / double(simulated);
    char line[256];
    std::snprintf(line, sizeof line, "sample %lld/%lld: %lld iterations%s, %.1f s (%.1f s/sample, ETA %.0f s)", static_cast<long long>(i + 1),
                  static_cast<long long>(o.samples), static_cast<long long>(r.total_iterations()),
                  r.newton_fallbacks > 0 ? (" (" + std::to_string(r.newton_fallbacks) + " solve(s) finished by Newton)").c_str() : "", r.seconds, mean,
                  mean * double(last - i - 1));  // this shard's samples left
    tell(line);
  }

  if (!o.shard.whole()) {  // this shard's part: the data set's files are the whole run's call's
    nlohmann::ordered_json part;
    part["scenario"] = "softdeca";
    part["shard"] = {{"index", o.shard.index}, {"count", o.shard.count}, {"first_sample", first}, {"last_sample", last}};
    part["simulated"] = simulated;
    part["resumed"] = resumed;
    part["failed_samples"] = failed;
    part["seconds_simulating"] = sim_seconds;
    part["fingerprint"] = print;
    part["per_sample"] = per_sample;
    return part;
  }
  if (kept.empty()) throw Error("softdeca datagen: no sample converged (" + std::to_string(failed.size()) + " left out: DIR/samples/*.failed.json)");
  const Index K = Index(kept.size());
  Eigen::MatrixXd kept_params(K, SoftDecaParameters::size), kept_expressions(K, E);
  std::vector<Points<>> kept_skins, kept_rests;
  VecX<> kept_seconds(K);
  for (Index k = 0; k < K; ++k) {
    const Index i = kept[std::size_t(k)];
    kept_params.row(k) = params.row(i);
    kept_expressions.row(k) = expressions.row(i);
    kept_skins.push_back(std::move(skins[std::size_t(i)]));
    kept_rests.push_back(std::move(rests[std::size_t(i)]));
    kept_seconds[k] = seconds[i];
  }
  if (!failed.empty())
    tell(std::to_string(failed.size()) + " of " + std::to_string(o.samples) + " samples did not converge and are left out (listed in softdeca_data.json)");
  io::NpzArrays all;
  all["parameters"] = io::make_npy(kept_params);
  all["parameter_names"] = io::make_npy(SoftDecaParameters::names());
  all["expressions"] = io::make_npy(kept_expressions);
  all["expression_names"] = io::make_npy(tpl.expression_names);
  all["skin"] = io::make_npy_frames(kept_skins);
  all["skin_at_rest"] = io::make_npy_frames(kept_rests);
  std::vector<std::int64_t> kept64(kept.begin(), kept.end()), failed64(failed.begin(), failed.end());
  all["sample_index"] = io::make_npy<std::int64_t>({std::int64_t(K)}, kept64.data());
  all["failed_samples"] = io::make_npy<std::int64_t>({std::int64_t(failed64.size())}, failed64.data());
  Points<> rest_skin(M, 3);
  for (Index k = 0; k < M; ++k) rest_skin.row(k) = h.mesh.V.row(tpl.skin[k]);
  all["rest_skin"] = io::make_npy(rest_skin);
  all["seconds"] = io::make_npy(kept_seconds);
  all["fingerprint"] = io::make_npy(std::vector<std::string>{print});
  io::write_npz(dir / "softdeca_samples.npz", all);

  nlohmann::ordered_json j;
  j["scenario"] = "softdeca";
  j["template_name"] = name;
  j["template"] = sizes;
  j["samples"] = o.samples;
  j["simulated"] = simulated;
  j["resumed"] = resumed;
  j["kept"] = K;
  j["failed_samples"] = failed;
  j["seed"] = o.seed;
  j["active_expressions"] = active;
  j["solver"] = o.simulation.solver == SoftDecaSolver::newton ? "newton" : "local_global";
  j["steps"] = o.simulation.steps;
  j["time_step"] = o.simulation.time_step;
  j["max_iterations"] = o.simulation.max_iterations;
  j["newton_iterations"] = o.simulation.newton_iterations;
  j["stiffness"] = o.stiffness.to_json();
  j["seconds_simulating"] = sim_seconds;
  j["seconds_total"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  j["fingerprint"] = print;
  j["per_sample"] = per_sample;
  io::write_file_atomic(dir / "softdeca_data.json", j.dump(2) + "\n");
  return j;
}

}  // namespace simsr::scenario
