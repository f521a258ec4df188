#pragma once
/// \file
/// The whole face data set in one call (what `simsr datagen --scenario face` and `simsr demo`
/// run): the anatomical model from the ICT kit, every performance simulated at both resolutions
/// (resumed and reused as face_datagen.hpp says), the VTU series for ParaView and the §5.3
/// unseen-force LR frames; DIR/face_data.json summarizes it. Progress (frames/s, ETA) goes to the
/// log, one line per frame.
///
///     scenario::FaceDatasetOptions o;  o.kit = "../shared/data/ict_face";
///     auto report = scenario::generate_face_dataset(exec::omp, o, "out/face_data", log);

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../../core/work_shard.hpp"
#include "../../io/atomic_file.hpp"
#include "face_datagen.hpp"
#include "face_model.hpp"
#include "face_views.hpp"
#include "ict_kit.hpp"
#include "performances.hpp"
#include "unseen_forces.hpp"

namespace simsr::scenario {

/// What a face data set is made of.
struct FaceDatasetOptions {
  std::filesystem::path kit = "../shared/data/ict_face";
  FaceModelOptions model = face_model_preset("default");
  std::vector<std::string> performances{"amazement", "anger", "fear", "pain"};  ///< built-in ones
  std::vector<std::filesystem::path> controls;  ///< controls files, each simulated as a performance
  Index frames = 120;                           ///< per built-in performance
  std::uint64_t seed = 1;                       ///< of the built-in performances
  Index checkpoint_every = 10;
  /// Contiguous chunks per performance (FaceDatagenOptions::chunks; face_datagen.hpp's file
  /// comment): 0 chooses ⌈shards / performances⌉, so that every process of a shared run has work
  /// (1 in one process).
  Index chunks = 0;
  Index chunk_overlap = 2;                      ///< lead-in frames before each later chunk
  Index vtk_every = 10;                         ///< VTU series of every n-th frame (0: none)
  bool unseen_forces = true;                    ///< the LR-only §5.3 sequences in DIR/unseen/
  Index unseen_frames = 40;
};

/// The names of the performances `o` asks for, in the order they are simulated.
inline std::vector<std::string> face_performance_names(const FaceDatasetOptions& o) {
  std::vector<std::string> names = o.performances;
  for (const auto& c : o.controls) names.push_back(performance_name_of(c));
  return names;
}

/// What the three steps of a data set share: the model and the performances, built once.
struct FaceDatasetParts {
  FaceModel face;
  std::vector<Performance> performances;
  std::chrono::steady_clock::time_point started;
};

/// Step 1: reads the kit, builds the model (tetgen works in `mesh_dir`, default out/mesh) and the
/// performances `o` asks for.
template <exec::HostPolicy P>
FaceDatasetParts prepare_face_dataset(P policy, const FaceDatasetOptions& o, const std::filesystem::path& out,
                                      const std::function<void(const std::string&)>& log = {}, const std::filesystem::path& mesh_dir = {}) {
  using clock = std::chrono::steady_clock;
  FaceDatasetParts parts;
  parts.started = clock::now();
  char buf[512];
  const auto kit = read_ict_kit(o.kit);
  if (log) log("datagen: building the face model (tetgen, lattice, muscles)...");
  parts.face = build_face_model(policy, kit, o.model, mesh_dir.empty() ? out / "mesh" : mesh_dir);
  const FaceModel& face = parts.face;
  std::snprintf(buf, sizeof buf, "datagen: HR %lld tets, LR %lld tets (%.1fx), surface %lld vertices; built in %.1f s", (long long)face.hr.num_tets(),
                (long long)face.lr.num_tets(), double(face.hr.num_tets()) / double(face.lr.num_tets()), (long long)face.surface.num_vertices(),
                std::chrono::duration<double>(clock::now() - parts.started).count());
  if (log) log(buf);
  PerformanceOptions po;
  po.frames = o.frames;
  for (const auto& name : o.performances) parts.performances.push_back(builtin_performance(name, face.expression_names, o.seed, po));
  for (const auto& file : o.controls) parts.performances.push_back(read_controls(file, performance_name_of(file)));
  return parts;
}

/// The chunks per performance a run of `o` over `shards` processes uses: o.chunks, or when it is 0
/// as many as give every process a unit (chunks_for_shards).
inline Index face_dataset_chunks(const FaceDatasetOptions& o, const FaceDatasetParts& parts, Index shards) {
  if (o.chunks < 0) throw ArgumentError("face datagen: chunks = " + std::to_string(o.chunks) + " (need >= 1, or 0 to choose)");
  return o.chunks > 0 ? o.chunks : chunks_for_shards(shards, Index(parts.performances.size()));
}

/// Step 2: simulates the performances (the block of units `shard` names, or all) into `out`, in
/// face_dataset_chunks(o, parts, shard.count) chunks each, a progress line per frame to `log`
/// (frames/s over this call's frames, ETA over its block).
template <exec::HostPolicy P>
std::vector<PerformanceStats> simulate_face_dataset(P policy, const FaceDatasetParts& parts, const FaceDatasetOptions& o, const std::filesystem::path& out,
                                                    const std::function<void(const std::string&)>& log = {}, WorkShard shard = {}) {
  using clock = std::chrono::steady_clock;
  FaceDatagenOptions opt;
  opt.checkpoint_every = o.checkpoint_every;
  opt.chunks = face_dataset_chunks(o, parts, shard.count);
  opt.chunk_overlap = o.chunk_overlap;
  opt.shard = shard;
  const auto units = face_chunks(parts.performances, opt.chunks, opt.chunk_overlap);
  const auto [first, last] = shard.range(Index(units.size()));
  Index total = 0;
  for (Index u = first; u < last; ++u) total += units[std::size_t(u)].last - units[std::size_t(u)].lead_in;
  Index done = 0;
  const auto start = clock::now();
  auto progress = [&](const char* what, const std::string& perf, Index f, Index F, const physics::NewtonReport& rl, const physics::NewtonReport& rh, double sl,
                      double sh) {
    ++done;
    if (!log) return;
    const double el = std::chrono::duration<double>(clock::now() - start).count();
    const double fps = double(done) / el;
    const double eta = double(total - done) / fps;  // an upper bound: resumed frames are not simulated
    char buf[512];
    std::snprintf(buf, sizeof buf, "datagen: %-10s %s %4lld/%lld | %.2f frames/s | LR %lld it %.2f s | HR %lld it %.2f s | ETA %d:%02d", perf.c_str(), what,
                  (long long)f + 1, (long long)F, fps, (long long)rl.iterations, sl, (long long)rh.iterations, sh, int(eta) / 60, int(eta) % 60);
    log(buf);
  };
  opt.on_frame = [&](const std::string& perf, Index f, Index F, const physics::NewtonReport& rl, const physics::NewtonReport& rh, double sl, double sh) {
    progress("frame", perf, f, F, rl, rh, sl, sh);
  };
  // "lead-in 3/5": frame 3 solved before the chunk that starts at frame 5 (index 4)
  opt.on_lead_in = [&](const std::string& perf, Index f, Index first_frame, const physics::NewtonReport& rl, const physics::NewtonReport& rh, double sl,
                       double sh) { progress("lead-in", perf, f, first_frame + 1, rl, rh, sl, sh); };
  return generate_face_data(policy, parts.face, parts.performances, out, opt);
}

/// Step 3: the VTU series, the unseen-force frames and the summary (out/face_data.json, returned)
/// from the stats of every performance; `extra`'s fields are added to the summary before it is
/// written (the MPI layer's `ranks`).
template <exec::HostPolicy P>
nlohmann::ordered_json finish_face_dataset(P policy, const FaceDatasetParts& parts, const std::vector<PerformanceStats>& stats, const FaceDatasetOptions& o,
                                           const std::filesystem::path& out, const std::function<void(const std::string&)>& log = {},
                                           const nlohmann::ordered_json& extra = nlohmann::ordered_json::object()) {
  auto say = [&](const std::string& s) {
    if (log) log(s);
  };
  const FaceModel& face = parts.face;
  auto j = face_data_report(face, stats);
  j["chunks_per_performance"] = face_dataset_chunks(o, parts, 1);
  j["chunk_overlap"] = o.chunk_overlap;
  char buf[512];
  for (const auto& s : stats)
    if (s.lip_intersecting_frames) {
      std::snprintf(buf, sizeof buf,
                    "datagen: warning: %s: the HR lips intersect in %lld frames (at most %lld triangle pairs): its controls press them harder than the contact holds",
                    s.name.c_str(), (long long)s.lip_intersecting_frames, (long long)s.lip_max_pairs);
      say(buf);
    }
  if (o.vtk_every > 0) {
    std::vector<std::string> names;
    for (const auto& p : parts.performances) names.push_back(p.name);
    say("datagen: VTU series (every " + std::to_string(o.vtk_every) + " frames) in " + (out / "vtk").string());
    write_face_data_views(policy, face, out, names, o.vtk_every);
  }
  if (o.unseen_forces) {
    say("datagen: the unseen-force frames (LR only: a lip corner pulled, a sphere in the cheek)...");
    UnseenForceOptions uo;
    uo.frames = o.unseen_frames;
    const auto us = generate_unseen_force_frames(policy, face, out, uo);
    j["unseen_forces"] = unseen_force_report(us);
  }
  for (const auto& [key, value] : extra.items()) j[key] = value;
  j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - parts.started).count();
  io::write_file_atomic(out / "face_data.json", j.dump(2) + "\n");
  return j;
}

/// Builds the model, simulates what `o` asks for into `out` and returns the summary (also written
/// to out/face_data.json). `log` receives the progress lines (may be empty). The three steps
/// above in a row; simsr::mpi::generate_face_dataset shares step 2 over ranks.
template <exec::HostPolicy P>
nlohmann::ordered_json generate_face_dataset(P policy, const FaceDatasetOptions& o, const std::filesystem::path& out,
                                             const std::function<void(const std::string&)>& log = {}) {
  const FaceDatasetParts parts = prepare_face_dataset(policy, o, out, log);
  const auto stats = simulate_face_dataset(policy, parts, o, out, log);
  return finish_face_dataset(policy, parts, stats, o, out, log);
}

}  // namespace simsr::scenario
