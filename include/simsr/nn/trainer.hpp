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

#include <chrono>
#include <cstdio>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "../io/npy.hpp"
#include "adam.hpp"
#include "model_file.hpp"
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
    t.ids.push_back(ids.empty() ? std::int64_t(f) : ids.at(std::size_t(f)));
  }
  return t;
}

/// What one epoch did (the progress line prints the same).
struct EpochReport {
  Index epoch = 0;                 ///< 1-based
  Index steps = 0;                 ///< optimizer steps so far
  double loss = 0, recon = 0, z_reg = 0, face_normals = 0;  ///< means over the epoch's batches
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
};

template <class S = float, class Search = neighbors::BruteForceKnn<S>>
class Trainer {
 public:
  Trainer(SuperResolutionNet<S, Search>& net, const Tris& hr_faces, TrainingFrames<S> frames, TrainerOptions options = {})
      : net_(&net), data_(std::move(frames)), opt_(std::move(options)), rng_(opt_.seed),
        adam_(net.store(), {.lr = opt_.lr > 0 ? opt_.lr : net.config().lr}),
        loss_(net.config(), net.hr_rest_normalized(), hr_faces, total_steps_estimate()) {
    if (data_.frames < 1) throw ArgumentError("nn::Trainer: no training frames");
    if (data_.n != net.lr_points() || data_.m != net.hr_points())
      throw ShapeError("nn::Trainer: frames (N, M)", {net.lr_points(), net.hr_points()}, {data_.n, data_.m});
    if (batch_size() < 1) throw ArgumentError("nn::Trainer: batch_size must be >= 1");
    if (epochs() < 0) throw ArgumentError("nn::Trainer: epochs must be >= 0");
  }

  Index epochs() const { return opt_.epochs >= 0 ? opt_.epochs : net_->config().epochs; }
  Index batch_size() const { return std::min(opt_.batch_size > 0 ? opt_.batch_size : net_->config().batch_size, data_.frames); }
  Index steps_per_epoch() const { return (data_.frames + batch_size() - 1) / batch_size(); }
  Index epoch() const { return epoch_; }
  std::int64_t steps() const { return adam_.steps(); }
  const std::vector<EpochReport>& history() const { return history_; }
  Adam<S>& optimizer() { return adam_; }

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
    std::vector<Index> order(std::size_t(data_.frames));
    for (Index i = 0; i < data_.frames; ++i) order[std::size_t(i)] = i;
    for (Index i = data_.frames - 1; i > 0; --i) std::swap(order[std::size_t(i)], order[std::size_t(uniform_index(i + 1))]);
    EpochReport rep;
    rep.epoch = epoch_ + 1;
    rep.lr = current_lr();
    const Index bs = batch_size(), nb = steps_per_epoch();
    for (Index b = 0; b < nb; ++b) {
      const Index first = b * bs, count = std::min(bs, data_.frames - first);
      gather(order, first, count);
      reseed_dropout();
      net_->store().zero_grad();
      net_->forward(policy, Mode::train, ldx_, pred_);
      const auto t = loss_.evaluate(policy, pred_, hdx_, net_->code(), long(adam_.steps()), &d_pred_, &d_code_);
      net_->backward(policy, d_pred_, &d_code_);
      adam_.step(policy);
      if (!std::isfinite(t.total))
        throw ConvergenceError("nn::Trainer", int(adam_.steps()), t.total);
      rep.loss += t.total / double(nb);
      rep.recon += t.recon / double(nb);
      rep.z_reg += t.z_reg / double(nb);
      rep.face_normals += t.face_normals / double(nb);
      if (opt_.progress) progress(rep, b + 1, nb, t, std::chrono::steady_clock::now() - t0);
    }
    net_->parameters_changed();
    ++epoch_;
    rep.steps = Index(adam_.steps());
    if (holdout_.frames > 0 && opt_.holdout_every_epochs > 0 && (epoch_ % opt_.holdout_every_epochs == 0 || epoch_ == epochs()))
      rep.holdout_mean_error = holdout_error(policy);
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (opt_.progress) {
      std::fprintf(stderr, "\repoch %lld/%lld  loss %.5f (recon %.5f  z %.5f  normals %.6f)  %.1f s", (long long)rep.epoch, (long long)epochs(),
                   rep.loss, rep.recon, rep.z_reg, rep.face_normals, rep.seconds);
      if (rep.holdout_mean_error >= 0) std::fprintf(stderr, "  held-out mean error %.3e", rep.holdout_mean_error);
      std::fprintf(stderr, "\n");
    }
    history_.push_back(rep);
    if (opt_.on_epoch) opt_.on_epoch(rep);
    return rep;
  }

  /// Mean HR vertex error (raw units: the normalized error × σ) over the held-out frames, eval mode.
  template <exec::HostPolicy Policy>
  double holdout_error(Policy policy) {
    if (holdout_.frames == 0) return -1;
    net_->prepare_inference(policy);
    const Index N = data_.n, M = data_.m;
    double sum = 0;
    for (Index f = 0; f < holdout_.frames; ++f) {
      net_->infer(policy, holdout_.ldx.middleRows(f * N, N), pred_eval_);
      sum += (pred_eval_ - holdout_.hdx.middleRows(f * M, M)).template cast<double>().rowwise().norm().sum();
    }
    return sum / double(holdout_.frames * M) * net_->config().norm_std;
  }

  /// The model file plus the training state: `train/epoch`, `train/adam_step`,
  /// `train/exp_avg/<name>`, `train/exp_avg_sq/<name>`, `train/rng` (the Mersenne twister state
  /// as text), `train/options` (JSON). A model file loads from it as is.
  void save_checkpoint(const std::filesystem::path& path, const ModelData& data) const {
    io::NpzArrays a = model_arrays(*net_, data);
    const std::int64_t ep = epoch_, st = adam_.steps();
    a["train/epoch"] = io::make_npy<std::int64_t>({}, &ep);
    a["train/adam_step"] = io::make_npy<std::int64_t>({}, &st);
    const auto& s = adam_.state();
    for (const auto& e : net_->store().entries()) {
      if (e.kind != TensorEntry::Kind::parameter) continue;
      std::vector<std::int64_t> shape(e.shape.begin(), e.shape.end());
      if (s.exp_avg.size() == net_->store().num_parameters()) {
        a["train/exp_avg/" + e.name] = io::make_npy<S>(shape, s.exp_avg.data() + e.offset);
        a["train/exp_avg_sq/" + e.name] = io::make_npy<S>(shape, s.exp_avg_sq.data() + e.offset);
      }
    }
    std::ostringstream rng;
    rng << rng_;
    a["train/rng"] = io::make_npy(std::vector<std::string>{rng.str()});
    nlohmann::json o{{"epochs", epochs()}, {"batch_size", batch_size()}, {"lr", adam_.options().lr}, {"seed", opt_.seed}};
    a["train/options"] = io::make_npy(std::vector<std::string>{o.dump()});
    io::write_npz(path, a);
  }

  /// Restores weights, buffers, optimizer, RNG and counters from save_checkpoint's file: run(policy)
  /// then continues exactly as the saved run would have.
  void load_checkpoint(const std::filesystem::path& path) {
    const io::NpzArrays a = io::read_npz(path);
    load_state(net_->store(), a);
    net_->parameters_changed();
    if (!a.contains("train/epoch")) throw ArgumentError(path.string() + ": not a training checkpoint (no train/epoch)");
    epoch_ = Index(a.at("train/epoch").item<std::int64_t>());
    typename Adam<S>::State s;
    s.step = a.at("train/adam_step").item<std::int64_t>();
    if (s.step > 0) {
      const Index n = net_->store().num_parameters();
      s.exp_avg.setZero(n);
      s.exp_avg_sq.setZero(n);
      for (const auto& e : net_->store().entries()) {
        if (e.kind != TensorEntry::Kind::parameter) continue;
        const auto m = a.at("train/exp_avg/" + e.name).template to_vector<S>();
        const auto v = a.at("train/exp_avg_sq/" + e.name).template to_vector<S>();
        if (Index(m.size()) != e.size || Index(v.size()) != e.size)
          throw ShapeError(path.string() + ": optimizer state of '" + e.name + "'", {e.size}, {Index(m.size())});
        std::copy(m.begin(), m.end(), s.exp_avg.data() + e.offset);
        std::copy(v.begin(), v.end(), s.exp_avg_sq.data() + e.offset);
      }
    }
    adam_.load_state(std::move(s));
    std::istringstream rng(a.at("train/rng").to_strings().at(0));
    rng >> rng_;
    if (rng.fail()) throw ParseError(path.string() + ":train/rng", 0, "not a Mersenne twister state");
  }

 private:
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
  /// Unbiased integer in [0, n) (rejection on the top of the 64-bit range).
  Index uniform_index(Index n) {
    const std::uint64_t un = std::uint64_t(n), limit = UINT64_MAX - UINT64_MAX % un;
    std::uint64_t x;
    do x = rng_();
    while (x >= limit);
    return Index(x % un);
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
    std::fprintf(stderr, "\repoch %lld/%lld [%s] %lld/%lld  loss %.5f (recon %.5f  z %.5f  normals %.6f)  %.2f s/step ", (long long)rep.epoch,
                 (long long)epochs(), bar.c_str(), (long long)b, (long long)nb, t.total, t.recon, t.z_reg, t.face_normals, s / double(b));
    std::fflush(stderr);
  }

  SuperResolutionNet<S, Search>* net_;
  TrainingFrames<S> data_, holdout_;
  TrainerOptions opt_;
  Rng rng_;
  Adam<S> adam_;
  SuperResolutionLoss<S> loss_;
  Index epoch_ = 0;
  std::vector<EpochReport> history_;
  Matrix<S> ldx_, hdx_, pred_, d_pred_, d_code_, pred_eval_;
};

}  // namespace simsr::nn
