#pragma once
/// \file
/// The SHEET and DISK datasets (Chen et al. 2023, supplement §3; issue #14 item 3): every
/// sequence simulated at the coarse and at the fine resolution, separately, with the same
/// parameters and no constraint between them, into
///
///     DIR/coarse_rest.obj, DIR/fine_rest.obj   the two cloths at rest (fine = Loop(coarse), or
///                                              a SHEET Loop-subdivided of its own: fine_cells)
///     DIR/<scene>_NNN.npz                      a sequence's frames (data::PairedFrames: lowres the
///                                              coarse cloth, highres the fine one, F × 3N / 3M)
///     DIR/cloth_data.json                      sizes, the split, per-sequence figures
///
/// Each sequence starts from the settled cloth (SHEET: sagging on its pins with the obstacle
/// above it; DISK: draped on the table, no wind), settled once (`settle_frames`) and kept in
/// DIR/.state. The split holds out whole sequences (every 5th: 20 %, the supplement's 3,200 /
/// 800 and 1,600 / 400 frames), never frames of a sequence it trains on.
///
/// A run checkpoints each sequence every `checkpoint_every` frames (DIR/.state/<name>.npz: the
/// frames so far and both cloths' last two states, written atomically), so a killed run resumes
/// where it stopped and ends bitwise where the uninterrupted run ends. A file of another run
/// (another scene, size, seed or parameters) is refused by fingerprint, never continued.
///
/// The fine cloth's frames of another dataset with the same fine cloth, scene and options (the
/// supplement's scale study: one fine simulation, coarse inputs of three sizes) are taken instead
/// of simulated again with `fine_frames_from` = that dataset's folder: every sequence file carries
/// the fingerprint of its fine cloth's simulation alone ("fine_fingerprint"), which must be this
/// run's, or the run is refused before anything is simulated. The data is bitwise what simulating
/// the fine cloth again would give (tested).
///
/// Under exec::omp the sequences are simulated side by side, one per thread (each sequence's
/// own steps then on that thread alone): a Newton step of the fine cloth is a sparse Cholesky
/// factorization that a second thread barely speeds up (README: 0.20 s at one or two threads at
/// 4,225 vertices), while two sequences at once take half the time. The data is bitwise the
/// same for any number of workers (tested).
///
///     auto stats = shell::generate_cloth_data(exec::omp, shell::ClothDataset::sheet, "sheet_data", {});

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "../core/eigen_threads.hpp"
#include "../core/error.hpp"
#include "../core/fingerprint.hpp"
#include "../core/parallel.hpp"
#include "../data/paired_frames.hpp"
#include "../data/run_checkpoint.hpp"
#include "../io/atomic_file.hpp"
#include "../io/mesh_io.hpp"
#include "../io/npz.hpp"
#include "cloth_scenes.hpp"
#include "cloth_simulator.hpp"

namespace simsr::shell {

/// What a cloth datagen run is asked for.
struct ClothDatagenOptions {
  ClothSceneSize size{0, -1};  ///< {0, -1}: the dataset's default_scene_size
  Index sequences = 0;         ///< 0: SHEET 32, DISK 16 (about the supplement's 4,000 and 2,000 frames)
  double extra_seconds = 1.0;  ///< simulated after a SHEET obstacle has left (the cloth swings back)
  std::uint64_t seed = 7;
  Index settle_frames = 45;    ///< frames to settle the start state
  Index checkpoint_every = 20;
  /// Sequences simulated at once, each on a thread of its own: 0 = the policy's threads (exec::omp:
  /// omp_get_max_threads(), exec::seq: 1). Above 1 only under exec::omp. Not part of the data's
  /// fingerprint: the frames are bitwise the same for any count.
  Index sequence_workers = 0;
  ClothMaterial material;
  ClothOptions simulation;  ///< frame time, substeps (`simsr datagen --substeps`), Newton's options, ...
  /// Called after every simulated frame: sequence, frame, frames, both reports, seconds (coarse,
  /// fine). With several workers it is called from the worker simulating that sequence, one call
  /// at a time (under a lock); what it throws ends that sequence (its checkpoint kept) and, once
  /// the other workers' sequences are done, the run.
  std::function<void(const std::string&, Index, Index, const ClothFrameReport&, const ClothFrameReport&, double, double)> on_frame;
  using FrameCallback = decltype(on_frame);
  /// Called after every frame of settling the sequences' shared start (on_frame's arguments, the
  /// name "settle"; minutes at the paper's sizes); nothing when the settled start is read from
  /// its file.
  FrameCallback on_settle_frame;
  /// A dataset folder whose sequences' fine frames this run takes instead of simulating them
  /// (see the file comment); empty: simulate both cloths.
  std::filesystem::path fine_frames_from;
};

/// One sequence's figures.
struct ClothSequenceStats {
  std::string name;
  bool test = false;    ///< held out
  bool reused = false;  ///< a finished file of this run was found
  bool fine_reused = false;  ///< the fine frames were read from ClothDatagenOptions::fine_frames_from
  Index frames = 0, simulated = 0;
  Index coarse_iterations = 0, fine_iterations = 0;  ///< Newton iterations (frames simulated in this run)
  Index halvings = 0;                                ///< steps halved after a failed solve (both resolutions)
  double coarse_seconds = 0, fine_seconds = 0;
  double deepest = 0;  ///< m, the deepest vertex inside the obstacle (both resolutions; this run's frames)
  /// RMSE (m) of the Loop-subdivided coarse cloth against the fine one over the frames: the
  /// evaluation's first baseline, measured from the file.
  double subdivided_rmse = 0;
};

/// The sequences' names, in order: "<scene>_000", ...
inline std::string cloth_sequence_name(ClothDataset d, Index k) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%s_%03lld", to_string(d), static_cast<long long>(k));
  return buf;
}

/// Held out: every 5th sequence (4, 9, 14, ...), so each SHEET obstacle kind is in both sets.
inline bool cloth_sequence_is_test(Index k) { return k % 5 == 4; }

namespace detail {

/// The material, the simulation's options and a sequence's own figures into a fingerprint.
inline void add_cloth_run(Fingerprint& f, const ClothDatagenOptions& o, Index sequence, Index frames, const std::vector<double>& parameters) {
  const ClothMaterial& m = o.material;
  const ClothOptions& s = o.simulation;
  f.add(m.areal_density).add(m.stretch).add(m.bending).add(s.frame_time).add(s.substeps).add(s.damping).add(s.gravity).add(s.contact_stiffness);
  f.add(s.newton.relative_tolerance).add(s.newton.absolute_tolerance).add(s.newton.max_iterations).add(std::int64_t(s.newton.hessian)).add(s.max_halvings);
  f.add(o.settle_frames).add(o.seed).add(o.extra_seconds).add(sequence).add(frames).add(parameters);
  // added after the data of earlier runs: their defaults hash as before, so that data stays valid
  if (s.contact_onset != 0) f.add(s.contact_onset);
  if (s.newton.accept_at_max_iterations) f.add(std::int64_t(1));
}

/// The fingerprint of a sequence's (or the settled start's: sequence −1) file: the meshes, the
/// material and options, and the sequence's own parameters (a sequence's wind speed depends on
/// how many sequences were drawn, so its index alone would not do).
inline std::string cloth_fingerprint(ClothDataset d, const ClothPair& pair, const ClothDatagenOptions& o, Index sequence, Index frames,
                                     const std::vector<double>& parameters) {
  Fingerprint f;
  f.add(std::int64_t(d)).add(pair.coarse.V).add(pair.coarse.F).add(pair.fine.V).add(pair.fine.F).add(pair.pinned);
  add_cloth_run(f, o, sequence, frames, parameters);
  // added after the data of earlier runs: their defaults hash as before, so that data stays valid
  if (!pair.fine_pins_are_coarse_pins()) f.add(pair.fine_pinned);
  return f.hex();
}

/// The fingerprint of the fine cloth's simulation alone in a sequence: what its frames depend on
/// (the fine mesh and pins, the material and options, the sequence, and what the shared start
/// settled with), not the coarse cloth. `settle_parameters` the settling's sequence parameters.
inline std::string cloth_fine_fingerprint(ClothDataset d, const ClothPair& pair, const ClothDatagenOptions& o, Index sequence, Index frames,
                                          const std::vector<double>& parameters, const std::vector<double>& settle_parameters) {
  static constexpr char tag[] = "fine cloth";  // never a whole file's fingerprint
  Fingerprint f;
  f.add_bytes(tag, sizeof tag - 1).add(std::int64_t(d)).add(pair.fine.V).add(pair.fine.F).add(pair.fine_pinned);
  add_cloth_run(f, o, sequence, frames, parameters);
  f.add(settle_parameters);
  return f.hex();
}

/// RMSE (m) over all frames and fine vertices of S·coarse against fine.
inline double subdivided_rmse(const data::PairedFrames<>& p, const Eigen::SparseMatrix<double>& S) {
  double sum = 0;
  for (Index f = 0; f < p.num_frames(); ++f) {
    const Points<> up = S * Points<>(p.lr(f));
    sum += (up - p.hr(f)).squaredNorm();
  }
  return std::sqrt(sum / double(std::max<Index>(1, p.num_frames() * p.num_hr())));
}

/// A frame of one resolution, its failure made specific.
template <class P, class Sim, class Move>
ClothFrameReport advance_frame(P policy, Sim& sim, const Move& move, const std::string& seq, Index frame, const char* resolution) {
  try {
    return sim.advance(policy, move);
  } catch (const ConvergenceError& e) {
    throw Error("cloth datagen: sequence '" + seq + "', frame " + std::to_string(frame) + ", " + resolution + " solve failed: " + e.what());
  }
}

/// One frame of both resolutions (coarse first), each timed: what on_frame reports. The fine
/// cloth stays where it is (a report of zeros) when its frames come from elsewhere (`fine_too`).
struct PairFrame {
  ClothFrameReport coarse, fine;
  double coarse_seconds = 0, fine_seconds = 0;
};
template <class P, class Sim, class Move>
PairFrame advance_pair(P policy, Sim& coarse, Sim& fine, const Move& move, const std::string& seq, Index frame, bool fine_too = true) {
  PairFrame r;
  const auto t0 = std::chrono::steady_clock::now();
  r.coarse = advance_frame(policy, coarse, move, seq, frame, "coarse");
  const auto t1 = std::chrono::steady_clock::now();
  if (fine_too) r.fine = advance_frame(policy, fine, move, seq, frame, "fine");
  const auto t2 = std::chrono::steady_clock::now();
  r.coarse_seconds = std::chrono::duration<double>(t1 - t0).count();
  r.fine_seconds = std::chrono::duration<double>(t2 - t1).count();
  return r;
}

/// What generate_cloth_data hands each scene's simulation: the meshes, options, paths, and per
/// sequence its frame count, fingerprint and checkpoint (read and checked before anything runs).
struct ClothDatagenRun {
  ClothDataset dataset;
  const ClothPair& pair;
  const ClothDatagenOptions& opt;
  const std::filesystem::path& dir;
  const std::filesystem::path& state;  ///< DIR/.state
  const std::vector<Index>& frames;
  const std::vector<std::string>& prints;
  const std::vector<std::string>& fine_prints;  ///< cloth_fine_fingerprint of each sequence
  const std::vector<std::optional<io::NpzArrays>>& checkpoints;
  const std::string& settle_print;
  Index workers;  ///< sequences at once (sequence_worker_count)
  Index coarse_vertices() const { return pair.coarse.V.rows(); }
  Index fine_vertices() const { return pair.fine.V.rows(); }
};

/// Both cloths' state: positions, the previous step's, the last step length ([0] coarse, [1] fine).
struct ClothPairState {
  Points<> x[2], previous[2];
  double last_step[2] = {0, 0};
  template <class Sim>
  static ClothPairState of(const Sim& coarse, const Sim& fine) {
    ClothPairState s;
    s.x[0] = coarse.positions(), s.previous[0] = coarse.previous_positions(), s.last_step[0] = coarse.last_step();
    s.x[1] = fine.positions(), s.previous[1] = fine.previous_positions(), s.last_step[1] = fine.last_step();
    return s;
  }
  /// Read from a settle file or a sequence checkpoint (`file` names it in errors).
  static ClothPairState read(const io::NpzArrays& z, Index N, Index M, const std::string& file) {
    ClothPairState s;
    s.x[0] = io::points_of(z, "coarse", N, file), s.previous[0] = io::points_of(z, "coarse_previous", N, file);
    s.x[1] = io::points_of(z, "fine", M, file), s.previous[1] = io::points_of(z, "fine_previous", M, file);
    s.last_step[0] = io::scalar_of(z, "coarse_last_step", file), s.last_step[1] = io::scalar_of(z, "fine_last_step", file);
    return s;
  }
  void add_to(io::NpzArrays& z) const {
    z["coarse"] = io::make_npy(x[0]);
    z["coarse_previous"] = io::make_npy(previous[0]);
    z["fine"] = io::make_npy(x[1]);
    z["fine_previous"] = io::make_npy(previous[1]);
    z["coarse_last_step"] = io::make_npy<double>({}, &last_step[0]);
    z["fine_last_step"] = io::make_npy<double>({}, &last_step[1]);
  }
  template <class Sim>
  void set(Sim& coarse, Sim& fine, Index steps) const {
    coarse.set_state(x[0], previous[0], steps, last_step[0]);
    fine.set_state(x[1], previous[1], steps, last_step[1]);
  }
};

/// The settled start of every sequence: read from DIR/.state/settled.npz when it is this run's,
/// else settled (`settle_frames` with the obstacle `still`) and written there.
template <exec::HostPolicy P, class O, class Linear>
ClothPairState settled_cloth_start(P policy, const ClothDatagenRun& run, ClothSimulator<O, Linear>& coarse, ClothSimulator<O, Linear>& fine,
                                   const std::function<void(O&, double)>& still) {
  const auto file = run.state / "settled.npz";
  if (std::filesystem::exists(file)) {
    const auto z = io::read_npz(file);
    if (io::fingerprint_of(z) == run.settle_print) return ClothPairState::read(z, run.coarse_vertices(), run.fine_vertices(), file.string());
  }
  for (Index f = 0; f < run.opt.settle_frames; ++f) {
    const PairFrame p = advance_pair(policy, coarse, fine, still, "settle", f);
    if (run.opt.on_settle_frame) run.opt.on_settle_frame("settle", f, run.opt.settle_frames, p.coarse, p.fine, p.coarse_seconds, p.fine_seconds);
  }
  const ClothPairState s = ClothPairState::of(coarse, fine);
  io::NpzArrays z;
  s.add_to(z);
  io::set_fingerprint(z, run.settle_print);
  io::write_npz(file, z);
  return s;
}

/// Sequence k from `start_state` (or from its checkpoint) into DIR/<name>.npz, checkpointing as
/// it goes, `on_frame` (may be empty) after every frame; a finished file of this run is reused.
/// Returns its figures.
template <exec::HostPolicy P, class O, class Linear, class AirFor>
ClothSequenceStats simulate_cloth_sequence(P policy, const ClothDatagenRun& run, Index k, ClothSimulator<O, Linear>& coarse, ClothSimulator<O, Linear>& fine,
                                           const ClothPairState& start_state, const std::function<void(O&, double)>& move, const AirFor& air_for,
                                           const ClothDatagenOptions::FrameCallback& on_frame) {
  const Index N = run.coarse_vertices(), M = run.fine_vertices();
  const ClothDatagenOptions& opt = run.opt;
  ClothSequenceStats st;
  st.name = cloth_sequence_name(run.dataset, k);
  st.test = cloth_sequence_is_test(k);
  const Index F = run.frames[std::size_t(k)];
  st.frames = F;
  const std::string& print = run.prints[std::size_t(k)];
  const auto final_file = run.dir / (st.name + ".npz");
  const auto partial = run.state / (st.name + ".npz");
  if (std::filesystem::exists(final_file)) {
    const auto z = io::read_npz(final_file);
    if (io::fingerprint_of(z) == print) {
      st.reused = true;
      st.subdivided_rmse = subdivided_rmse(data::read_paired_frames(final_file, N, M), run.pair.subdivision);
      return st;
    }
  }
  // the fine frames of ClothDatagenOptions::fine_frames_from (its fingerprints checked before the run)
  std::optional<data::PairedFrames<>> fine_source;
  if (!opt.fine_frames_from.empty()) {
    const auto file = opt.fine_frames_from / (st.name + ".npz");
    fine_source = data::read_paired_frames(file);
    if (fine_source->num_frames() != F || fine_source->num_hr() != M)
      throw ShapeError(file.string() + ": fine frames (frames, vertices) for " + st.name, {F, M}, {fine_source->num_frames(), fine_source->num_hr()});
    st.fine_reused = true;
  }
  data::PairedFrames<> out = data::PairedFrames<>::one_sequence(F, N, M, st.name);
  Index start = 0;
  start_state.set(coarse, fine, 0);
  if (const auto& checkpoint = run.checkpoints[std::size_t(k)]) {
    start = data::resume_frames(*checkpoint, partial.string(), out);
    ClothPairState::read(*checkpoint, N, M, partial.string()).set(coarse, fine, start * opt.simulation.substeps);
  }
  for (Index f = start; f < F; ++f) {
    coarse.set_air(air_for(k, coarse.time()));
    fine.set_air(air_for(k, fine.time()));
    const PairFrame p = advance_pair(policy, coarse, fine, move, st.name, f, !fine_source);
    const ClothFrameReport &rc = p.coarse, &rf = p.fine;
    const double sc = p.coarse_seconds, sf = p.fine_seconds;
    out.lr(f) = coarse.positions();
    if (fine_source) out.hr(f) = fine_source->hr(f);
    else out.hr(f) = fine.positions();
    st.coarse_seconds += sc;
    st.fine_seconds += sf;
    st.coarse_iterations += rc.newton_iterations;
    st.fine_iterations += rf.newton_iterations;
    st.halvings += rc.halvings + rf.halvings;
    st.deepest = std::min({st.deepest, rc.deepest, rf.deepest});
    ++st.simulated;
    if (on_frame) on_frame(st.name, f, F, rc, rf, sc, sf);
    const Index done = f + 1;
    if (done < F && done % opt.checkpoint_every == 0) {
      io::NpzArrays z = data::frames_checkpoint(out, done, print);
      ClothPairState::of(coarse, fine).add_to(z);
      io::write_npz(partial, z);
    }
  }
  st.subdivided_rmse = subdivided_rmse(out, run.pair.subdivision);
  auto arrays = data::paired_frame_arrays(out);
  io::set_fingerprint(arrays, print);
  io::set_fingerprint(arrays, run.fine_prints[std::size_t(k)], "fine_fingerprint");
  io::write_npz(final_file, arrays);
  std::filesystem::remove(partial);
  return st;
}

/// Refuses a fine_frames_from folder that is the output folder, lacks a sequence, or holds a
/// sequence whose fine cloth is not this run's (ArgumentError naming the file), before anything runs.
inline void check_fine_frames_source(const std::filesystem::path& from, const std::filesystem::path& dir, ClothDataset d,
                                     const std::vector<std::string>& fine_prints) {
  if (std::filesystem::weakly_canonical(from) == std::filesystem::weakly_canonical(dir))
    throw ArgumentError("generate_cloth_data: fine_frames_from is the output folder (" + dir.string() + "): name the other dataset's folder");
  for (std::size_t k = 0; k < fine_prints.size(); ++k) {
    const auto file = from / (cloth_sequence_name(d, Index(k)) + ".npz");
    if (!std::filesystem::exists(file))
      throw ArgumentError(file.string() + ": no such file, so its fine frames can't be reused (fine_frames_from must be a finished dataset of this scene with at least this run's sequences)");
    io::NpzReader z(file);  // reads the one member
    const std::string print = io::fingerprint_of(z, "fine_fingerprint");
    if (print != fine_prints[k])
      throw ArgumentError(file.string() + (!print.empty() ? ": its fine cloth is another simulation's (another fine mesh, seed, sequence count or simulation option)"
                                               : ": carries no fine-cloth fingerprint (written before they were)") +
                          ", so its fine frames can't stand in for this run's");
  }
}

/// How many sequences run at once (ClothDatagenOptions::sequence_workers).
template <exec::HostPolicy P>
Index sequence_worker_count(P, const ClothDatagenOptions& o) {
  if (o.sequence_workers < 0) throw ArgumentError("generate_cloth_data: sequence_workers must be >= 0 (0: the policy's threads)");
  if constexpr (std::is_same_v<std::remove_cvref_t<P>, exec::seq_t>) {
    if (o.sequence_workers > 1)
      throw ArgumentError("generate_cloth_data: sequence_workers = " + std::to_string(o.sequence_workers) +
                          " under exec::seq, which runs on the calling thread: pass exec::omp");
    return 1;
  } else {
    return o.sequence_workers > 0 ? o.sequence_workers : Index(exec::omp_max_threads());
  }
}

/// One scene's sequences (a function template over the obstacle type, since SHEET's and DISK's
/// differ): make_obstacle(k) the obstacle at the start of sequence k (k < 0: while settling),
/// move_for(k) its motion, air_for(k, t) the air. Appends each sequence's figures to `stats`.
template <class Linear, exec::HostPolicy P, class MakeObstacle, class MoveFor, class AirFor>
void simulate_cloth_scene(P policy, const ClothDatagenRun& run, const MakeObstacle& make_obstacle, const MoveFor& move_for, const AirFor& air_for,
                          std::vector<ClothSequenceStats>& stats) {
  using O = std::decay_t<decltype(make_obstacle(Index(0)))>;
  using Sim = ClothSimulator<O, Linear>;
  auto simulator = [&](const TriMesh<>& cloth, const IndexVector& pins) { return Sim(cloth, pins, make_obstacle(-1), run.opt.material, run.opt.simulation); };
  auto sequence = [&](auto pol, Index k, Sim& c, Sim& f, const ClothPairState& start, const ClothDatagenOptions::FrameCallback& on_frame) {
    return simulate_cloth_sequence(pol, run, k, c, f, start, std::function<void(O&, double)>(move_for(k)), air_for, on_frame);
  };
  Sim coarse = simulator(run.pair.coarse, run.pair.pinned), fine = simulator(run.pair.fine, run.pair.fine_pinned);
  const std::function<void(O&, double)> still = [&](O& o, double) { o = make_obstacle(-1); };
  const ClothPairState start = settled_cloth_start(policy, run, coarse, fine, still);
  const Index count = Index(run.frames.size()), workers = std::min(count, run.workers);
  if (workers <= 1) {
    for (Index k = 0; k < count; ++k) stats.push_back(sequence(policy, k, coarse, fine, start, run.opt.on_frame));
    return;
  }
  // Side by side: each worker its own pair of simulators and the next sequence not yet taken,
  // run with exec::seq; on_frame under a lock. A failed sequence stops its worker; the others
  // finish the sequence they have and take no new one (nothing simulated is lost), then the
  // first error is thrown.
  std::mutex lock;
  ClothDatagenOptions::FrameCallback locked;
  if (run.opt.on_frame)
    locked = [&](const std::string& s, Index f, Index F, const ClothFrameReport& c, const ClothFrameReport& fi, double sc, double sf) {
      const std::lock_guard<std::mutex> hold(lock);
      run.opt.on_frame(s, f, F, c, fi, sc, sf);
    };
  std::vector<ClothSequenceStats> done(static_cast<std::size_t>(count));
  std::atomic<Index> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  auto work = [&] {
    try {
      const EigenSingleThreaded eigen_serial;  // this thread's Eigen products stay on it
      Sim c = simulator(run.pair.coarse, run.pair.pinned), f = simulator(run.pair.fine, run.pair.fine_pinned);
      for (Index k; !failed.load() && (k = next.fetch_add(1)) < count;) done[std::size_t(k)] = sequence(exec::seq, k, c, f, start, locked);
    } catch (...) {
      const std::lock_guard<std::mutex> hold(lock);
      if (!error) error = std::current_exception();
      failed.store(true);
    }
  };
  std::vector<std::thread> threads;
  threads.reserve(std::size_t(workers));
  for (Index w = 0; w < workers; ++w) threads.emplace_back(work);
  for (auto& t : threads) t.join();
  if (error) std::rethrow_exception(error);
  stats.insert(stats.end(), done.begin(), done.end());
}

}  // namespace detail

/// Simulates the dataset into `dir` (see the file comment). Returns the figures of this run,
/// also written to DIR/cloth_data.json. Linear is both simulators' Newton linear solver
/// (ClothSimulator): the data is the same to the solver's round-off whichever it is, so it is no
/// part of the fingerprint and a run may be resumed with the other one;
/// `generate_cloth_data<physics::CholmodCholesky<>>(...)` is ~3× faster at the fine SHEET's 4,225
/// vertices (README).
template <class Linear = physics::SparseCholesky<>, exec::HostPolicy P>
std::vector<ClothSequenceStats> generate_cloth_data(P policy, ClothDataset d, const std::filesystem::path& dir, const ClothDatagenOptions& opt = {}) {
  checked_cloth_options(opt.simulation);  // before anything is written
  if (opt.checkpoint_every < 1) throw ArgumentError("generate_cloth_data: checkpoint_every must be >= 1");
  const Index workers = detail::sequence_worker_count(policy, opt);  // its ArgumentError before anything is written
  if (opt.settle_frames < 0) throw ArgumentError("generate_cloth_data: settle_frames must be >= 0");
  if (!(opt.extra_seconds >= 0) || !std::isfinite(opt.extra_seconds)) throw ArgumentError("generate_cloth_data: extra_seconds must be finite and >= 0");
  const ClothSceneSize size = opt.size.levels < 0 ? default_scene_size(d) : opt.size;
  const Index count = opt.sequences > 0 ? opt.sequences : (d == ClothDataset::sheet ? 32 : 16);
  const ClothPair pair = cloth_pair(d, size);
  const Index N = pair.coarse.V.rows(), M = pair.fine.V.rows();
  const double dt = opt.simulation.frame_time;

  // the sequences, their frame counts and fingerprints; another run's checkpoints refused first
  const auto sheets = d == ClothDataset::sheet ? sheet_sequences(count, opt.seed) : std::vector<SheetSequence>{};
  const auto disks = d == ClothDataset::disk ? disk_sequences(count, opt.seed) : std::vector<DiskSequence>{};
  std::vector<Index> frames(static_cast<std::size_t>(count));
  for (Index k = 0; k < count; ++k) {
    const double seconds = d == ClothDataset::sheet ? sheets[std::size_t(k)].duration() + opt.extra_seconds : disks[std::size_t(k)].duration();
    frames[std::size_t(k)] = std::max<Index>(1, Index(std::llround(seconds / dt)));
  }
  auto parameters_of = [&](Index k) { return d == ClothDataset::sheet ? sequence_parameters(sheets[std::size_t(k)]) : sequence_parameters(disks[std::size_t(k)]); };
  auto values_of = [&](Index k) {
    std::vector<double> v;
    for (const auto& p : parameters_of(k)) v.push_back(p.value);
    return v;
  };
  const auto state = dir / ".state";
  const std::vector<double> settle_values = d == ClothDataset::sheet ? values_of(0) : std::vector<double>{};
  std::vector<std::string> prints, fine_prints;
  std::vector<std::optional<io::NpzArrays>> checkpoints;
  for (Index k = 0; k < count; ++k) {
    prints.push_back(detail::cloth_fingerprint(d, pair, opt, k, frames[std::size_t(k)], values_of(k)));
    fine_prints.push_back(detail::cloth_fine_fingerprint(d, pair, opt, k, frames[std::size_t(k)], values_of(k), settle_values));
    const auto partial = state / (cloth_sequence_name(d, k) + ".npz");
    checkpoints.emplace_back();
    if (!std::filesystem::exists(partial)) continue;
    checkpoints.back() = io::read_npz(partial);
    if (io::fingerprint_of(*checkpoints.back()) != prints.back())
      throw ArgumentError(partial.string() + " is a checkpoint of another run (another scene, size, seed or parameters): remove it or use another directory");
  }
  if (!opt.fine_frames_from.empty()) detail::check_fine_frames_source(opt.fine_frames_from, dir, d, fine_prints);
  std::filesystem::create_directories(state);
  {
    io::MeshData<double> c, f;
    c.V = pair.coarse.V;
    c.F = pair.coarse.F;
    f.V = pair.fine.V;
    f.F = pair.fine.F;
    io::write_mesh(dir / "coarse_rest.obj", c);
    io::write_mesh(dir / "fine_rest.obj", f);
  }

  // SHEET settles with the first sequence's obstacle at its start (above the sheet)
  const std::string settle_print = detail::cloth_fingerprint(d, pair, opt, -1, opt.settle_frames, settle_values);

  const detail::ClothDatagenRun run{d, pair, opt, dir, state, frames, prints, fine_prints, checkpoints, settle_print, workers};
  std::vector<ClothSequenceStats> stats;
  if (d == ClothDataset::sheet) {
    detail::simulate_cloth_scene<Linear>(
        policy, run, [&](Index k) { return k < 0 ? sheets[0].obstacle_at(0) : sheets[std::size_t(k)].obstacle_at(0); },
        [&](Index k) { return std::function<void(physics::Capsule<>&, double)>([&, k](physics::Capsule<>& o, double t) { o = sheets[std::size_t(k)].obstacle_at(t); }); },
        [](Index, double) { return Air{}; }, stats);
  } else {
    detail::simulate_cloth_scene<Linear>(
        policy, run, [](Index) { return disk_table(); }, [](Index) { return std::function<void(physics::RoundedCylinder<>&, double)>(); },
        [&](Index k, double t) { return disks[std::size_t(k)].air_at(t); }, stats);
  }

  // the summary
  nlohmann::ordered_json j;
  j["scene"] = to_string(d);
  j["coarse"] = {{"vertices", N}, {"triangles", pair.coarse.F.rows()}};
  j["coarse_cells"] = size.coarse_cells;
  j["fine"] = {{"vertices", M}, {"triangles", pair.fine.F.rows()}, {"loop_levels", size.levels}, {"cells", size.fine_source_cells()}};
  if (!opt.fine_frames_from.empty()) j["fine_frames_from"] = opt.fine_frames_from.string();
  j["seed"] = opt.seed;
  j["frame_time_s"] = dt;
  j["substeps"] = opt.simulation.substeps;
  const physics::NewtonOptions& newton = opt.simulation.newton;
  j["newton"] = {{"max_iterations", newton.max_iterations},
                 {"accept_at_max_iterations", newton.accept_at_max_iterations},
                 {"relative_tolerance", newton.relative_tolerance},
                 {"hessian", physics::hessian_name(newton.hessian)}};
  nlohmann::ordered_json seqs = nlohmann::ordered_json::array();
  Index train_frames = 0, test_frames = 0;
  for (std::size_t k = 0; k < stats.size(); ++k) {
    const ClothSequenceStats& s = stats[k];
    (s.test ? test_frames : train_frames) += s.frames;
    nlohmann::ordered_json e{{"name", s.name}, {"split", s.test ? "test" : "train"}, {"frames", s.frames}, {"reused", s.reused},
                             {"simulated", s.simulated}, {"subdivided_rmse_m", s.subdivided_rmse}};
    if (s.fine_reused) e["fine_reused"] = true;
    nlohmann::ordered_json& scene = e["scene"] = nlohmann::ordered_json::object();
    for (const auto& p : parameters_of(Index(k))) scene[p.name] = p.value;
    if (s.simulated > 0) {
      e["coarse_seconds_per_frame"] = s.coarse_seconds / double(s.simulated);
      e["fine_seconds_per_frame"] = s.fine_seconds / double(s.simulated);
      e["coarse_newton_per_frame"] = double(s.coarse_iterations) / double(s.simulated);
      e["fine_newton_per_frame"] = double(s.fine_iterations) / double(s.simulated);
      e["halved_steps"] = s.halvings;
      e["deepest_m"] = s.deepest;
    }
    seqs.push_back(e);
  }
  j["train_frames"] = train_frames;
  j["test_frames"] = test_frames;
  j["sequences"] = seqs;
  io::write_file_atomic(dir / "cloth_data.json", j.dump(2) + "\n");
  return stats;
}

}  // namespace simsr::shell
