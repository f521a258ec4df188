#pragma once
/// \file
/// `simsr animate` (core paper §5.1): the face's LR simulation and a trained network run live on
/// performances from controls files, frame after frame, pipelined (live.hpp: the simulation of
/// frame t+1 beside the network on frame t) and, for comparison, unpipelined; writes the HR frames
/// and the LR-simulation, inference and end-to-end frame rates.
///
///     pipeline::AnimateOptions o;
///     o.network = "out/demo/network/model.npz";  o.controls = {"anger_controls.npz"};  o.out = "out/live";
///     auto report = pipeline::animate_face(exec::omp, o, log);          // also OUT/animate.json
///
/// OUT gets, per performance, <name>.npz (lowres and highres frames, the paired layout: `simsr
/// eval` and `infer` read it), vtk/<name>/hr_skin.pvd (every n-th HR frame, its displacement as
/// point data) and animate.json (the figures). The face model is built as datagen builds it (same
/// kit and options, OUT/mesh for tetgen); a network trained on another LR mesh or HR surface is
/// refused. `untrained` times a freshly initialized network of the recipe's architecture on the
/// face model's meshes instead, for meshes no network was trained on (the paper-ratio preset):
/// the frame rates do not depend on the weights (the HR frames are then meaningless).
/// `method = "embedded"` runs Embedded instead of a network: the paper-lr preset's LR mesh has more
/// vertices (16.9k) than the HR surface (9.0k), which the network's §3.2 neighbourhoods (one HR
/// vertex per LR vertex) cannot take, and its LR simulation rate is measured that way.
/// A run takes seconds to minutes and is not resumed: a killed run is run again.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../data/paired_frames.hpp"
#include "../interp/embedded.hpp"
#include "../interp/fit_and_train.hpp"
#include "../interp/learned.hpp"
#include "../interp/network_recipe.hpp"
#include "../io/atomic_file.hpp"
#include "../io/vtu.hpp"
#include "../scenario/face/face_datagen.hpp"
#include "../scenario/face/face_lr_source.hpp"
#include "../scenario/face/ict_kit.hpp"
#include "live.hpp"
#include "stages.hpp"

namespace simsr::pipeline {

struct AnimateOptions {
  std::filesystem::path kit = "../shared/data/ict_face";
  scenario::FaceModelOptions model = scenario::face_model_preset("default");  ///< as the network's data was made
  scenario::FaceSimulationOptions simulation;
  /// What upsamples the LR frames: "network" (a model file, or `untrained`) or "embedded" (the
  /// LR surface itself: no model, no §3.2 neighbourhoods, so it runs at LR sizes the network's
  /// neighbourhoods cannot take: more LR vertices than HR surface vertices, the paper-lr preset).
  std::string method = "network";
  std::filesystem::path network;               ///< a model file (simsr demo / train); empty with `untrained`
  bool untrained = false;                      ///< timing only: a fresh network of `recipe` (file comment)
  interp::NetworkRecipe recipe;                ///< the untrained network's architecture
  Index neighborhood_k = 20;                   ///< the untrained network's §3.2 neighbourhoods
  std::vector<std::filesystem::path> controls; ///< controls files (names C, weights F×C), one performance each
  Index max_frames = 0;                        ///< > 0: only the first that many frames of each performance
  std::filesystem::path out = "out/animate";
  bool unpipelined = true;                     ///< also run unpipelined (the comparison)
  LiveOptions live;                            ///< the pipelined run's thread split
  Index vtk_every = 10;                        ///< HR VTU every n-th frame (0: none)
};

namespace detail {

/// Largest distance between two rest shapes of the same size (rows() checked by the caller).
inline double max_distance(const Points<Scalar>& a, const Points<Scalar>& b) { return (a - b).rowwise().norm().maxCoeff(); }

/// The network: read and checked against the face model's meshes, or fresh (untrained).
template <exec::HostPolicy P>
interp::Learned<> animate_network(P policy, const AnimateOptions& o, const scenario::FaceModel& face) {
  if (o.untrained) {
    auto r = o.recipe;
    if (r.displacement_scale == 0) r.displacement_scale = 1;  // no frames to take it from; the weights are random anyway
    interp::Learned<> net(r.config(), r.seed);
    interp::UpsamplingProblem<> problem{face.lr, face.surface, {}, {}};
    interp::prepare(policy, net, problem, o.neighborhood_k);
    return net;
  }
  auto net = interp::Learned<>::from_model_file(o.network);
  const auto& g = net.model().geometry;
  const double tolerance = 1e-6;  // m: the same mesh rebuilt (bits aside); another mesh differs by millimetres
  auto refuse = [&](const std::string& what, Index want, Index got) {
    throw ArgumentError("animate: " + o.network.string() + " was trained on another " + what + " (" + std::to_string(got) + " vertices; the face model built from " +
                        o.kit.string() + " with these options has " + std::to_string(want) +
                        "): build it with the preset and LR cell its data was made with (simsr datagen --preset / --lr-cell)");
  };
  if (g.lr_rest.rows() != face.lr.num_vertices()) refuse("LR mesh", face.lr.num_vertices(), g.lr_rest.rows());
  if (g.hr_rest.rows() != face.surface.num_vertices()) refuse("HR surface", face.surface.num_vertices(), g.hr_rest.rows());
  if (const double d = max_distance(g.lr_rest, face.lr.V); !(d <= tolerance))
    throw ArgumentError("animate: " + o.network.string() + " was trained on another LR mesh of the same size (rest positions " + std::to_string(d) +
                        " m apart): build the face with the options its data was made with");
  if (const double d = max_distance(g.hr_rest, face.surface.V); !(d <= tolerance))
    throw ArgumentError("animate: " + o.network.string() + " was trained on another HR surface of the same size (rest positions " + std::to_string(d) +
                        " m apart)");
  return net;
}

/// Every performance live with `method`, pipelined and (o.unpipelined) not; its files written and
/// its figures added to report["performances"].
template <exec::HostPolicy P, interp::Interpolator I, class Say>
void animate_performances(P policy, const AnimateOptions& o, const scenario::FaceModel& face, const std::vector<scenario::Performance>& perfs, const I& method,
                          nlohmann::ordered_json& report, const Say& say) {
  using clock = std::chrono::steady_clock;
  char buf[512];
  for (const auto& perf : perfs) {
    const Index F = perf.num_frames(), M = face.surface.num_vertices(), N = face.lr.num_vertices();
    nlohmann::ordered_json pj;
    pj["name"] = perf.name;
    pj["frames"] = F;
    data::PairedFrames<> frames = data::PairedFrames<>::one_sequence(F, N, M, perf.name);
    frames.controls = perf.weights;

    data::FrameMatrix<Scalar> unpiped;
    if (o.unpipelined) {
      say("animate: " + perf.name + ": unpipelined (" + std::to_string(F) + " frames)...");
      scenario::FaceLrSource<> source(policy, face, perf, o.simulation);
      unpiped.resize(F, 3 * M);
      LiveOptions lo = o.live;
      lo.pipelined = false;
      const auto r = run_live(policy, source, method, face.lr.V, face.surface.V, [&](Index f, const Points<Scalar>&, const Points<Scalar>& hr) {
        unpiped.row(f) = Eigen::Map<const Eigen::Matrix<Scalar, 1, Eigen::Dynamic>>(hr.data(), hr.size());
      }, lo);
      pj["unpipelined"] = r.to_json();
      std::snprintf(buf, sizeof buf, "animate: %s unpipelined: LR simulation %.2f fps, inference %.2f fps, end to end %.2f fps", perf.name.c_str(), r.source_fps(),
                    r.method_fps(), r.end_to_end_fps());
      say(buf);
    }
    say("animate: " + perf.name + ": pipelined...");
    scenario::FaceLrSource<> source(policy, face, perf, o.simulation);
    LiveOptions lo = o.live;
    lo.pipelined = true;
    const auto live_start = clock::now();
    const auto r = run_live(policy, source, method, face.lr.V, face.surface.V, [&](Index f, const Points<Scalar>& lr, const Points<Scalar>& hr) {
      frames.lr(f) = lr;
      frames.hr(f) = hr;
      if ((f + 1) % 20 == 0 || f + 1 == F) {
        std::snprintf(buf, sizeof buf, "animate: %s frame %lld/%lld, %.2f fps end to end", perf.name.c_str(), (long long)f + 1, (long long)F,
                      double(f + 1) / std::chrono::duration<double>(clock::now() - live_start).count());
        say(buf);
      }
    }, lo);
    pj["pipelined"] = r.to_json();
    std::snprintf(buf, sizeof buf, "animate: %s pipelined (%d + %d threads): LR simulation %.2f fps, inference %.2f fps, end to end %.2f fps", perf.name.c_str(),
                  r.source_threads, r.method_threads, r.source_fps(), r.method_fps(), r.end_to_end_fps());
    say(buf);
    if (o.unpipelined) {
      // the same frames either way up to the threads' rounding (the simulator's reductions use fixed chunks)
      pj["pipelined_vs_unpipelined_max_difference_m"] = (frames.highres - unpiped).cwiseAbs().maxCoeff();
    }
    const auto file = o.out / (perf.name + ".npz");
    data::write_paired_frames(file, frames);
    pj["frames_file"] = file.string();
    if (o.vtk_every > 0) {
      io::PvdWriter series(o.out / "vtk" / perf.name / "hr_skin.pvd");
      for (Index f = 0; f < F; f += o.vtk_every) {
        const Points<Scalar> x = frames.hr(f);
        io::VtuGrid g;
        g.set_points(x).set_triangles(face.surface.F);
        g.add_point_data("displacement", VecX<double>((x - face.surface.V).rowwise().norm()));
        series.add(double(f), g);
      }
      pj["vtk"] = (o.out / "vtk" / perf.name / "hr_skin.pvd").string();
    }
    report["performances"].push_back(pj);
  }
}

}  // namespace detail

/// Builds the face, runs every performance live (see the file comment) and returns the report
/// (also OUT/animate.json).
template <exec::HostPolicy P>
nlohmann::ordered_json animate_face(P policy, const AnimateOptions& o, const Log& log = {}) {
  using clock = std::chrono::steady_clock;
  auto say = [&](const std::string& s) {
    if (log) log(s);
  };
  if (o.controls.empty()) throw ArgumentError("animate: no controls file (--controls C.npz: names C, weights F×C)");
  if (o.method != "network" && o.method != "embedded") throw ArgumentError("animate: method must be network or embedded (got '" + o.method + "')");
  if (o.method == "embedded" && (o.untrained || !o.network.empty())) throw ArgumentError("animate: embedded takes no model file and is never untrained");
  if (o.method == "network" && o.untrained == !o.network.empty())
    throw ArgumentError(o.untrained ? "animate: a model file and untrained both given: pick one" : "animate: no model file (--model M.npz), and not untrained");
  if (o.max_frames < 0 || o.vtk_every < 0) throw ArgumentError("animate: max frames and the VTU interval must be >= 0");
  std::vector<scenario::Performance> perfs;
  for (const auto& file : o.controls) {
    perfs.push_back(scenario::read_controls(file, scenario::performance_name_of(file)));
    for (std::size_t i = 0; i + 1 < perfs.size(); ++i)
      if (perfs[i].name == perfs.back().name) throw ArgumentError("animate: two controls files name the performance '" + perfs.back().name + "'");
    if (o.max_frames > 0 && perfs.back().num_frames() > o.max_frames) perfs.back().weights.conservativeResize(o.max_frames, Eigen::NoChange);
  }
  if (o.method == "network" && !o.untrained && !std::filesystem::exists(o.network)) throw ParseError(o.network.string(), 0, "no such model file");

  char buf[512];
  const auto t0 = clock::now();
  say("animate: building the face model (tetgen, lattice, muscles)...");
  const auto kit = scenario::read_ict_kit(o.kit);
  const scenario::FaceModel face = scenario::build_face_model(policy, kit, o.model, o.out / "mesh");
  const double model_seconds = std::chrono::duration<double>(clock::now() - t0).count();
  std::snprintf(buf, sizeof buf, "animate: LR %lld tets, %lld vertices; HR surface %lld vertices; built in %.1f s", (long long)face.lr.num_tets(),
                (long long)face.lr.num_vertices(), (long long)face.surface.num_vertices(), model_seconds);
  say(buf);
  nlohmann::ordered_json report;
  report["method"] = o.method;
  report["network"] = o.method == "embedded" ? nlohmann::ordered_json(nullptr)
                      : o.untrained           ? nlohmann::ordered_json("untrained (timing only)")
                                              : nlohmann::ordered_json(o.network.string());
  report["lr"] = {{"tets", face.lr.num_tets()}, {"vertices", face.lr.num_vertices()}, {"lr_cell_cm", o.model.lr_cell}};
  report["hr_surface_vertices"] = face.surface.num_vertices();
  report["threads"] = exec::omp_max_threads();
  report["model_seconds"] = model_seconds;
  std::filesystem::create_directories(o.out);
  const auto t1 = clock::now();
  if (o.method == "embedded") {
    interp::Embedded<> embedded;
    interp::UpsamplingProblem<> problem{face.lr, face.surface, {}, {}};
    embedded.fit(policy, problem);
    report["method_setup_seconds"] = std::chrono::duration<double>(clock::now() - t1).count();
    detail::animate_performances(policy, o, face, perfs, embedded, report, say);
  } else {
    const interp::Learned<> net = detail::animate_network(policy, o, face);
    report["method_setup_seconds"] = std::chrono::duration<double>(clock::now() - t1).count();
    detail::animate_performances(policy, o, face, perfs, net, report, say);
  }
  report["seconds"] = std::chrono::duration<double>(clock::now() - t0).count();
  io::write_file_atomic(o.out / "animate.json", report.dump(2) + "\n");
  return report;
}

}  // namespace simsr::pipeline
