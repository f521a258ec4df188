#pragma once
/// \file
/// Paired face data (core paper §4): every performance simulated at both resolutions from the same
/// controls, written in the layout every simsr command reads (data/paired_frames.hpp):
///
///     DIR/lr_rest.msh            the LR rest mesh (split lattice, m)
///     DIR/hr_rest.obj            the HR rest surface: the face skin, with triangles (m)
///     DIR/hr_volume.msh          the HR conforming tet mesh (for looking at it)
///     DIR/hr_lips.npz            the lips as contact patches of hr_rest.obj (a: upper, b: lower;
///                                data/contact_patches_file.hpp): the contact loss and the
///                                evaluation's intersection count read them
///     DIR/<performance>.npz      lowres F×N×3, highres F×M×3, controls F×C, frame F, sequence
///     DIR/<performance>_controls.npz   the controls alone (names, weights): a controls file
///     DIR/face_data.json         sizes, options, per-performance timings and Newton iterations
///
/// Each frame is a warm-started quasistatic solve at each resolution. Every performance starts
/// from the settled neutral (all controls 0), solved once and kept in DIR/.state. A run checkpoints
/// each performance every `checkpoint_every` frames (DIR/.state/<name>.npz: the frames so far and
/// the last two states of both meshes, atomically), so a killed run resumes where it stopped and
/// loses no finished frame. A frame depends on the two states before it and its controls only
/// (the warm start is restored exactly, the solver keeps no estimates across frames), so a resumed
/// run's frames equal the uninterrupted run's bitwise (tests/scenario/test_face_datagen.cpp;
/// the policies' reductions use fixed chunks). A file from another run (another mesh, options or
/// controls) is refused by fingerprint, never continued. A Newton failure or an inverted tet after a solve is an
/// Error naming the performance, the frame, the resolution and the residual: nothing is written
/// for that frame. Every HR frame's lips are checked by an exact triangle–triangle test
/// (mesh/triangle_intersection.hpp) and counted in the stats and face_data.json: none in the
/// built-in performances (the contact holds the lips apart where the kit's own neutral has them
/// crossing, see face_simulator.hpp); a count, not an error, so that a user's performance that
/// presses the lips harder than the penalty holds is still written and reported.

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../../core/error.hpp"
#include "../../core/fingerprint.hpp"
#include "../../core/parallel.hpp"
#include "../../core/work_shard.hpp"
#include "../../data/contact_patches_file.hpp"
#include "../../data/paired_frames.hpp"
#include "../../data/run_checkpoint.hpp"
#include "../../io/atomic_file.hpp"
#include "../../io/mesh_io.hpp"
#include "../../io/npz.hpp"
#include "../../mesh/triangle_intersection.hpp"
#include "face_model.hpp"
#include "face_simulator.hpp"
#include "performances.hpp"

namespace simsr::scenario {

/// What a datagen run is asked for.
struct FaceDatagenOptions {
  FaceSimulationOptions simulation;
  Index checkpoint_every = 10;  ///< frames between checkpoints of a performance
  /// Called after every frame: performance, frame, frames of it, the two reports, seconds of the
  /// frame (LR, HR). Progress lines and ETA live in the caller.
  std::function<void(const std::string&, Index, Index, const physics::NewtonReport&, const physics::NewtonReport&, double, double)> on_frame;
  /// The performances this process simulates: shard `index` of `count`, a contiguous block of the
  /// list (WorkShard::range); the others are neither simulated nor checked. Each performance
  /// starts from the settled neutral, so a shard's files equal the whole run's bitwise
  /// (simsr::mpi::generate_face_dataset gives each rank one). Not part of any fingerprint.
  WorkShard shard;
};

/// Per-performance figures of a run.
struct PerformanceStats {
  std::string name;
  Index frames = 0;
  double lr_seconds = 0, hr_seconds = 0;   ///< total over the frames simulated in this run
  Index lr_iterations = 0, hr_iterations = 0;
  Index simulated = 0;                     ///< frames simulated in this run (the rest were resumed or reused)
  bool reused = false;                     ///< the finished file was there already
  Index lip_intersecting_frames = 0;       ///< HR frames whose upper and lower lip triangles intersect (all frames: the files keep the counts)
  Index lip_max_pairs = 0;                 ///< the most intersecting triangle pairs in one frame
  /// Fig. 4's discrepancy over all the performance's frames (resumed and reused ones included), m:
  /// the mean distance between the embedded LR surface and the HR surface, and each one's mean
  /// skin displacement from the rest surface (their ratio is the bulk agreement of SPEC §3).
  double lr_hr_mean_distance = 0, hr_mean_displacement = 0, lr_mean_displacement = 0;
};

/// Fills the discrepancy figures of `st` from a performance's frames (LR mesh positions, HR
/// surface positions), each averaged over every surface vertex of every frame.
template <exec::HostPolicy P>
void measure_discrepancy(P policy, const FaceModel& face, const data::PairedFrames<>& frames, PerformanceStats& st) {
  const Index F = frames.num_frames(), M = face.surface.num_vertices();
  if (frames.num_lr() != face.lr.num_vertices() || frames.num_hr() != M)
    throw ShapeError("measure_discrepancy: frames (N, M)", {face.lr.num_vertices(), M}, {frames.num_lr(), frames.num_hr()});
  double dist = 0, hr_disp = 0, lr_disp = 0;
  for (Index f = 0; f < F; ++f) {
    const Points<> lr = deform(policy, face.surface_in_lr, face.lr.T, frames.lr(f));
    const auto hr = frames.hr(f);
    dist += (lr - hr).rowwise().norm().sum();
    hr_disp += (hr - face.surface.V).rowwise().norm().sum();
    lr_disp += (lr - face.surface.V).rowwise().norm().sum();
  }
  const double n = double(F) * double(M);
  st.lr_hr_mean_distance = dist / n;
  st.hr_mean_displacement = hr_disp / n;
  st.lr_mean_displacement = lr_disp / n;
}

/// The pairs (upper lip triangle, lower lip triangle) that intersect at HR positions X, exactly
/// (a 2^-36 m grid, ±4 m).
inline std::vector<std::pair<Index, Index>> intersecting_lip_pairs(const FaceModel& face, const Points<>& X) {
  return intersecting_triangle_pairs(X, face.lip_upper_triangles, face.lip_lower_triangles, 0x1p-36);
}

/// The lips as contact patches of the HR surface (face.surface): its triangles whose three corners
/// are upper-lip (patch a) or lower-lip (patch b) vertices of the model, in the surface's own
/// order and orientation (outward). The HR simulation's contact sets also hold the mouth socket's
/// inner lip triangles, which the surface (the skin super-resolution predicts) does not have.
inline ContactPatches face_lip_patches(const FaceModel& face) {
  const Index M = face.surface.num_vertices();
  std::vector<char> side(std::size_t(face.hr.num_vertices()), 0);
  for (Index i = 0; i < face.lip_upper_vertices.size(); ++i) side[std::size_t(face.lip_upper_vertices[i])] = 1;
  for (Index i = 0; i < face.lip_lower_vertices.size(); ++i) side[std::size_t(face.lip_lower_vertices[i])] = 2;
  std::vector<Index> rows[2];
  for (Index t = 0; t < face.surface.F.rows(); ++t) {
    const char s0 = side[std::size_t(face.surface_hr_vertex[face.surface.F(t, 0)])];
    if (s0 == 0) continue;
    bool same = true;
    for (Index k = 1; k < 3; ++k) same = same && side[std::size_t(face.surface_hr_vertex[face.surface.F(t, k)])] == s0;
    if (same) rows[s0 - 1].push_back(t);
  }
  ContactPatches p;
  Tris* out[2] = {&p.a, &p.b};
  for (int s = 0; s < 2; ++s) {
    out[s]->resize(Index(rows[s].size()), 3);
    for (std::size_t i = 0; i < rows[s].size(); ++i) out[s]->row(Index(i)) = face.surface.F.row(rows[s][i]);
  }
  p.check(M, "face_lip_patches");
  return p;
}

namespace detail {

/// The fingerprint of everything a frame depends on: meshes, options, controls.
inline std::string face_run_fingerprint(const FaceModel& face, const FaceSimulationOptions& o, const Performance* p) {
  Fingerprint f;
  f.add(face.hr.V).add(face.hr.T).add(face.lr.V).add(face.lr.T).add(face.surface.F);
  f.add(face.hr_bone).add(face.hr_bone_jaw).add(face.lr_bone).add(face.lr_bone_jaw).add(face.hinge.point).add(face.hinge.axis).add(face.hinge.angle);
  for (const auto& m : face.muscles) {
    f.add_bytes(m.spec.name.data(), m.spec.name.size()).add(m.insertion).add(m.origin).add(m.ring).add(m.spec.radius);
    for (const auto& d : m.spec.drivers) f.add_bytes(d.expression.data(), d.expression.size()).add(d.gain);
  }
  f.add(o.inversion_threshold).add(o.mu10).add(o.mu01).add(o.kappa).add(o.muscle_max_stress).add(o.track_stiffness).add(o.contact_stiffness).add(o.contact_thickness);
  f.add(o.contact_rest_fraction).add(o.newton.relative_tolerance).add(o.newton.absolute_tolerance).add(o.newton.max_iterations).add(o.linear.tolerance).add(std::int64_t(o.extrapolate));
  f.add(o.substep_levels).add(std::int64_t(o.carry_with_jaw));
  if (p) {
    f.add(p->weights);
    for (const auto& n : p->names) f.add_bytes(n.data(), n.size());
  }
  return f.hex();
}


/// A file's per-frame counts of intersecting HR lip triangle pairs (`hr_lip_pairs`, `frames` of
/// them, each ≥ 0); ArgumentError naming the file otherwise.
inline std::vector<std::int64_t> lip_pairs_of(const io::NpzArrays& z, Index frames, const std::string& file) {
  if (!z.contains("hr_lip_pairs")) throw ArgumentError(file + ": no 'hr_lip_pairs' array");
  const io::NpyArray& a = z.at("hr_lip_pairs");
  const auto v = a.to_vector<std::int64_t>();
  if (a.ndim() != 1 || Index(v.size()) != frames)
    throw ArgumentError(file + ": 'hr_lip_pairs' has " + std::to_string(v.size()) + " entries, not one per frame (" + std::to_string(frames) + ")");
  for (std::size_t f = 0; f < v.size(); ++f)
    if (v[f] < 0) throw ArgumentError(file + ": 'hr_lip_pairs' is negative at frame " + std::to_string(f));
  return v;
}

/// The stats' lip figures from per-frame counts.
inline void count_lip_frames(const std::vector<std::int64_t>& pairs, PerformanceStats& st) {
  st.lip_intersecting_frames = Index(std::count_if(pairs.begin(), pairs.end(), [](std::int64_t n) { return n > 0; }));
  st.lip_max_pairs = pairs.empty() ? 0 : Index(*std::max_element(pairs.begin(), pairs.end()));
}

/// One resolution's Newton solve with the failure made specific.
template <class P, class Sim>
physics::NewtonReport solve_frame(P policy, Sim& sim, const std::string& perf, Index frame) {
  physics::NewtonReport r;
  try {
    r = sim.step(policy);
  } catch (const ConvergenceError& e) {
    throw Error("face datagen: performance '" + perf + "', frame " + std::to_string(frame) + ", " + resolution_name(sim.resolution()) +
                " solve failed: " + e.what());
  }
  if (const Index inv = sim.count_inverted(policy))
    throw Error("face datagen: performance '" + perf + "', frame " + std::to_string(frame) + ", " + resolution_name(sim.resolution()) + ": " +
                std::to_string(inv) + " tets inverted after the solve (residual " + std::to_string(r.gradient_norm) + ")");
  return r;
}

}  // namespace detail

/// Writes the rest shapes (atomically) to `dir`.
inline void write_face_rest_shapes(const FaceModel& face, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  io::MeshData<double> lr, hrv, hrs;
  lr.V = face.lr.V;
  lr.T = face.lr.T;
  hrv.V = face.hr.V;
  hrv.T = face.hr.T;
  hrs.V = face.surface.V;
  hrs.F = face.surface.F;
  io::write_mesh(dir / "lr_rest.msh", lr);
  io::write_mesh(dir / "hr_volume.msh", hrv);
  io::write_mesh(dir / "hr_rest.obj", hrs);
  data::write_contact_patches(dir / "hr_lips.npz", face_lip_patches(face), face.surface.num_vertices());
}

/// Simulates `performances` on `face` into `dir` (see the file comment), or the block of them
/// `opt.shard` names. Returns the figures of this run, one per performance simulated or reused.
template <class Linear = physics::ConjugateGradient<physics::Multigrid<>>, exec::HostPolicy P>
std::vector<PerformanceStats> generate_face_data(P policy, const FaceModel& face, const std::vector<Performance>& performances,
                                                 const std::filesystem::path& dir, const FaceDatagenOptions& opt = {}) {
  if (opt.checkpoint_every < 1) throw ArgumentError("generate_face_data: checkpoint_every must be ≥ 1");
  opt.shard.check("generate_face_data");
  const auto [first_performance, last_performance] = opt.shard.range(Index(performances.size()));
  const std::vector<Performance> mine(performances.begin() + first_performance, performances.begin() + last_performance);
  const auto state = dir / ".state";
  // every performance checked, and another run's checkpoint refused, before anything is written
  // or solved; the checkpoints read here are the ones resumed below
  std::vector<std::string> prints;
  std::vector<std::optional<io::NpzArrays>> checkpoints;
  for (const auto& p : mine) {
    if (p.name.empty() || p.name.find_first_of("/\\. ") != std::string::npos)
      throw ArgumentError("generate_face_data: performance name '" + p.name + "' cannot be a file name");
    if (p.num_frames() < 1) throw ArgumentError("generate_face_data: performance '" + p.name + "' has no frames");
    prints.push_back(detail::face_run_fingerprint(face, opt.simulation, &p));
    const auto partial = state / (p.name + ".npz");
    checkpoints.emplace_back();
    if (!std::filesystem::exists(partial)) continue;
    checkpoints.back() = io::read_npz(partial);
    if (io::fingerprint_of(*checkpoints.back()) != prints.back())
      throw ArgumentError(partial.string() + " is a checkpoint of another run (other meshes, options or controls): remove it or use another directory");
  }
  if (mine.empty()) return {};  // a shard with no performance (more shards than performances)
  std::filesystem::create_directories(state);
  write_face_rest_shapes(face, dir);
  const std::string model_print = detail::face_run_fingerprint(face, opt.simulation, nullptr);

  FaceSimulator<Linear> lr(policy, face, FaceResolution::low, opt.simulation);
  FaceSimulator<Linear> hr(policy, face, FaceResolution::high, opt.simulation);

  // the settled neutral, shared by every performance's first frame
  Points<> lr_neutral, hr_neutral;
  const auto neutral_file = state / "neutral.npz";
  bool have_neutral = false;
  if (std::filesystem::exists(neutral_file)) {
    const auto z = io::read_npz(neutral_file);
    if (io::fingerprint_of(z) == model_print) {
      lr_neutral = io::points_of(z, "lr", face.lr.num_vertices(), neutral_file.string());
      hr_neutral = io::points_of(z, "hr", face.hr.num_vertices(), neutral_file.string());
      have_neutral = true;
    }
  }
  const FaceControls zero = neutral_controls(face);
  if (!have_neutral) {
    lr.set_controls(zero);
    hr.set_controls(zero);
    detail::solve_frame(policy, lr, "neutral", 0);
    detail::solve_frame(policy, hr, "neutral", 0);
    lr_neutral = lr.positions();
    hr_neutral = hr.positions();
    io::NpzArrays z;
    z["lr"] = io::make_npy(lr_neutral);
    z["hr"] = io::make_npy(hr_neutral);
    io::set_fingerprint(z, model_print);
    io::write_npz(neutral_file, z);
  }

  std::vector<PerformanceStats> stats;
  for (std::size_t pi = 0; pi < mine.size(); ++pi) {
    const Performance& perf = mine[pi];
    const Index F = perf.num_frames(), N = face.lr.num_vertices(), M = face.surface.num_vertices();
    PerformanceStats st;
    st.name = perf.name;
    st.frames = F;
    const std::string& print = prints[pi];
    const auto final_file = dir / (perf.name + ".npz");
    const auto partial = state / (perf.name + ".npz");
    // a finished file of this very run: reuse
    if (std::filesystem::exists(final_file)) {
      const auto z = io::read_npz(final_file);
      if (io::fingerprint_of(z) == print) {
        st.reused = true;
        detail::count_lip_frames(detail::lip_pairs_of(z, F, final_file.string()), st);
        measure_discrepancy(policy, face, data::read_paired_frames(final_file, N, M), st);
        stats.push_back(st);
        continue;
      }
    }
    data::PairedFrames<> out = data::PairedFrames<>::one_sequence(F, N, M, perf.name);
    out.controls = perf.weights;
    Index start = 0;
    std::vector<std::int64_t> lip_pairs(std::size_t(F), 0);  // per frame: intersecting lip triangle pairs at HR
    // positions are taken as solved under the controls set before them (continuation walks from
    // those): the neutral under zero controls, a checkpoint under its last frame's
    lr.set_controls(zero);
    hr.set_controls(zero);
    lr.set_positions(lr_neutral);
    hr.set_positions(hr_neutral);
    if (checkpoints[pi]) {
      const io::NpzArrays& z = *checkpoints[pi];
      start = data::resume_frames(z, partial.string(), out);
      const auto lips = detail::lip_pairs_of(z, start, partial.string());
      std::copy(lips.begin(), lips.end(), lip_pairs.begin());
      const Points<> lx = io::points_of(z, "lr_state", N, partial.string()), hx = io::points_of(z, "hr_state", face.hr.num_vertices(), partial.string());
      const FaceControls last = face_controls(perf, start - 1, face);
      lr.set_controls(last);
      hr.set_controls(last);
      // the frame before the last: as the uninterrupted run had it (the neutral before frame 0)
      const FaceControls before = start >= 2 ? face_controls(perf, start - 2, face) : zero;
      lr.set_positions(start >= 2 ? io::points_of(z, "lr_before", N, partial.string()) : lr_neutral, before, lx);
      hr.set_positions(start >= 2 ? io::points_of(z, "hr_before", face.hr.num_vertices(), partial.string()) : hr_neutral, before, hx);
    }
    Points<> lr_before = lr.positions(), hr_before = hr.positions();
    for (Index f = start; f < F; ++f) {
      const FaceControls c = face_controls(perf, f, face);
      lr.set_controls(c);
      hr.set_controls(c);
      lr_before = lr.positions();
      hr_before = hr.positions();
      const auto t0 = std::chrono::steady_clock::now();
      const auto rl = detail::solve_frame(policy, lr, perf.name, f);
      const auto t1 = std::chrono::steady_clock::now();
      const auto rh = detail::solve_frame(policy, hr, perf.name, f);
      const auto t2 = std::chrono::steady_clock::now();
      const double sl = std::chrono::duration<double>(t1 - t0).count(), sh = std::chrono::duration<double>(t2 - t1).count();
      lip_pairs[std::size_t(f)] = std::int64_t(intersecting_lip_pairs(face, hr.positions()).size());
      out.lr(f) = lr.positions();
      out.hr(f) = hr.surface(policy);
      st.lr_seconds += sl;
      st.hr_seconds += sh;
      st.lr_iterations += rl.iterations;
      st.hr_iterations += rh.iterations;
      ++st.simulated;
      if (opt.on_frame) opt.on_frame(perf.name, f, F, rl, rh, sl, sh);
      const Index done = f + 1;
      if (done < F && done % opt.checkpoint_every == 0) {
        io::NpzArrays z = data::frames_checkpoint(out, done, print);
        z["lr_state"] = io::make_npy(lr.positions());
        z["hr_state"] = io::make_npy(hr.positions());
        z["lr_before"] = io::make_npy(lr_before);
        z["hr_before"] = io::make_npy(hr_before);
        z["hr_lip_pairs"] = io::make_npy<std::int64_t>({done}, lip_pairs.data());
        io::write_npz(partial, z);
      }
    }
    measure_discrepancy(policy, face, out, st);
    detail::count_lip_frames(lip_pairs, st);
    auto arrays = data::paired_frame_arrays(out);
    io::set_fingerprint(arrays, print);
    arrays["hr_lip_pairs"] = io::make_npy<std::int64_t>({F}, lip_pairs.data());
    arrays["control_names"] = io::make_npy(perf.names);
    io::write_npz(final_file, arrays);
    io::NpzArrays ctl;
    ctl["names"] = io::make_npy(perf.names);
    ctl["weights"] = io::make_npy(perf.weights);
    io::write_npz(dir / (perf.name + "_controls.npz"), ctl);
    std::filesystem::remove(partial);
    stats.push_back(st);
  }
  return stats;
}

/// The run's summary as JSON: mesh sizes, the split, muscles, and per performance the discrepancy
/// (embedded LR surface to HR surface, absolute and relative to the rest surface's bounding-box
/// diagonal; the HR/LR ratio of mean skin displacement), the seconds per frame and Newton
/// iterations per frame at each resolution (frames simulated in this run).
inline nlohmann::ordered_json face_data_report(const FaceModel& face, const std::vector<PerformanceStats>& stats) {
  nlohmann::ordered_json j;
  j["hr"] = {{"vertices", face.hr.num_vertices()}, {"tets", face.hr.num_tets()}, {"bone_vertices", face.hr_bone.size()}};
  j["lr"] = {{"vertices", face.lr.num_vertices()},
             {"tets", face.lr.num_tets()},
             {"bone_vertices", face.lr_bone.size()},
             {"split_lattice_tets", face.lr_split.split_lattice_tets},
             {"duplicated_nodes", face.lr_split.duplicated_nodes}};
  j["tet_ratio"] = double(face.hr.num_tets()) / double(face.lr.num_tets());
  j["surface"] = {{"vertices", face.surface.num_vertices()}, {"triangles", face.surface.num_faces()}};
  j["skull"] = {{"vertices", face.skull_vertices}, {"volume_cm3", face.skull_volume * 1e6}, {"thinnest_flesh_cm", face.min_flesh * 100}};
  j["jaw"] = {{"hinge_point_m", {face.hinge.point.x(), face.hinge.point.y(), face.hinge.point.z()}},
              {"hinge_axis", {face.hinge.axis.x(), face.hinge.axis.y(), face.hinge.axis.z()}},
              {"jawOpen_degrees", face.hinge.angle * 180 / std::acos(-1.0)},
              {"rest_degrees", face.rest_jaw_angle * 180 / std::acos(-1.0)}};
  nlohmann::ordered_json muscles = nlohmann::ordered_json::array();
  for (const auto& m : face.muscles) muscles.push_back(m.spec.name);
  j["muscles"] = muscles;
  const double diagonal = (face.surface.V.colwise().maxCoeff() - face.surface.V.colwise().minCoeff()).norm();
  j["surface_bbox_diagonal_m"] = diagonal;
  nlohmann::ordered_json perf = nlohmann::ordered_json::array();
  for (const auto& s : stats) {
    nlohmann::ordered_json p{{"name", s.name}, {"frames", s.frames}, {"reused", s.reused}, {"simulated", s.simulated}};
    p["embedded_lr_to_hr_mean_distance_m"] = s.lr_hr_mean_distance;
    p["embedded_lr_to_hr_mean_distance_relative"] = s.lr_hr_mean_distance / diagonal;
    p["hr_mean_skin_displacement_m"] = s.hr_mean_displacement;
    p["lr_mean_skin_displacement_m"] = s.lr_mean_displacement;
    p["hr_lr_displacement_ratio"] = s.lr_mean_displacement > 0 ? s.hr_mean_displacement / s.lr_mean_displacement : 0.0;
    if (s.simulated > 0) {
      const double n = double(s.simulated);
      p["lr_seconds_per_frame"] = s.lr_seconds / n;
      p["hr_seconds_per_frame"] = s.hr_seconds / n;
      p["lr_newton_iterations_per_frame"] = double(s.lr_iterations) / n;
      p["hr_newton_iterations_per_frame"] = double(s.hr_iterations) / n;
      p["hr_frames_with_intersecting_lips"] = s.lip_intersecting_frames;
      p["hr_most_intersecting_lip_triangle_pairs"] = s.lip_max_pairs;
    }
    perf.push_back(p);
  }
  j["performances"] = perf;
  return j;
}

/// The performance a controls file stands for: its stem, less a trailing "_controls" (so the
/// DIR/<name>_controls.npz a run writes simulates again as <name>, and never overwrites itself).
inline std::string performance_name_of(const std::filesystem::path& controls_file) {
  std::string s = controls_file.stem().string();
  const std::string tail = "_controls";
  if (s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0) s.resize(s.size() - tail.size());
  return s;
}

/// Reads a controls file (`names`: C strings, `weights`: F×C) as a performance called `name`.
inline Performance read_controls(const std::filesystem::path& file, const std::string& name) {
  const auto z = io::read_npz(file);
  if (!z.contains("names") || !z.contains("weights")) throw ArgumentError(file.string() + ": a controls file needs arrays 'names' (C strings) and 'weights' (F×C)");
  Performance p;
  p.name = name;
  p.names = z.at("names").to_strings();
  const auto& w = z.at("weights");
  if (w.ndim() != 2 || w.shape[1] != std::int64_t(p.names.size()))
    throw ShapeError(file.string() + ": weights", {-1, Index(p.names.size())}, {w.ndim() > 0 ? Index(w.shape[0]) : 0, w.ndim() > 1 ? Index(w.shape[1]) : 0});
  if (w.shape[0] < 1 || w.shape[0] > data::max_frames) throw ArgumentError(file.string() + ": " + std::to_string(w.shape[0]) + " frames (expected 1 to " + std::to_string(data::max_frames) + ")");
  for (std::size_t i = 0; i < p.names.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (p.names[i] == p.names[j]) throw ArgumentError(file.string() + ": control '" + p.names[i] + "' appears twice (columns " + std::to_string(j) + " and " + std::to_string(i) + ")");
  p.weights = w.to_matrix<double>();
  return p;
}

}  // namespace simsr::scenario
