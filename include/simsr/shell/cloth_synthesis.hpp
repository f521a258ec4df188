#pragma once
/// \file
/// Detail synthesis on a cloth dataset end to end (Chen et al. 2023): TS-ACAP features of every
/// sequence at both resolutions, training of DetailSynthesisNet on the training sequences
/// (resumable: a checkpoint after every epoch), and evaluation on the held-out sequences against
/// the fine simulation, with the Loop-subdivided coarse mesh as the baseline and the supplement's
/// Table 1 stages timed per frame (TS-ACAP extraction, synthesis, collision refinement).
///
///     const shell::ClothData data = shell::read_cloth_data("sheet_data");
///     shell::ClothSynthesis run(exec::omp, data);                    // TS-ACAP of every frame
///     run.train(exec::omp, {.epochs = 60, .checkpoint = "sheet_data/.state/train.npz"});
///     const shell::ClothEvaluation e = run.evaluate(exec::omp);

#include <chrono>
#include <filesystem>
#include <functional>
#include <numbers>
#include <numeric>
#include <optional>

#include "../core/fingerprint.hpp"
#include "../io/run_file.hpp"
#include "../nn/adam_state.hpp"
#include "cloth_data.hpp"
#include "collision_refinement.hpp"
#include "detail_synthesis.hpp"

namespace simsr::shell {

struct ClothTrainingOptions {
  Index epochs = 60;  ///< the supplement's 200 with lr ×0.1 every 20 would train 140 epochs at lr ≤ 1e-6
  Index batch = 16;   ///< windows per Adam step (not printed in the supplement)
  std::uint64_t seed = 1;
  std::filesystem::path checkpoint;  ///< "" none; else written after every epoch and resumed from
};

struct ClothEpochReport {
  Index epoch = 0, epochs = 0;
  double lr = 0;
  SynthesisLoss loss;  ///< means over the epoch's steps
  double seconds = 0;
};

/// One held-out sequence: RMS vertex distance (m) to the fine simulation over all its frames.
struct ClothSequenceEvaluation {
  std::string name;
  Index frames = 0;
  double subdivided_rmse = 0;   ///< the coarse mesh Loop-subdivided to the fine topology
  double synthesized_rmse = 0;  ///< the network's, before collision refinement
  double refined_rmse = 0;      ///< after it
  double decoded_truth_rmse = 0;  ///< the true fine features decoded the same way: the representation's floor
  /// the subdivided coarse mesh's features decoded the same way: what a residual network that
  /// outputs zero gives (it differs from subdivided_rmse by what the decoding moves)
  double decoded_subdivided_rmse = 0;
  Index inside_before = 0, projected = 0;  ///< vertex-frames inside the obstacle before; left to projection
  double deepest_before = 0, deepest_after = 0;
  std::vector<double> frame_subdivided, frame_synthesized, frame_refined;  ///< per-frame RMS distances
};

/// Mean seconds per frame of the supplement's Table 1 stages, measured on this machine.
struct ClothTimings {
  double ts_acap = 0;     ///< coarse TS-ACAP extraction
  double synthesis = 0;   ///< network and fine positions (Poisson solve)
  double refinement = 0;  ///< collision refinement
};

struct ClothEvaluation {
  std::vector<ClothSequenceEvaluation> sequences;
  double subdivided_rmse = 0, synthesized_rmse = 0, refined_rmse = 0;  ///< over all held-out vertex-frames
  double decoded_truth_rmse = 0, decoded_subdivided_rmse = 0;
  ClothTimings timings;
  Index frames = 0;
};

/// Rotation-vector jumps of more than π in a dataset's features: between a vertex's consecutive
/// frames (temporal) and between the ends of an edge (spatial). A jump that large is a 2π cycle
/// or an axis flip the integer steps (Eq. 2–4) failed to make consistent: it decodes to the same
/// mesh, but the network must learn a discontinuity. This is what replacing CoMISo's solver by
/// propagation + local improvement can cost; 0 means nothing.
struct FeatureJumps {
  /// Vertices whose rotation vectors in a and b lie more than π apart.
  static Index beyond_pi(const TsAcapFeatures<double>& a, const TsAcapFeatures<double>& b) {
    return ((a.leftCols<3>() - b.leftCols<3>()).rowwise().norm().array() > std::numbers::pi).count();
  }

  /// One resolution's counts over every frame added.
  struct Counts {
    Index temporal = 0, spatial = 0;        ///< vertex-frames / edge-frames with a jump > π
    Index vertex_frames = 0, edge_frames = 0;
    double largest_angle = 0;               ///< the largest |Φ| met (rad)

    /// Counts a sequence's features (its frames in order) over the mesh's unique edges.
    void add(const std::vector<TsAcapFeatures<double>>& seq, const Edges& edges) {
      constexpr double pi = std::numbers::pi;
      for (std::size_t f = 0; f < seq.size(); ++f) {
        const auto rho = seq[f].leftCols<3>();
        for (Index e = 0; e < edges.rows(); ++e) spatial += (rho.row(edges(e, 0)) - rho.row(edges(e, 1))).norm() > pi;
        if (f > 0) temporal += beyond_pi(seq[f], seq[f - 1]);
        largest_angle = std::max(largest_angle, rho.rowwise().norm().maxCoeff());
        vertex_frames += rho.rows();
        edge_frames += edges.rows();
      }
    }
  };
  Counts coarse, fine;
  /// A residual target's training vertex-frames whose fine rotation vector lies more than π from
  /// the subdivided coarse frame's: as the fine sequence's own integer steps left it, and as the
  /// network is given it (after lift_rotations_toward with ResidualLift::nearest; else the same).
  Index residual_own = 0, residual_trained = 0, residual_vertex_frames = 0;

};

namespace detail {
inline double rms_distance(const Points<>& a, const Points<>& b) { return std::sqrt((a - b).rowwise().squaredNorm().mean()); }
}  // namespace detail

/// The dataset's features, the network and its training and evaluation (see the file comment).
/// `Linear` solves the collision refinement's systems (CollisionRefinement<Linear>).
template <class Linear = physics::SparseCholesky<>>
class ClothSynthesis {
 public:
  std::function<void(const ClothEpochReport&)> on_epoch;          ///< progress of train()
  std::function<void(const std::string&, Index, Index)> on_encode;  ///< (sequence, done, total) of the feature pass

  template <exec::HostPolicy P>
  ClothSynthesis(P policy, const ClothData& data, DetailSynthesisOptions options = {}, std::uint64_t seed = 1,
                 std::function<void(const std::string&, Index, Index)> progress = {})
      : data_(&data),
        coarse_acap_(policy, data.pair.coarse.V, data.pair.coarse.F),
        fine_acap_(policy, data.pair.fine.V, data.pair.fine.F),
        net_(vertex_adjacency(data.pair.coarse.F, data.num_coarse()), vertex_adjacency(data.pair.fine.F, data.num_fine()), options, seed),
        refine_(data.pair.fine) {
    on_encode = std::move(progress);
    // the fine cloth's pinned vertices, held where the coarse cloth's are, anchor the Poisson
    // solve; where a scene pins none, the subdivided coarse centroid places it
    if (data.pair.fine_pinned.size() != data.pair.pinned.size())
      throw ArgumentError("ClothSynthesis: the pair pins " + std::to_string(data.pair.pinned.size()) + " coarse and " +
                          std::to_string(data.pair.fine_pinned.size()) + " fine vertices: pin a of one must be pin a of the other");
    if (data.pair.fine_pinned.size() > 0) fine_acap_.set_anchors(data.pair.fine_pinned);
    // TS-ACAP of every frame (the fine side of the training sequences only, as the residual to
    // the subdivided coarse frames' features where the network holds residuals); the scaling from
    // the training sequences; normalized float copies
    std::vector<std::vector<TsAcapFeatures<double>>> coarse, fine;
    std::vector<const TsAcapFeatures<double>*> train_c, train_f;
    for (const auto& s : data.sequences) {
      coarse.push_back(coarse_acap_.encode_sequence(policy, s.coarse));
      feature_jumps_.coarse.add(coarse.back(), coarse_acap_.edges());
      fine.emplace_back();
      if (!s.test) {
        fine.back() = fine_acap_.encode_sequence(policy, s.fine);
        feature_jumps_.fine.add(fine.back(), fine_acap_.edges());
        if (residual()) {
          const std::vector<TsAcapFeatures<double>> base = fine_acap_.encode_sequence(policy, subdivided(s.coarse));
          for (std::size_t f = 0; f < base.size(); ++f) {
            TsAcapFeatures<double>& target = fine.back()[f];
            const Index own = FeatureJumps::beyond_pi(target, base[f]);
            feature_jumps_.residual_own += own;
            const bool lift = net_.options().residual_lift == ResidualLift::nearest && lift_rotations_toward(target, base[f]) > 0;
            feature_jumps_.residual_trained += lift ? FeatureJumps::beyond_pi(target, base[f]) : own;
            feature_jumps_.residual_vertex_frames += target.rows();
            target -= base[f];
          }
        }
      }
      if (on_encode) on_encode(s.name, Index(coarse.size()), Index(data.sequences.size()));
    }
    for (std::size_t q = 0; q < data.sequences.size(); ++q)
      if (!data.sequences[q].test) {
        for (const auto& f : coarse[q]) train_c.push_back(&f);
        for (const auto& f : fine[q]) train_f.push_back(&f);
      }
    if (train_c.empty()) throw ArgumentError("ClothSynthesis: the dataset has no training sequence");
    net_.set_scaling(FeatureScaling::fit(train_c), FeatureScaling::fit(train_f));
    for (std::size_t q = 0; q < data.sequences.size(); ++q) features_.push_back(net_.normalize(coarse[q], fine[q]));
  }

  /// Whether the network's fine side holds residuals to the subdivided coarse mesh's features.
  bool residual() const { return net_.options().fine_target == FineTarget::residual; }

  /// The coarse frames Loop-subdivided to the fine topology.
  std::vector<Points<>> subdivided(const std::vector<Points<>>& coarse) const {
    std::vector<Points<>> out;
    out.reserve(coarse.size());
    for (const auto& V : coarse) out.emplace_back(data_->pair.subdivision * V);
    return out;
  }

  /// How smooth the integer steps left the rotation features of the training data (see FeatureJumps).
  const FeatureJumps& feature_jumps() const { return feature_jumps_; }

  DetailSynthesisNet<float>& network() { return net_; }
  const TsAcap<double>& coarse_acap() const { return coarse_acap_; }
  const TsAcap<double>& fine_acap() const { return fine_acap_; }

  /// A fingerprint of the data, the network shape and the training options but the epoch count (a
  /// run may be extended), so a checkpoint of another run is refused.
  std::string fingerprint(const ClothTrainingOptions& o) const {
    Fingerprint f;
    f.add(std::int64_t(data_->scene)).add(data_->pair.coarse.F).add(data_->pair.fine.F).add(data_->seed).add(net_.store().num_parameters());
    for (const auto& s : data_->sequences) f.add(s.num_frames()).add(std::int64_t(s.test)).add(s.coarse.front()).add(s.fine.back());
    f.add(o.batch).add(o.seed).add(net_.options().lr).add(net_.options().lr_decay).add(net_.options().lr_step);
    f.add(net_.options().noise_variance).add(std::int64_t(net_.options().fine_target));
    if (residual()) f.add(std::int64_t(net_.options().residual_lift));
    return f.hex();
  }

  /// Trains on the training sequences' windows (all T-frame windows, shuffled each epoch).
  /// With a checkpoint path, resumes a run of the same fingerprint and refuses another's.
  template <exec::HostPolicy P>
  std::vector<ClothEpochReport> train(P policy, const ClothTrainingOptions& o) {
    if (o.epochs < 0 || o.batch < 1) throw ArgumentError("ClothSynthesis::train: epochs >= 0 and batch >= 1 are required");
    const Index T = net_.frames();
    std::vector<std::pair<Index, Index>> windows;
    for (std::size_t q = 0; q < data_->sequences.size(); ++q)
      if (!data_->sequences[q].test)
        for (Index s = 0; s + T <= features_[q].frames; ++s) windows.emplace_back(Index(q), s);
    if (windows.empty()) throw ArgumentError("ClothSynthesis::train: no training sequence has " + std::to_string(T) + " frames");
    const std::string print = fingerprint(o);
    std::vector<ClothEpochReport> history;
    Index start = 0;
    if (!o.checkpoint.empty() && std::filesystem::exists(o.checkpoint)) start = resume(o.checkpoint, print, history);
    for (Index epoch = start; epoch < o.epochs; ++epoch) {
      const auto t0 = std::chrono::steady_clock::now();
      const double lr = net_.options().lr * std::pow(net_.options().lr_decay, double(epoch / net_.options().lr_step));
      net_.optimizer().set_lr(lr);
      nn::Rng rng(o.seed * 1000003u + std::uint64_t(epoch));  // per epoch: a resumed run draws what an unbroken one would
      std::vector<std::pair<Index, Index>> order = windows;  // from the same order every epoch
      std::shuffle(order.begin(), order.end(), rng);
      ClothEpochReport rep;
      rep.epoch = epoch + 1, rep.epochs = o.epochs, rep.lr = lr;
      Index steps = 0;
      for (std::size_t first = 0; first < windows.size(); first += std::size_t(o.batch)) {
        SynthesisBatch b;
        b.windows.assign(order.begin() + std::ptrdiff_t(first), order.begin() + std::ptrdiff_t(std::min(order.size(), first + std::size_t(o.batch))));
        const SynthesisLoss l = net_.train_step(policy, features_, b, rng);
        rep.loss.synthesis += l.synthesis, rep.loss.reconstruction += l.reconstruction, rep.loss.latent += l.latent;
        ++steps;
      }
      rep.loss.synthesis /= double(steps), rep.loss.reconstruction /= double(steps), rep.loss.latent /= double(steps);
      rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      history.push_back(rep);
      if (!o.checkpoint.empty()) save_checkpoint(o.checkpoint, print, history);
      if (on_epoch) on_epoch(rep);
    }
    return history;
  }

  /// The fine positions of held-out sequence q, frame by frame, from its coarse frames only:
  /// features → network → fine features → positions (the pinned vertices where the coarse frame
  /// has them; else the subdivided coarse mesh's centroid) →
  /// collision refinement against the scene's obstacle. `timings` (optional) gets seconds summed.
  template <exec::HostPolicy P>
  std::vector<Points<>> synthesize(P policy, Index q, ClothTimings* timings = nullptr, ClothSequenceEvaluation* eval = nullptr,
                                   std::vector<Points<>>* unrefined = nullptr) {
    using clock = std::chrono::steady_clock;
    const ClothSequenceFrames& s = data_->sequences.at(std::size_t(q));
    const Index F = s.num_frames();
    // TS-ACAP extraction of the coarse frames, as a new simulation would be read (and of the
    // subdivided coarse frames where the network adds residuals to them)
    auto t0 = clock::now();
    TsAcapState<double> state, base_state;
    std::vector<TsAcapFeatures<double>> coarse, base;
    coarse.reserve(std::size_t(F));
    Points<> subdivided_frame(data_->num_fine(), 3);
    for (const auto& V : s.coarse) {
      coarse.push_back(coarse_acap_.encode(policy, V, state));
      if (residual()) {
        subdivided_frame.noalias() = data_->pair.subdivision * V;
        base.push_back(fine_acap_.encode(policy, subdivided_frame, base_state));
      }
    }
    auto t1 = clock::now();
    const SequenceFeatures<float> in = net_.normalize(coarse, {});
    const nn::Matrix<float> fine = net_.synthesize(policy, in.coarse);
    std::vector<Points<>> out(static_cast<std::size_t>(F));
    const Index M = data_->num_fine();
    for (Index f = 0; f < F; ++f) {
      TsAcapFeatures<double> features = net_.fine_scaling().denormalize<float>(fine.middleRows(f * M, M));
      if (residual()) features += base[std::size_t(f)];
      out[std::size_t(f)] = positions(policy, features, s.coarse[std::size_t(f)]);
    }
    auto t2 = clock::now();
    if (unrefined) *unrefined = out;
    for (Index f = 0; f < F; ++f)
      data_->with_obstacle(s.index, f, [&](const auto& obstacle) {
        const CollisionRefinementReport r = refine_.refine(policy, obstacle, out[std::size_t(f)]);
        if (eval) {
          eval->inside_before += r.inside_before;
          eval->projected += r.projected;
          eval->deepest_before = std::min(eval->deepest_before, r.deepest_before);
          eval->deepest_after = std::min(eval->deepest_after, r.deepest_after);
        }
      });
    auto t3 = clock::now();
    if (timings) {
      timings->ts_acap += std::chrono::duration<double>(t1 - t0).count();
      timings->synthesis += std::chrono::duration<double>(t2 - t1).count();
      timings->refinement += std::chrono::duration<double>(t3 - t2).count();
    }
    return out;
  }

  /// Fine positions from fine features: the Poisson solve with the pinned vertices where the
  /// coarse frame has them, or (no pins) translated to the subdivided coarse frame's centroid.
  template <exec::HostPolicy P>
  Points<> positions(P policy, const TsAcapFeatures<double>& fine, const Points<>& coarse) const {
    if (data_->pair.pinned.size() > 0) {
      Points<> at(data_->pair.pinned.size(), 3);
      for (Index a = 0; a < at.rows(); ++a) at.row(a) = coarse.row(data_->pair.pinned[a]);
      return fine_acap_.decode_anchored(policy, fine, at);
    }
    return fine_acap_.decode(policy, fine, Vec3<>((data_->pair.subdivision * coarse).colwise().mean().transpose()));
  }

  /// What evaluate() hands on per held-out sequence: its index, the synthesized and the refined
  /// frames, and its figures (so a caller can write views without synthesizing again).
  using SequenceSink = std::function<void(Index, const std::vector<Points<>>&, const std::vector<Points<>>&, const ClothSequenceEvaluation&)>;

  /// Every held-out sequence against its fine simulation (see ClothEvaluation); `sink` (optional)
  /// receives each sequence's frames.
  template <exec::HostPolicy P>
  ClothEvaluation evaluate(P policy, const SequenceSink& sink = {}) {
    ClothEvaluation e;
    double sub = 0, syn = 0, ref = 0, flo = 0, dsub = 0;
    for (std::size_t q = 0; q < data_->sequences.size(); ++q) {
      const ClothSequenceFrames& s = data_->sequences[q];
      if (!s.test) continue;
      ClothSequenceEvaluation r;
      r.name = s.name;
      r.frames = s.num_frames();
      std::vector<Points<>> raw;
      const std::vector<Points<>> refined = synthesize(policy, Index(q), &e.timings, &r, &raw);
      double a = 0, b = 0, c = 0, d = 0, g = 0;
      TsAcapState<double> truth_state, sub_state;
      for (Index f = 0; f < r.frames; ++f) {
        const Points<>& truth = s.fine[std::size_t(f)];
        const double floor = detail::rms_distance(positions(policy, fine_acap_.encode(policy, truth, truth_state), s.coarse[std::size_t(f)]), truth);
        d += floor * floor;
        const Points<> subdivided = data_->pair.subdivision * s.coarse[std::size_t(f)];
        const double zero = detail::rms_distance(positions(policy, fine_acap_.encode(policy, subdivided, sub_state), s.coarse[std::size_t(f)]), truth);
        g += zero * zero;
        r.frame_subdivided.push_back(detail::rms_distance(subdivided, truth));
        r.frame_synthesized.push_back(detail::rms_distance(raw[std::size_t(f)], truth));
        r.frame_refined.push_back(detail::rms_distance(refined[std::size_t(f)], truth));
        a += r.frame_subdivided.back() * r.frame_subdivided.back();
        b += r.frame_synthesized.back() * r.frame_synthesized.back();
        c += r.frame_refined.back() * r.frame_refined.back();
      }
      r.subdivided_rmse = std::sqrt(a / double(r.frames));
      r.synthesized_rmse = std::sqrt(b / double(r.frames));
      r.refined_rmse = std::sqrt(c / double(r.frames));
      r.decoded_truth_rmse = std::sqrt(d / double(r.frames));
      r.decoded_subdivided_rmse = std::sqrt(g / double(r.frames));
      sub += a, syn += b, ref += c, flo += d, dsub += g;
      e.frames += r.frames;
      if (sink) sink(Index(q), raw, refined, r);
      e.sequences.push_back(std::move(r));
    }
    if (e.frames == 0) throw ArgumentError("ClothSynthesis::evaluate: the dataset has no held-out sequence");
    e.subdivided_rmse = std::sqrt(sub / double(e.frames));
    e.synthesized_rmse = std::sqrt(syn / double(e.frames));
    e.refined_rmse = std::sqrt(ref / double(e.frames));
    e.decoded_truth_rmse = std::sqrt(flo / double(e.frames));
    e.decoded_subdivided_rmse = std::sqrt(dsub / double(e.frames));
    e.timings.ts_acap /= double(e.frames);
    e.timings.synthesis /= double(e.frames);
    e.timings.refinement /= double(e.frames);
    return e;
  }

 private:
  void save_checkpoint(const std::filesystem::path& file, const std::string& print, const std::vector<ClothEpochReport>& history) const {
    io::NpzArrays z;
    nn::add_state(z, net_.store());
    nn::add_adam_state(z, net_.store(), net_.optimizer());
    std::vector<double> h;
    for (const auto& r : history) h.insert(h.end(), {r.lr, r.loss.synthesis, r.loss.reconstruction, r.loss.latent, r.seconds});
    z["train/history"] = io::make_npy<double>({std::int64_t(history.size()), 5}, h.data());
    io::set_fingerprint(z, print);
    std::filesystem::create_directories(file.parent_path().empty() ? "." : file.parent_path());
    io::write_npz(file, z);
  }
  Index resume(const std::filesystem::path& file, const std::string& print, std::vector<ClothEpochReport>& history) {
    const io::NpzArrays z = io::read_npz(file);
    if (io::fingerprint_of(z) != print)
      throw ArgumentError(file.string() + ": a training checkpoint of another run (other data, network or options); remove it to start over");
    nn::load_state(net_.store(), z);
    net_.optimizer().load_state(nn::read_adam_state(z, net_.store(), file.string()));
    if (!z.contains("train/history")) throw ArgumentError(file.string() + ": the checkpoint has no 'train/history'");
    const auto h = z.at("train/history").to_vector<double>();
    const Index epochs = Index(h.size() / 5);
    for (Index e = 0; e < epochs; ++e) {
      ClothEpochReport r;
      r.epoch = e + 1, r.lr = h[std::size_t(5 * e)], r.loss.synthesis = h[std::size_t(5 * e + 1)];
      r.loss.reconstruction = h[std::size_t(5 * e + 2)], r.loss.latent = h[std::size_t(5 * e + 3)], r.seconds = h[std::size_t(5 * e + 4)];
      history.push_back(r);
    }
    return epochs;
  }

  const ClothData* data_;
  TsAcap<double> coarse_acap_, fine_acap_;
  DetailSynthesisNet<float> net_;
  CollisionRefinement<Linear> refine_;
  std::vector<SequenceFeatures<float>> features_;
  FeatureJumps feature_jumps_;
};

}  // namespace simsr::shell
