#pragma once
/// \file
/// Training of the super-resolution network (SPEC §7 "training"; issue #4 item 3): paired frames
/// normalized as the official dataset.py, shuffled mini-batches over epochs, Adam, the config's
/// loss, a progress line with the loss terms, held-out evaluation, and checkpoints that resume to
/// the identical continuation (weights, BatchNorm statistics, Adam moments, the shuffling RNG,
/// the epoch and step counters all saved).
///
///     nn::TrainingFrames<float> data = nn::training_frames<float>(cfg, lr_rest, hr_rest, lowres, highres, train_ids);
///     nn::Trainer<float> trainer(net, hr_faces, std::move(data), {.epochs = 40, .seed = 1});
///     trainer.run(exec::omp);                // or: trainer.load_checkpoint(p); trainer.run(exec::omp);
///     trainer.save_checkpoint("ckpt.npz", model_data);
///
/// Determinism: the shuffle is a Fisher–Yates over a 64-bit Mersenne twister seeded by `seed`,
/// dropout masks are reseeded from it at every step, and every kernel gives the same bits under
/// exec::seq and exec::omp, so a seed fixes the run.
///
/// No silent failure (issue #10): the loss is checked before anything moves (backward, the
/// optimizer step), the gradients before the step and the weights and BatchNorm statistics after
/// it; a non-finite value is a NumericalError naming the step and the tensor, and since every
/// model file and checkpoint writer checks the state again, a non-finite weight is never saved. A
/// non-finite held-out error is a NumericalError too. A checkpoint records the run's config,
/// options and a fingerprint of its data (training frames, held-out frames, rest shapes, faces);
/// load_checkpoint refuses one that differs and says in what.

#include <chrono>
#include <cstdio>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "../core/fingerprint.hpp"
#include "../io/npy.hpp"
#include "adam.hpp"
#include "adam_state.hpp"
#include "finite_checks.hpp"
#include "model_file.hpp"
#include "shuffle.hpp"
#include "super_resolution_loss.hpp"

namespace simsr::nn {

/// Paired frames in the network's units: ldx (F·N)×3 = norm(x^L) − norm(rest^L), hdx (F·M)×3
/// likewise for the HR surface (positions parsed to S and normalized in S, as dataset.py).
template <class S = float>
struct TrainingFrames {
  Matrix<S> ldx, hdx;
  Index frames = 0, n = 0, m = 0;
  std::vector<std::int64_t> ids;  ///< the frames' ids (the `frame` array, or their indices)
};

/// The frames `which` (indices into the F frames of lowres F×N×3 / highres F×M×3) as
/// TrainingFrames. Non-finite positions are an ArgumentError naming the frame and vertex.
template <class S, class DL, class DH>
TrainingFrames<S> training_frames(const NetworkConfig& cfg, const Eigen::MatrixBase<DL>& lr_rest, const Eigen::MatrixBase<DH>& hr_rest,
                                  const io::NpyArray& lowres, const io::NpyArray& highres, const std::vector<Index>& which,
                                  const std::vector<std::int64_t>& ids = {}) {
  TrainingFrames<S> t;
  t.n = lr_rest.rows();
  t.m = hr_rest.rows();
  t.frames = Index(which.size());
  if (lowres.num_frames() != highres.num_frames())
    throw ShapeError("nn::training_frames: highres frames", {lowres.num_frames(), t.m, 3}, {highres.num_frames(), highres.ndim() > 1 ? highres.shape[1] : 0});
  const Matrix<S> lr0 = normalize_positions<S>(lr_rest, cfg.norm_mean, cfg.norm_std);
  const Matrix<S> hr0 = normalize_positions<S>(hr_rest, cfg.norm_mean, cfg.norm_std);
  t.ldx.resize(t.frames * t.n, 3);
  t.hdx.resize(t.frames * t.m, 3);
  for (Index i = 0; i < t.frames; ++i) {
    const Index f = which[std::size_t(i)];
    if (f < 0 || f >= lowres.num_frames()) throw ArgumentError("nn::training_frames: frame index " + std::to_string(f) + " is out of range");
    const Points<double> lo = lowres.frame_points<double>(f), hi = highres.frame_points<double>(f);
    if (lo.rows() != t.n || hi.rows() != t.m)
      throw ShapeError("nn::training_frames: frame " + std::to_string(f) + " (lowres N×3, highres M×3)", {t.n, t.m}, {lo.rows(), hi.rows()});
    for (const auto* P : {&lo, &hi})
      for (Index r = 0; r < P->rows(); ++r)
        if (!P->row(r).allFinite())
          throw ArgumentError(std::string("nn::training_frames: ") + (P == &lo ? "lowres" : "highres") + " frame " + std::to_string(f) + ", vertex " +
                              std::to_string(r) + " is not finite");
    normalized_displacements(lo, lr0, cfg.norm_mean, cfg.norm_std, t.ldx.middleRows(i * t.n, t.n));
    normalized_displacements(hi, hr0, cfg.norm_mean, cfg.norm_std, t.hdx.middleRows(i * t.m, t.m));
    if (cfg.displacement_scale != 1.0) {
      t.ldx.middleRows(i * t.n, t.n) *= S(cfg.displacement_scale);
      t.hdx.middleRows(i * t.m, t.m) *= S(cfg.displacement_scale);
    }
    t.ids.push_back(ids.empty() ? std::int64_t(f) : ids.at(std::size_t(f)));
  }
  return t;
}

/// What one epoch did (the progress line prints the same).
struct EpochReport {
  Index epoch = 0;                 ///< 1-based
  Index steps = 0;                 ///< optimizer steps so far
  double loss = 0, recon = 0, z_reg = 0, face_normals = 0, contact = 0;  ///< means over the epoch's batches
  Index penetrating = 0;           ///< contact pairs found penetrating, summed over the epoch's batches (w_contact > 0)
  double seconds = 0;
  double lr = 0;
  double holdout_mean_error = -1;  ///< mean HR vertex error (raw units) on the held-out frames, or −1
};

struct TrainerOptions {
  Index epochs = -1;           ///< −1: the config's
  Index batch_size = -1;       ///< −1: the config's
  double lr = -1;              ///< −1: the config's
  std::uint64_t seed = 0;
  bool progress = true;        ///< a progress line on stderr
  Index lr_decay_epochs = 0;   ///< 0: constant lr; else lr × lr_decay_gamma every that many epochs
  double lr_decay_gamma = 0.5;
  Index holdout_every_epochs = 1;  ///< evaluate held-out frames every that many epochs (0: never)
  std::function<void(const EpochReport&)> on_epoch;  ///< called after every epoch
  /// Data-parallel training (issue #16): the ranks that share every global batch (not owned;
  /// simsr::mpi::MpiBatchGroup), or nullptr for one process. Each rank takes its block of every
  /// batch's items (nn::BatchSplit); the run's numbers do not depend on the rank count.
  BatchGroup* group = nullptr;
};

template <class S = float, class Search = neighbors::BruteForceKnn<S>>
class Trainer {
 public:
  Trainer(SuperResolutionNet<S, Search>& net, const Tris& hr_faces, TrainingFrames<S> frames, TrainerOptions options = {})
      : net_(&net), data_(std::move(frames)), opt_(std::move(options)), split_(opt_.group), holdout_split_(opt_.group), rng_(opt_.seed),
        adam_(net.store(), {.lr = opt_.lr > 0 ? opt_.lr : net.config().lr}),
        loss_(net.config(), net.hr_rest_normalized(), hr_faces, total_steps_estimate()), hr_faces_(hr_faces) {
    if (data_.frames < 1) throw ArgumentError("nn::Trainer: no training frames");
    if (data_.n != net.lr_points() || data_.m != net.hr_points())
      throw ShapeError("nn::Trainer: frames (N, M)", {net.lr_points(), net.hr_points()}, {data_.n, data_.m});
    if (batch_size() < 1) throw ArgumentError("nn::Trainer: batch_size must be >= 1");
    if (epochs() < 0) throw ArgumentError("nn::Trainer: epochs must be >= 0");
    const Index last_batch = data_.frames - (steps_per_epoch() - 1) * batch_size();
    if (last_batch < split_.size())
      throw ArgumentError("nn::Trainer: on " + std::to_string(split_.size()) + " ranks every batch needs at least " + std::to_string(split_.size()) +
                          " items (one per rank), and the " + std::to_string(data_.frames) + " training frames in batches of " +
                          std::to_string(batch_size()) + " end with a batch of " + std::to_string(last_batch));
  }

  /// The batch split of every step (its group: TrainerOptions::group).
  const BatchSplit& batch_split() const { return split_; }
  /// Collectives made and bytes this rank received so far in training (the batch split's, and
  /// the upsampling's f_θ row groups'; the held-out evaluation's aside): 0 on one process.
  std::int64_t gathers() const {
    const BatchSplit* q = net_->upsampling().query_split();
    return split_.gathers() + (q ? q->gathers() : 0);
  }
  std::int64_t bytes_received() const {
    const BatchSplit* q = net_->upsampling().query_split();
    return split_.bytes_received() + (q ? q->bytes_received() : 0);
  }

  Index epochs() const { return opt_.epochs >= 0 ? opt_.epochs : net_->config().epochs; }
  Index batch_size() const { return std::min(opt_.batch_size > 0 ? opt_.batch_size : net_->config().batch_size, data_.frames); }
  Index steps_per_epoch() const { return (data_.frames + batch_size() - 1) / batch_size(); }
  Index epoch() const { return epoch_; }
  std::int64_t steps() const { return adam_.steps(); }
  const std::vector<EpochReport>& history() const { return history_; }
  Adam<S>& optimizer() { return adam_; }

  /// The contact term's patches (rows of the HR surface; the config's w_contact must be > 0).
  /// Part of the checkpoint's data: a checkpoint trained with other patches is refused.
  void set_contact(const ContactPatches& patches) {
    loss_.set_contact(net_->hr_rest_normalized(), patches);
    contact_fingerprint_ = patches.fingerprint();
  }

  /// Frames evaluated after each epoch (never trained on).
  void set_holdout(TrainingFrames<S> frames) {
    if (frames.n != data_.n || frames.m != data_.m) throw ShapeError("nn::Trainer: held-out frames (N, M)", {data_.n, data_.m}, {frames.n, frames.m});
    holdout_ = std::move(frames);
  }

  /// Trains from the current epoch to epochs().
  template <exec::HostPolicy Policy>
  void run(Policy policy) {
    while (epoch_ < epochs()) run_epoch(policy);
  }

  /// One epoch: a fresh permutation, then every batch (the last one may be smaller).
  template <exec::HostPolicy Policy>
  EpochReport run_epoch(Policy policy) {
    const auto t0 = std::chrono::steady_clock::now();
    adam_.set_lr(current_lr());
    shuffled_order(rng_, data_.frames, order_);
    const auto& order = order_;
    EpochReport rep;
    rep.epoch = epoch_ + 1;
    rep.lr = current_lr();
    const Index bs = batch_size(), nb = steps_per_epoch();
    for (Index b = 0; b < nb; ++b) {
      const Index first = b * bs, count = std::min(bs, data_.frames - first);
      split_.set_batch(count);
      gather(order, first + split_.first(), split_.count());  // this rank's items of the batch
      reseed_dropout();
      net_->store().zero_grad();
      const std::int64_t step = adam_.steps() + 1;  // the step this batch makes (1-based)
      typename SuperResolutionLoss<S>::Terms t;
      {
        const SplitScope scope(*this);  // the step's sums over the batch taken over the global batch, in item order
        net_->forward(policy, Mode::train, ldx_, pred_);
        t = loss_.evaluate(policy, pred_, hdx_, net_->code(), long(adam_.steps()), &d_pred_, &d_code_);
        require_finite_loss("nn::Trainer", t.total, step);
        net_->backward(policy, d_pred_, &d_code_);
      }
      require_finite_gradients("nn::Trainer", net_->store(), step);
      adam_.step(policy);
      require_finite_state("nn::Trainer (after the optimizer step)", net_->store(), step);
      rep.loss += t.total / double(nb);
      rep.recon += t.recon / double(nb);
      rep.z_reg += t.z_reg / double(nb);
      rep.face_normals += t.face_normals / double(nb);
      rep.contact += t.contact / double(nb);
      rep.penetrating += t.penetrating;
      if (prints()) progress(rep, b + 1, nb, t, std::chrono::steady_clock::now() - t0);
    }
    net_->parameters_changed();
    ++epoch_;
    rep.steps = Index(adam_.steps());
    if (holdout_.frames > 0 && opt_.holdout_every_epochs > 0 && (epoch_ % opt_.holdout_every_epochs == 0 || epoch_ == epochs()))
      rep.holdout_mean_error = holdout_error(policy);
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (prints()) {
      std::fprintf(stderr, "\repoch %lld/%lld  loss %.5f (recon %.5f  z %.5f  normals %.6f)  %.1f s", (long long)rep.epoch, (long long)epochs(),
                   rep.loss, rep.recon, rep.z_reg, rep.face_normals, rep.seconds);
      if (loss_.has_contact()) std::fprintf(stderr, "  contact %.5f (%lld penetrating pairs)", rep.contact, (long long)rep.penetrating);
      if (rep.holdout_mean_error >= 0) std::fprintf(stderr, "  held-out mean error %.3e", rep.holdout_mean_error);
      std::fprintf(stderr, "\n");
    }
    history_.push_back(rep);
    if (opt_.on_epoch) opt_.on_epoch(rep);
    return rep;
  }

  /// Mean HR vertex error (raw units: the network's error × σ / displacement_scale) over the held-out frames, eval mode.
  /// In data-parallel training each rank infers its block of the frames (at least one frame per
  /// rank; else every rank all of them) and the per-frame sums are added in frame order: the
  /// single process's value, bit for bit.
  template <exec::HostPolicy Policy>
  double holdout_error(Policy policy) {
    if (holdout_.frames == 0) return -1;
    net_->prepare_inference(policy);
    const Index N = data_.n, M = data_.m;
    const bool shared = holdout_split_.size() > 1 && holdout_.frames >= holdout_split_.size();
    if (shared) holdout_split_.set_batch(holdout_.frames);
    const Index first = shared ? holdout_split_.first() : 0, count = shared ? holdout_split_.count() : holdout_.frames;
    frame_sums_.assign(std::size_t(count), 0.0);
    for (Index i = 0; i < count; ++i) {
      const Index f = first + i;
      net_->infer(policy, holdout_.ldx.middleRows(f * N, N), pred_eval_);
      frame_sums_[std::size_t(i)] = (pred_eval_ - holdout_.hdx.middleRows(f * M, M)).template cast<double>().rowwise().norm().sum();
    }
    double sum = 0;
    if (shared) {
      holdout_split_.sum_items(frame_sums_.data(), 1, &sum);
    } else {
      for (double s : frame_sums_) sum += s;
    }
    const double error = sum / double(holdout_.frames * M) * net_->config().displacement_unit();
    if (!std::isfinite(error)) throw NumericalError("nn::Trainer", "the held-out mean error", adam_.steps(), error);
    return error;
  }

  /// The model file plus the training state: `train/epoch`, `train/adam_step`,
  /// `train/exp_avg/<name>`, `train/exp_avg_sq/<name>`, `train/rng` (the Mersenne twister state
  /// as text), `train/options` and `train/data` (JSON: what load_checkpoint compares). A model file
  /// loads from it as is. Written before the first step it resumes too (epoch 0, no moments).
  /// NumericalError (nothing written) when a weight, buffer or moment is not finite.
  /// In data-parallel training only rank 0 writes (every rank holds the same state).
  void save_checkpoint(const std::filesystem::path& path, const ModelData& data) const {
    if (!split_.is_root()) return;
    io::NpzArrays a = model_arrays(*net_, data);  // checks the weights and buffers
    const std::int64_t ep = epoch_;
    a["train/epoch"] = io::make_npy<std::int64_t>({}, &ep);
    add_adam_state(a, net_->store(), adam_);
    std::ostringstream rng;
    rng << rng_;
    a["train/rng"] = io::make_npy(std::vector<std::string>{rng.str()});
    a["train/options"] = io::make_npy(std::vector<std::string>{options_json().dump()});
    a["train/data"] = io::make_npy(std::vector<std::string>{data_json().dump()});
    io::write_npz(path, a);
  }

  /// True when the loss's schedule depends on the run's length (the paper's ramped latent norm
  /// over the whole run): then a resumed run must have the checkpoint's epochs; otherwise it may
  /// train longer (or stop earlier) than the run that wrote the checkpoint.
  bool schedule_depends_on_epochs() const {
    return net_->config().zreg == LatentRegularizer::ramped_norm && net_->config().zreg_ramp_steps == 0;
  }

  /// What a resumed run must share with the run that wrote the checkpoint: every option that
  /// changes the continuation (epochs only where schedule_depends_on_epochs()).
  nlohmann::json options_json() const {
    return {{"epochs", epochs()}, {"batch_size", batch_size()}, {"lr", opt_.lr > 0 ? opt_.lr : net_->config().lr}, {"seed", opt_.seed},
            {"lr_decay_epochs", opt_.lr_decay_epochs}, {"lr_decay_gamma", opt_.lr_decay_gamma}};
  }
  /// The data a resumed run must share: frame counts and fingerprints of the normalized training and
  /// held-out frames (ids included), of the rest shapes, of the HR faces and of the contact patches.
  nlohmann::json data_json() const {
    auto frames = [](const TrainingFrames<S>& t) {
      return Fingerprint().add(t.ldx).add(t.hdx).add(t.ids).hex();
    };
    nlohmann::json j = {{"training_frames", data_.frames},
            {"training_fingerprint", frames(data_)},
            {"holdout_frames", holdout_.frames},
            {"holdout_fingerprint", frames(holdout_)},
            {"lr_vertices", data_.n},
            {"hr_vertices", data_.m},
            {"rest_fingerprint", Fingerprint().add(net_->lr_rest_normalized()).add(net_->hr_rest_normalized()).hex()},
            {"faces_fingerprint", Fingerprint().add(hr_faces_).hex()}};
    if (!contact_fingerprint_.empty()) j["contact_fingerprint"] = contact_fingerprint_;  // only then: older checkpoints still load
    return j;
  }

  /// Restores weights, buffers, optimizer, RNG and counters from save_checkpoint's file: run(policy)
  /// then continues exactly as the saved run would have.
  /// ArgumentError, before anything changes, when the checkpoint's config, options (options_json)
  /// or data (data_json) differ from this run's, naming each difference.
  void load_checkpoint(const std::filesystem::path& path) {
    const io::NpzArrays a = io::read_npz(path);
    const std::string file = path.string();
    for (const char* key : {"train/epoch", "train/adam_step", "train/rng", "train/options", "train/data", "config"})
      if (!a.contains(key)) throw ArgumentError(file + ": not a training checkpoint of this version (no '" + key + "')");
    std::string differences;
    // the config's training fields are compared as the effective options below (a config's
    // n_epochs may differ where the run's length may)
    nlohmann::json saved_config = json_text(a, file, "config"), run_config = net_->config().to_json();
    // Read as a config, so that a field the checkpoint's version did not have yet compares as the
    // default it had then (an unreadable config is compared as it is: every key differs).
    try {
      saved_config = NetworkConfig::from_json(saved_config).to_json();
    } catch (const Error&) {
    }
    for (const char* key : {"n_epochs", "batch_size", "lr"})
      if (saved_config.is_object()) saved_config.erase(key), run_config.erase(key);
    compare_json(differences, "config", saved_config, run_config);
    nlohmann::json saved_options = json_text(a, file, "train/options"), run_options = options_json();
    if (!schedule_depends_on_epochs() && saved_options.is_object()) {
      saved_options.erase("epochs");
      run_options.erase("epochs");
    }
    compare_json(differences, "options", saved_options, run_options);
    compare_json(differences, "data", json_text(a, file, "train/data"), data_json());
    if (!differences.empty()) throw ArgumentError(file + ": this checkpoint comes from another run; " + differences);
    const std::int64_t epoch = a.at("train/epoch").item<std::int64_t>();
    typename Adam<S>::State s = read_adam_state(a, net_->store(), file);
    if (epoch > epochs())
      throw ArgumentError(file + ": the checkpoint has trained " + std::to_string(epoch) + " epochs, more than this run's " + std::to_string(epochs()));
    if (epoch < 0 || s.step < 0 || s.step != epoch * std::int64_t(steps_per_epoch()))
      throw ArgumentError(file + ": inconsistent counters (epoch " + std::to_string(epoch) + ", step " + std::to_string(s.step) + ", " +
                          std::to_string(steps_per_epoch()) + " steps per epoch)");
    load_state(net_->store(), a);
    net_->parameters_changed();
    epoch_ = Index(epoch);
    adam_.load_state(std::move(s));
    std::istringstream rng(a.at("train/rng").to_strings().at(0));
    rng >> rng_;
    if (rng.fail()) throw ParseError(file + ":train/rng", 0, "not a Mersenne twister state");
  }

 private:
  /// The batch split set on the network and the loss for one step's forward and backward, and
  /// unset after it (an exception too): evaluation and inference run on whole frames.
  struct SplitScope {
    Trainer& t;
    explicit SplitScope(Trainer& tr) : t(tr) {
      t.net_->set_batch_split(&t.split_);
      t.loss_.set_batch_split(&t.split_);
    }
    ~SplitScope() {
      t.net_->set_batch_split(nullptr);
      t.loss_.set_batch_split(nullptr);
    }
    SplitScope(const SplitScope&) = delete;
    SplitScope& operator=(const SplitScope&) = delete;
  };
  bool prints() const { return opt_.progress && split_.is_root(); }
  long total_steps_estimate() const {
    const Index bs = std::min(opt_.batch_size > 0 ? opt_.batch_size : net_->config().batch_size, std::max<Index>(1, data_.frames));
    const Index ep = opt_.epochs >= 0 ? opt_.epochs : net_->config().epochs;
    return long(std::max<Index>(1, ep * ((data_.frames + bs - 1) / bs)));
  }
  double current_lr() const {
    double lr = opt_.lr > 0 ? opt_.lr : net_->config().lr;
    if (opt_.lr_decay_epochs > 0) lr *= std::pow(opt_.lr_decay_gamma, double(epoch_ / opt_.lr_decay_epochs));
    return lr;
  }
  static nlohmann::json json_text(const io::NpzArrays& a, const std::string& file, const std::string& key) {
    const auto text = a.at(key).to_strings();
    if (text.size() != 1) throw ArgumentError(file + ": '" + key + "' must be one JSON string");
    try {
      return nlohmann::json::parse(text[0]);
    } catch (const nlohmann::json::exception& e) {
      throw ParseError(file + ":" + key, 0, e.what());
    }
  }
  /// Appends "what: key (checkpoint X, this run Y)" for every top-level key that differs.
  static void compare_json(std::string& out, const char* what, const nlohmann::json& saved, const nlohmann::json& run) {
    std::string diff;
    auto note = [&](const std::string& key, const std::string& a, const std::string& b) {
      diff += (diff.empty() ? "" : ", ") + key + " (checkpoint " + a + ", this run " + b + ")";
    };
    if (!saved.is_object()) {
      note("the whole entry", saved.dump(), run.dump());
    } else {
      for (const auto& [key, value] : run.items())
        if (!saved.contains(key) || saved.at(key) != value) note(key, saved.contains(key) ? saved.at(key).dump() : "none", value.dump());
      for (const auto& [key, value] : saved.items())
        if (!run.contains(key)) note(key, value.dump(), "none");
    }
    if (!diff.empty()) out += (out.empty() ? "" : "; ") + std::string(what) + " differ: " + diff;
  }
  void reseed_dropout() {
    const std::uint64_t s = rng_();
    if (!net_->has_feature_embedding()) return;
    auto& fe = net_->feature_embedding();
    for (Index b = 0; b < fe.blocks(); ++b) fe.dropout(b).rng().seed(s + std::uint64_t(b));
  }
  void gather(const std::vector<Index>& order, Index first, Index count) {
    const Index N = data_.n, M = data_.m;
    ensure_shape(ldx_, count * N, 3);
    ensure_shape(hdx_, count * M, 3);
    for (Index i = 0; i < count; ++i) {
      const Index f = order[std::size_t(first + i)];
      ldx_.middleRows(i * N, N) = data_.ldx.middleRows(f * N, N);
      hdx_.middleRows(i * M, M) = data_.hdx.middleRows(f * M, M);
    }
  }
  template <class Dur>
  void progress(const EpochReport& rep, Index b, Index nb, const typename SuperResolutionLoss<S>::Terms& t, Dur elapsed) const {
    const int width = 20, filled = int(width * b / nb);
    std::string bar(std::size_t(filled), '#');
    bar.resize(std::size_t(width), '.');
    const double s = std::chrono::duration<double>(elapsed).count();
    std::fprintf(stderr, "\repoch %lld/%lld [%s] %lld/%lld  loss %.5f (recon %.5f  z %.5f  normals %.6f", (long long)rep.epoch, (long long)epochs(),
                 bar.c_str(), (long long)b, (long long)nb, t.total, t.recon, t.z_reg, t.face_normals);
    if (loss_.has_contact()) std::fprintf(stderr, "  contact %.5f", t.contact);
    std::fprintf(stderr, ")  %.2f s/step ", s / double(b));
    std::fflush(stderr);
  }

  SuperResolutionNet<S, Search>* net_;
  TrainingFrames<S> data_, holdout_;
  TrainerOptions opt_;
  BatchSplit split_, holdout_split_;  ///< the training batches' split; the held-out frames' (evaluation)
  Rng rng_;
  Adam<S> adam_;
  SuperResolutionLoss<S> loss_;
  Tris hr_faces_;
  std::string contact_fingerprint_;
  Index epoch_ = 0;
  std::vector<EpochReport> history_;
  std::vector<Index> order_;
  std::vector<double> frame_sums_;
  Matrix<S> ldx_, hdx_, pred_, d_pred_, d_code_, pred_eval_;
};

}  // namespace simsr::nn
