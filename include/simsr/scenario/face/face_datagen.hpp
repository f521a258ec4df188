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
///
/// Chunks (FaceDatagenOptions::chunks, so that more processes than performances share a run):
/// each performance's frames split into K contiguous chunks, each a unit of work. A chunk [a, b)
/// starts from the settled neutral at frame a − w (w = chunk_overlap, 2 by default; at frame 0 if
/// a ≤ w) and solves the w lead-in frames a − w … a − 1 without writing them: the first lead-in
/// frame is reached from the neutral by the simulator's continuation (its controls walked in 2,
/// 4, … substeps; FaceSimulator::step_from_afar), and
/// the next w − 1 give frame a the warm start a whole run gives it, the extrapolation of two solved
/// frames. The lead-in frames are the chunk's extra cost (w frames per chunk after the first).
/// Frames of a chunk whose lead-in starts at frame 0 equal the whole run's bitwise (the same
/// solves from the same state); the others are the same equilibria to the solver tolerance, not
/// bitwise: a quasistatic frame is the equilibrium of its own controls, which Newton reaches from
/// either warm start to its tolerance (tests/scenario/test_face_datagen.cpp measures how far
/// apart). A finished chunk is written atomically to DIR/.state/<performance>.chunk<c>of<K>.npz
/// (its checkpoints to ….partial.npz); the process that runs the whole list (shard 0 of 1)
/// assembles a performance's chunks into DIR/<performance>.npz, which then records the chunks'
/// first frames (`chunk_first_frames`) and the overlap. A performance file keeps its
/// performance's fingerprint whatever the chunks (any chunking is the same run to the solver
/// tolerance), so a rerun with other chunks reuses a finished file.

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
  /// Contiguous chunks per performance (file comment; fewer where a performance has fewer
  /// frames). 1: every performance is one unit, solved from its first frame on.
  Index chunks = 1;
  /// Lead-in frames solved before a chunk's first frame and not written (file comment).
  Index chunk_overlap = 2;
  /// Called after every lead-in frame: performance, frame, the chunk's first frame, the two
  /// reports, seconds of the frame (LR, HR).
  std::function<void(const std::string&, Index, Index, const physics::NewtonReport&, const physics::NewtonReport&, double, double)> on_lead_in;
  /// The units this process simulates: shard `index` of `count`, a contiguous block of the list of
  /// (performance, chunk) units (face_chunks; with one chunk each, of the performances); the
  /// others are neither simulated nor checked. Every unit starts from the settled neutral, so a
  /// shard's files are those of the whole run with the same chunks, bitwise
  /// (simsr::mpi::generate_face_dataset gives each rank one). Not part of any fingerprint. Only
  /// the whole list (one shard) assembles chunks into performance files.
  WorkShard shard;
};

/// One unit of a face run's work: frames [first, last) of performance `performance`, its chunk
/// `index` of `count`, solved from the settled neutral at frame `lead_in` ≤ first (the frames
/// before `first` are the unwritten warm-start overlap).
struct FaceChunk {
  Index performance = 0, index = 0, count = 1, first = 0, last = 0, lead_in = 0;
  bool whole() const { return count == 1; }
  Index frames() const { return last - first; }
};

/// The units of a run, in order: each performance's frames in min(chunks, F) contiguous chunks
/// (WorkShard::range over its F frames), each chunk after `overlap` lead-in frames (from frame 0
/// where its first frame is ≤ overlap). ArgumentError for chunks < 1, overlap < 0 or a performance
/// without frames.
inline std::vector<FaceChunk> face_chunks(const std::vector<Performance>& performances, Index chunks, Index overlap) {
  if (chunks < 1) throw ArgumentError("face datagen: chunks per performance = " + std::to_string(chunks) + " (need >= 1)");
  if (overlap < 0) throw ArgumentError("face datagen: chunk overlap = " + std::to_string(overlap) + " frames (need >= 0)");
  std::vector<FaceChunk> units;
  for (std::size_t p = 0; p < performances.size(); ++p) {
    const Index F = performances[p].num_frames();
    if (F < 1) throw ArgumentError("face datagen: performance '" + performances[p].name + "' has no frames");
    const Index K = std::min(chunks, F);
    for (Index c = 0; c < K; ++c) {
      const auto [a, b] = WorkShard{c, K}.range(F);
      units.push_back({Index(p), c, K, a, b, std::max<Index>(0, a - overlap)});
    }
  }
  return units;
}

/// The chunks per performance that give each of `shards` processes at least one unit:
/// ⌈shards / performances⌉ (1 for one shard).
inline Index chunks_for_shards(Index shards, Index performances) {
  if (shards < 1 || performances < 1) return 1;
  return (shards + performances - 1) / performances;
}

/// Per-performance figures of a run.
struct PerformanceStats {
  std::string name;
  Index frames = 0;
  double lr_seconds = 0, hr_seconds = 0;   ///< total over the frames simulated in this run
  Index lr_iterations = 0, hr_iterations = 0;
  Index simulated = 0;                     ///< frames simulated in this run (the rest were resumed or reused)
  bool reused = false;                     ///< the finished file was there already
  Index chunks = 1;                        ///< the units its frames were split into
  Index lead_in_frames = 0;                ///< lead-in frames solved in this run (chunks after the first; not written)
  double lead_in_seconds = 0;              ///< their LR + HR seconds
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
  // the products' storage changes frames to rounding, the lagged levels by PCG's tolerance
  f.add(std::int64_t(o.linear.block_products)).add(std::int64_t(o.multigrid.storage)).add(std::int64_t(o.multigrid.coarse_refresh_every));
  f.add(std::int64_t(o.multigrid.smoothing_sweeps)).add(o.multigrid.damping).add(std::int64_t(o.multigrid.power_iterations)).add(std::int64_t(o.multigrid.warm_power_iterations));
  // the smoother and Newton's schedule (forcing, Hessian fallback, chord steps) change frames by PCG's tolerance
  f.add(std::int64_t(o.multigrid.smoother)).add(std::int64_t(o.multigrid.chebyshev_degree)).add(o.multigrid.chebyshev_ratio);
  // the smoother's spectrum estimate (MultigridOptions::spectrum: Lanczos for Chebyshev since
  // 2026-12-06, the power method's before) changes frames by PCG's tolerance
  f.add(std::int64_t(o.multigrid.spectrum)).add(std::int64_t(o.multigrid.lanczos_iterations));
  // the multigrid's levels (LatticeHierarchyOptions; coarsened to 1/8 per level since 2026-12-07)
  // change frames by PCG's tolerance
  f.add(o.hierarchy.h).add(std::int64_t(o.hierarchy.max_coarse_vertices)).add(std::int64_t(o.hierarchy.max_levels));
  f.add(o.hierarchy.coarsening).add(std::int64_t(o.hierarchy.coarsening_tries));
  f.add(std::int64_t(o.newton.forcing)).add(o.newton.forcing_max).add(std::int64_t(o.newton.forcing_safeguard)).add(std::int64_t(o.newton.hessian));
  f.add(o.newton.chord_below).add(o.newton.step_tolerance).add(o.newton.reference_force);
  if (o.newton.chord_first) f.add(std::int64_t(1));  // only when on: runs made before the option keep their fingerprint
  // only where the meshes' forcings differ: before the option both used newton.forcing, and a run
  // where they still agree (the defaults) keeps the fingerprint it had
  if (o.hr_forcing != o.newton.forcing) f.add(std::int64_t(o.hr_forcing));
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

/// One resolution's Newton solve with the failure made specific; `from_afar`: by continuation at
/// once (FaceSimulator::step_from_afar).
template <class P, class Sim>
physics::NewtonReport solve_frame(P policy, Sim& sim, const std::string& perf, Index frame, bool from_afar = false) {
  physics::NewtonReport r;
  try {
    r = from_afar ? sim.step_from_afar(policy) : sim.step(policy);
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

namespace detail {

/// The fingerprint of chunk `u` of a performance whose own fingerprint is `print` (a chunk's
/// frames depend on where its lead-in starts as well).
inline std::string face_chunk_fingerprint(const std::string& print, const FaceChunk& u) {
  if (u.whole()) return print;
  Fingerprint f;
  f.add_bytes(print.data(), print.size()).add(u.first).add(u.last).add(u.lead_in).add(u.count);
  return f.hex();
}

/// DIR/.state/<performance>.chunk<c>of<K>.npz (`partial`: its checkpoint, ….partial.npz); a whole
/// performance's checkpoint is DIR/.state/<performance>.npz and it has no part file.
inline std::filesystem::path face_chunk_file(const std::filesystem::path& state, const std::string& name, const FaceChunk& u, bool partial) {
  if (u.whole()) return state / (name + ".npz");
  return state / (name + ".chunk" + std::to_string(u.index) + "of" + std::to_string(u.count) + (partial ? ".partial.npz" : ".npz"));
}

/// Solves unit `u` of `perf` (file comment): from the settled neutral (lr_neutral, hr_neutral,
/// under zero controls) at frame u.lead_in, or from `checkpoint` (read from `partial`, of
/// fingerprint `print`), into `out` (u.frames() frames) and `lip_pairs` (one per frame of `out`),
/// checkpointing to `partial` every opt.checkpoint_every written frames; figures added to `st`.
template <class Linear, class P>
void simulate_face_chunk(P policy, const FaceModel& face, const Performance& perf, const FaceChunk& u, FaceSimulator<Linear>& lr, FaceSimulator<Linear>& hr,
                         const Points<>& lr_neutral, const Points<>& hr_neutral, const io::NpzArrays* checkpoint, const std::filesystem::path& partial,
                         const std::string& print, const FaceDatagenOptions& opt, PerformanceStats& st, data::PairedFrames<>& out,
                         std::vector<std::int64_t>& lip_pairs) {
  const Index F = perf.num_frames(), N = face.lr.num_vertices(), n = u.frames();
  const FaceControls zero = neutral_controls(face);
  Index start = u.lead_in;  // the first frame solved here
  // positions are taken as solved under the controls set before them (continuation walks from
  // those): the neutral under zero controls, a checkpoint under its last frame's
  lr.set_controls(zero);
  hr.set_controls(zero);
  lr.set_positions(lr_neutral);
  hr.set_positions(hr_neutral);
  if (checkpoint) {
    const io::NpzArrays& z = *checkpoint;
    start = u.first + data::resume_frames(z, partial.string(), out);
    const auto lips = lip_pairs_of(z, start - u.first, partial.string());
    std::copy(lips.begin(), lips.end(), lip_pairs.begin());
    const Points<> lx = io::points_of(z, "lr_state", N, partial.string()), hx = io::points_of(z, "hr_state", face.hr.num_vertices(), partial.string());
    const FaceControls last = face_controls(perf, start - 1, face);
    lr.set_controls(last);
    hr.set_controls(last);
    // the frame before the last: as the uninterrupted run had it (the neutral before the first
    // frame solved)
    const bool neutral_before = start - 1 == u.lead_in;
    const FaceControls before = neutral_before ? zero : face_controls(perf, start - 2, face);
    lr.set_positions(neutral_before ? lr_neutral : io::points_of(z, "lr_before", N, partial.string()), before, lx);
    hr.set_positions(neutral_before ? hr_neutral : io::points_of(z, "hr_before", face.hr.num_vertices(), partial.string()), before, hx);
  }
  Points<> lr_before = lr.positions(), hr_before = hr.positions();
  for (Index f = start; f < u.last; ++f) {
    const FaceControls c = face_controls(perf, f, face);
    lr.set_controls(c);
    hr.set_controls(c);
    lr_before = lr.positions();
    hr_before = hr.positions();
    // a chunk's first frame solved away from frame 0 is a jump from the neutral: walked in substeps
    // at once (a frame-0 start is the whole run's own first solve, kept as it is: bitwise)
    const bool from_afar = f == u.lead_in && f > 0;
    const auto t0 = std::chrono::steady_clock::now();
    const auto rl = solve_frame(policy, lr, perf.name, f, from_afar);
    const auto t1 = std::chrono::steady_clock::now();
    const auto rh = solve_frame(policy, hr, perf.name, f, from_afar);
    const auto t2 = std::chrono::steady_clock::now();
    const double sl = std::chrono::duration<double>(t1 - t0).count(), sh = std::chrono::duration<double>(t2 - t1).count();
    if (f < u.first) {  // the lead-in: solved, not written
      ++st.lead_in_frames;
      st.lead_in_seconds += sl + sh;
      if (opt.on_lead_in) opt.on_lead_in(perf.name, f, u.first, rl, rh, sl, sh);
      continue;
    }
    const Index row = f - u.first;
    lip_pairs[std::size_t(row)] = std::int64_t(intersecting_lip_pairs(face, hr.positions()).size());
    out.lr(row) = lr.positions();
    out.hr(row) = hr.surface(policy);
    st.lr_seconds += sl;
    st.hr_seconds += sh;
    st.lr_iterations += rl.iterations;
    st.hr_iterations += rh.iterations;
    ++st.simulated;
    if (opt.on_frame) opt.on_frame(perf.name, f, F, rl, rh, sl, sh);
    const Index done = row + 1;
    if (done < n && done % opt.checkpoint_every == 0) {
      io::NpzArrays z = data::frames_checkpoint(out, done, print);
      z["lr_state"] = io::make_npy(lr.positions());
      z["hr_state"] = io::make_npy(hr.positions());
      z["lr_before"] = io::make_npy(lr_before);
      z["hr_before"] = io::make_npy(hr_before);
      z["hr_lip_pairs"] = io::make_npy<std::int64_t>({done}, lip_pairs.data());
      io::write_npz(partial, z);
    }
  }
}

/// Writes a performance's file (atomically) and its controls file.
inline void write_performance_file(const std::filesystem::path& dir, const Performance& perf, const data::PairedFrames<>& frames,
                                   const std::vector<std::int64_t>& lip_pairs, const std::string& print, const io::NpzArrays& extra = {}) {
  const Index F = perf.num_frames();
  auto arrays = data::paired_frame_arrays(frames);
  io::set_fingerprint(arrays, print);
  arrays["hr_lip_pairs"] = io::make_npy<std::int64_t>({F}, lip_pairs.data());
  arrays["control_names"] = io::make_npy(perf.names);
  for (const auto& [name, a] : extra) arrays[name] = a;
  io::write_npz(dir / (perf.name + ".npz"), arrays);
  io::NpzArrays ctl;
  ctl["names"] = io::make_npy(perf.names);
  ctl["weights"] = io::make_npy(perf.weights);
  io::write_npz(dir / (perf.name + "_controls.npz"), ctl);
}

}  // namespace detail

/// Simulates `performances` on `face` into `dir` (see the file comment), in opt.chunks chunks
/// each, or the block of those units `opt.shard` names. Returns the figures of this run, one per
/// performance with a unit in the block (simulated, resumed or reused), in order; a performance
/// only part of whose chunks are in the block has no discrepancy or lip figures (they need all
/// its frames: the whole list's pass measures them when it assembles the file).
template <class Linear = physics::ConjugateGradient<physics::Multigrid<>>, exec::HostPolicy P>
std::vector<PerformanceStats> generate_face_data(P policy, const FaceModel& face, const std::vector<Performance>& performances,
                                                 const std::filesystem::path& dir, const FaceDatagenOptions& opt = {}) {
  if (opt.checkpoint_every < 1) throw ArgumentError("generate_face_data: checkpoint_every must be ≥ 1");
  opt.shard.check("generate_face_data");
  for (const auto& p : performances)
    if (p.name.empty() || p.name.find_first_of("/\\. ") != std::string::npos)
      throw ArgumentError("generate_face_data: performance name '" + p.name + "' cannot be a file name");
  const std::vector<FaceChunk> units = face_chunks(performances, opt.chunks, opt.chunk_overlap);
  const auto [first_unit, last_unit] = opt.shard.range(Index(units.size()));
  const auto state = dir / ".state";
  // every unit's performance fingerprinted, and another run's checkpoint refused, before anything
  // is written or solved; the checkpoints read here are the ones resumed below
  std::vector<std::string> prints(performances.size());
  std::vector<std::optional<io::NpzArrays>> checkpoints(std::size_t(last_unit - first_unit));
  for (Index i = first_unit; i < last_unit; ++i) {
    const FaceChunk& u = units[std::size_t(i)];
    const Performance& p = performances[std::size_t(u.performance)];
    std::string& print = prints[std::size_t(u.performance)];
    if (print.empty()) print = detail::face_run_fingerprint(face, opt.simulation, &p);
    const auto partial = detail::face_chunk_file(state, p.name, u, true);
    if (!std::filesystem::exists(partial)) continue;
    auto& z = checkpoints[std::size_t(i - first_unit)];
    z = io::read_npz(partial);
    if (io::fingerprint_of(*z) != detail::face_chunk_fingerprint(print, u))
      throw ArgumentError(partial.string() + " is a checkpoint of another run (other meshes, options, controls or chunks): remove it or use another directory");
  }
  if (first_unit == last_unit) return {};  // a shard with no unit (more shards than units)
  std::filesystem::create_directories(state);
  write_face_rest_shapes(face, dir);
  const std::string model_print = detail::face_run_fingerprint(face, opt.simulation, nullptr);

  FaceSimulator<Linear> lr(policy, face, FaceResolution::low, opt.simulation);
  FaceSimulator<Linear> hr(policy, face, FaceResolution::high, opt.simulation);

  // the settled neutral, shared by every unit's first frame
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

  const Index N = face.lr.num_vertices(), M = face.surface.num_vertices();
  // a performance's file, whole: its lip and discrepancy figures
  auto measure_file = [&](const data::PairedFrames<>& frames, const std::vector<std::int64_t>& lip_pairs, PerformanceStats& st) {
    measure_discrepancy(policy, face, frames, st);
    detail::count_lip_frames(lip_pairs, st);
  };
  std::vector<PerformanceStats> stats;
  std::vector<std::size_t> stats_of;                     // the performance of each entry of stats
  std::vector<char> finished(performances.size(), 0);  // its file is there (reused or written)
  for (Index i = first_unit; i < last_unit; ++i) {
    const FaceChunk& u = units[std::size_t(i)];
    const Performance& perf = performances[std::size_t(u.performance)];
    const Index F = perf.num_frames();
    const std::string& print = prints[std::size_t(u.performance)];
    const auto final_file = dir / (perf.name + ".npz");
    if (stats.empty() || stats_of.back() != std::size_t(u.performance)) {  // the first of its units here
      PerformanceStats st;
      st.name = perf.name;
      st.frames = F;
      st.chunks = u.count;
      // a finished file of this very run (any chunks): reuse
      if (std::filesystem::exists(final_file)) {
        const auto z = io::read_npz(final_file);
        if (io::fingerprint_of(z) == print) {
          st.reused = true;
          finished[std::size_t(u.performance)] = 1;
          measure_file(data::read_paired_frames(final_file, N, M), detail::lip_pairs_of(z, F, final_file.string()), st);
        }
      }
      stats.push_back(st);
      stats_of.push_back(std::size_t(u.performance));
    }
    if (finished[std::size_t(u.performance)]) continue;
    PerformanceStats& st = stats.back();
    const auto partial = detail::face_chunk_file(state, perf.name, u, true);
    const auto part = detail::face_chunk_file(state, perf.name, u, false);
    const std::string chunk_print = detail::face_chunk_fingerprint(print, u);
    if (!u.whole() && std::filesystem::exists(part)) {  // a finished chunk of this run: kept
      io::NpzReader r(part);
      if (io::fingerprint_of(r) == chunk_print) continue;
    }
    data::PairedFrames<> out = data::PairedFrames<>::one_sequence(u.frames(), N, M, perf.name);
    std::vector<std::int64_t> lip_pairs(std::size_t(u.frames()), 0);  // per frame: intersecting lip triangle pairs at HR
    const auto& checkpoint = checkpoints[std::size_t(i - first_unit)];
    detail::simulate_face_chunk(policy, face, perf, u, lr, hr, lr_neutral, hr_neutral, checkpoint ? &*checkpoint : nullptr, partial, chunk_print, opt, st, out,
                                lip_pairs);
    if (u.whole()) {
      out.controls = perf.weights;
      measure_file(out, lip_pairs, st);
      detail::write_performance_file(dir, perf, out, lip_pairs, print);
      finished[std::size_t(u.performance)] = 1;
    } else {
      io::NpzArrays z = data::frames_checkpoint(out, u.frames(), chunk_print);
      z["hr_lip_pairs"] = io::make_npy<std::int64_t>({u.frames()}, lip_pairs.data());
      io::write_npz(part, z);
    }
    std::filesystem::remove(partial);
  }

  // the whole list: every performance's chunks are there; assembled into its file
  if (opt.shard.whole())
    for (std::size_t s = 0; s < stats.size(); ++s) {
      const std::size_t p = stats_of[s];
      if (finished[p]) continue;
      PerformanceStats& st = stats[s];
      const Performance& perf = performances[p];
      const Index F = perf.num_frames();
      data::PairedFrames<> out = data::PairedFrames<>::one_sequence(F, N, M, perf.name);
      out.controls = perf.weights;
      std::vector<std::int64_t> lip_pairs(std::size_t(F), 0), firsts;
      std::vector<std::filesystem::path> parts;
      for (const FaceChunk& u : units) {
        if (u.performance != Index(p)) continue;
        const auto part = detail::face_chunk_file(state, perf.name, u, false);
        const auto z = io::read_npz(part);
        if (io::fingerprint_of(z) != detail::face_chunk_fingerprint(prints[p], u))
          throw ArgumentError(part.string() + " is a chunk of another run (other meshes, options, controls or chunks)");
        data::PairedFrames<> chunk = data::PairedFrames<>::one_sequence(u.frames(), N, M, perf.name);
        if (data::resume_frames(z, part.string(), chunk) != u.frames())
          throw ArgumentError(part.string() + ": holds fewer frames than its chunk [" + std::to_string(u.first) + ", " + std::to_string(u.last) + ")");
        out.lowres.middleRows(u.first, u.frames()) = chunk.lowres;
        out.highres.middleRows(u.first, u.frames()) = chunk.highres;
        const auto lips = detail::lip_pairs_of(z, u.frames(), part.string());
        std::copy(lips.begin(), lips.end(), lip_pairs.begin() + u.first);
        firsts.push_back(u.first);
        parts.push_back(part);
      }
      measure_file(out, lip_pairs, st);
      io::NpzArrays extra;
      extra["chunk_first_frames"] = io::make_npy<std::int64_t>({Index(firsts.size())}, firsts.data());
      const std::int64_t overlap = opt.chunk_overlap;
      extra["chunk_overlap"] = io::make_npy<std::int64_t>({}, &overlap);
      detail::write_performance_file(dir, perf, out, lip_pairs, prints[p], extra);
      for (const auto& part : parts) std::filesystem::remove(part);
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
    if (s.chunks > 1) {  // its frames in chunks: what the lead-ins cost
      p["chunks"] = s.chunks;
      p["lead_in_frames_solved"] = s.lead_in_frames;
      p["lead_in_seconds"] = s.lead_in_seconds;
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
