#pragma once
/// \file
/// The super-resolution network (§3) as an interpolator: one type away from every baseline.
///
///     interp::Learned<> net(nn::NetworkConfig::official());   // or paper(), or any ablation field
///     net.fit(exec::omp, problem);            // geometry: rest shapes, §3.2 neighbourhoods, LR graph, Embedded
///     net.train(exec::omp, data::displacements(train, lr.V, hr.V), {.trainer = {.epochs = 14}});
///     net.apply(exec::omp, lr_displacement, hr_displacement);   // N×3 → M×3 in mesh units
///     net.save("model.npz");                  // one self-contained model file
///     auto again = interp::Learned<>::from_model_file("model.npz");   // fit then checks the rest shapes
///
/// It owns what a network user must otherwise get right by hand: the network's geometry from the
/// fitted problem (the problem's upsampling neighbourhoods and LR graph — from the authors'
/// files via `problem.use(...)`, or computed; Euclidean neighbours for the w/o CU ablation; the
/// Embedded matrix for the residual composition, or the local-linear base fitted on the training
/// frames: NetworkConfig::residual_base), the official normalization of inputs and
/// targets (positions (x − μ)/σ in float32 minus the normalized rest shape; predictions back to
/// mesh units by σ; displacements scaled by the config's displacement_scale), training with held-out evaluation and resumable checkpoints, and inference
/// through the precomputed upsampling weights.
///
/// No silent failure: inputs must be finite and within float32's range after normalization
/// (ArgumentError naming the vertex), predictions must be finite (NumericalError), and training
/// stops at a non-finite loss, gradient or weight (nn::Trainer).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../data/paired_frames.hpp"
#include "../discretize/embedding.hpp"
#include "../neighbors/kd_tree.hpp"
#include "../nn/model_file.hpp"
#include "../nn/normalization.hpp"
#include "../nn/super_resolution_net.hpp"
#include "../nn/trainer.hpp"
#include "concepts.hpp"
#include "local_linear.hpp"
#include "problem.hpp"

namespace simsr::interp {

/// How Learned::train runs.
struct NetworkTrainOptions {
  /// Epochs, batch size, learning rate and its decay, seed, progress line, per-epoch callback
  /// (−1 fields: the network config's values).
  nn::TrainerOptions trainer;
  /// Frames (displacements, as the training frames) evaluated after every epoch; never trained on.
  const data::PairedFrames<Scalar>* holdout = nullptr;
  /// Written before the first step and after every epoch when not empty (atomically); resumable.
  std::filesystem::path checkpoint;
  /// Continue from this checkpoint when not empty: it must come from the same config, options and
  /// data (nn::Trainer::load_checkpoint names what differs).
  std::filesystem::path resume;
  /// How the local-linear residual base is fitted (NetworkConfig::residual_base = local_linear).
  LocalLinearTrainOptions base;
  /// The contact term's patches (rows of the HR surface), for a config with w_contact > 0 (the
  /// face's lips: scenario::face_lip_patches, DIR/hr_lips.npz of simsr datagen).
  ContactPatches contact;
};

/// The network `Net` (nn::SuperResolutionNet<float> by default; <double> for checks) as an
/// interp::TrainableInterpolator. apply is const but runs the network in the object's buffers:
/// one call at a time per object.
template <class Net = nn::SuperResolutionNet<float>>
class Learned {
 public:
  using scalar_type = Scalar;  ///< displacements in mesh units, as every interpolator
  using network_scalar = typename Net::scalar_type;
  using train_options = NetworkTrainOptions;
  /// fit reads problem.neighborhoods (and the LR graph, computed when absent).
  static constexpr bool needs_neighborhoods = true;

  /// An untrained network of `config` whose initial weights `seed` draws (at fit).
  explicit Learned(nn::NetworkConfig config = nn::NetworkConfig::official(), std::uint64_t seed = 0)
      : config_(std::move(config)), seed_(seed) {
    config_.validate();
  }

  /// A trained network from a model file (`save`, `simsr train`): apply works at once; fit only
  /// checks that the problem's rest shapes are the model's.
  static Learned from_model_file(const std::filesystem::path& file) {
    nn::ModelData md = nn::read_model_data(file);
    Learned l(md.config);
    nn::Rng rng(0);
    l.net_ = std::make_unique<Net>(md.config, md.geometry, rng);
    nn::load_state(l.net_->store(), nn::read_model_arrays(file));
    l.net_->parameters_changed();
    l.model_ = std::move(md);
    l.loaded_from_ = file.string();
    l.prepare();
    return l;
  }

  /// The upsampling neighbours per HR vertex fit() reads for `config`: upK, or the local-linear
  /// base's k when that is more (what interp::prepare must compute before fitting).
  static Index neighborhoods_needed(const nn::NetworkConfig& config) {
    const bool local_base = config.residual && config.residual_base == nn::ResidualBase::local_linear;
    return local_base ? std::max(config.up_k, config.residual_base_k) : config.up_k;
  }

  /// Builds the network's geometry from the problem and draws the initial weights (see the file
  /// comment). For a loaded model: ArgumentError unless the rest shapes are the model's.
  template <exec::HostPolicy Policy>
  void fit(Policy policy, UpsamplingProblem<Scalar>& problem) {
    if (!loaded_from_.empty()) {
      check_same_rest(problem);
      return;
    }
    const auto& cfg = config_;
    nn::NetworkGeometry g;
    g.lr_rest = problem.lr.V;
    g.hr_rest = problem.hr.V;
    if (cfg.upsampling == nn::UpsamplingKind::table) {  // w/o CU: fixed Euclidean upK nearest LR vertices
      neighbors::KdTree<double> tree(problem.lr.V);
      const auto r = tree.query(policy, problem.hr.V, cfg.up_k);
      g.up_indices = r.indices;
      g.up_distances = r.distances;
    } else {
      const auto& nb = problem.checked_neighborhoods(cfg.up_k);
      g.up_indices = nb.indices.leftCols(cfg.up_k);
      g.up_distances = nb.distances.leftCols(cfg.up_k);
    }
    if (cfg.feature_embedding) g.lr_graph = problem.ensure_lr_graph(policy, cfg.knn).leftCols(cfg.knn);
    base_.reset();
    if (cfg.residual && cfg.residual_base == nn::ResidualBase::embedded)
      g.embedding = embedding_matrix(embed(policy, problem.lr, problem.hr.V), problem.lr.T, problem.num_lr()).template cast<double>();
    if (cfg.residual && cfg.residual_base == nn::ResidualBase::local_linear) {  // fitted on the frames by train()
      base_ = std::make_unique<LocalLinear<Scalar>>(LocalLinearOptions{.k = cfg.residual_base_k});
      base_->fit(policy, problem);
    }
    model_ = nn::ModelData{cfg, std::move(g), problem.lr.T, problem.hr.F};
    nn::Rng rng(seed_);
    net_ = std::make_unique<Net>(cfg, model_.geometry, rng);
    history_.clear();
    prepare();
  }

  /// Trains on F paired frames of displacements from the fitted rest shapes (data::displacements).
  template <exec::HostPolicy Policy>
  void train(Policy policy, const data::PairedFrames<Scalar>& frames, const NetworkTrainOptions& options) {
    if (!net_) throw ArgumentError("Learned::train before fit");
    if (base_) {  // the local-linear base, on the frames the network then trains on (deterministic: a resumed run refits the same)
      base_->train(policy, frames, options.base);
      model_.geometry.residual_map = base_->linear_map();
      net_->set_residual_map(model_.geometry.residual_map);
    }
    nn::Trainer<network_scalar, typename Net::search_type> trainer(*net_, model_.hr_faces, training_frames(frames, "training frames"), options.trainer);
    if (options.holdout) trainer.set_holdout(training_frames(*options.holdout, "held-out frames"));
    if (!options.contact.empty()) trainer.set_contact(options.contact);
    if (!options.resume.empty())
      trainer.load_checkpoint(options.resume);  // refuses another run's checkpoint, naming what differs
    else if (!options.checkpoint.empty())
      trainer.save_checkpoint(options.checkpoint, model_);  // before the first step: a run killed in epoch 1 resumes too
    while (trainer.epoch() < trainer.epochs()) {
      trainer.run_epoch(policy);
      if (!options.checkpoint.empty()) trainer.save_checkpoint(options.checkpoint, model_);
    }
    history_ = trainer.history();
    gathers_ = trainer.gathers();
    bytes_received_ = trainer.bytes_received();
    epoch_ = trainer.epoch();
    steps_ = trainer.steps();
    batch_size_ = trainer.batch_size();
    net_->prepare_inference(policy);
  }

  /// hr_displacement (M×3) from lr_displacement (N×3), both in mesh units.
  template <exec::HostPolicy Policy>
  void apply(Policy policy, const ConstPointsRef<Scalar>& lr_displacement, PointsRef<Scalar> hr_displacement) const {
    if (!net_) throw ArgumentError("Learned::apply before fit");
    const Index n = num_lr(), m = num_hr();
    if (lr_displacement.rows() != n) throw ShapeError("Learned::apply: LR displacement", {n, 3}, {lr_displacement.rows(), 3});
    if (hr_displacement.rows() != m) throw ShapeError("Learned::apply: HR displacement", {m, 3}, {hr_displacement.rows(), 3});
    normalize_into(lr_displacement, ldx_, "Learned::apply: LR displacement");
    net_->infer(policy, ldx_, pred_);
    const double sigma = config_.displacement_unit();
    for (Index r = 0; r < m; ++r)
      for (Index c = 0; c < 3; ++c) {
        const double v = double(pred_(r, c)) * sigma;
        if (!std::isfinite(v)) throw NumericalError("Learned::apply", "the prediction of HR vertex " + std::to_string(r), -1, v);
        hr_displacement(r, c) = v;
      }
  }

  /// Writes the model file (weights, config, geometry): `from_model_file` and `simsr infer` read it.
  void save(const std::filesystem::path& file) const {
    if (!net_) throw ArgumentError("Learned::save before fit");
    nn::save_model(file, *net_, model_);
  }

  Index num_lr() const { return net_ ? net_->lr_points() : 0; }
  Index num_hr() const { return net_ ? net_->hr_points() : 0; }
  const nn::NetworkConfig& config() const { return config_; }
  /// The network itself (after fit), e.g. for its parameter count or a custom training loop.
  Net& network() { return *net_; }
  const Net& network() const { return *net_; }
  /// The model data (config, geometry, meshes) fitted or loaded.
  const nn::ModelData& model() const { return model_; }
  /// The local-linear residual base's training report (after train; nullptr for another base or a loaded model).
  const LocalLinearTrainInfo* base_info() const { return base_ ? &base_->info() : nullptr; }
  /// One report per trained epoch (loss terms, seconds, held-out mean error in mesh units).
  const std::vector<nn::EpochReport>& history() const { return history_; }
  /// Epochs trained in all (a resumed run counts the checkpoint's), optimizer steps, batch size.
  Index epoch() const { return epoch_; }
  std::int64_t steps() const { return steps_; }
  Index batch_size() const { return batch_size_; }
  /// Data-parallel training (TrainerOptions::group): the last train's collectives and the bytes
  /// this rank received (0 on one process).
  std::int64_t gathers() const { return gathers_; }
  std::int64_t bytes_received() const { return bytes_received_; }

 private:
  /// normalized positions of the rest shapes, and the float32 range check of every input.
  void prepare() {
    lr0_ = nn::normalize_positions<network_scalar>(model_.geometry.lr_rest, config_.norm_mean, config_.norm_std);
    lr_rest_ = model_.geometry.lr_rest;
  }

  /// out = norm(rest + d) − norm(rest), in the network's scalar (the official order of operations).
  template <class D>
  void normalize_into(const Eigen::MatrixBase<D>& d, nn::Matrix<network_scalar>& out, const std::string& what) const {
    const Index n = d.rows();
    if (positions_.rows() != n) positions_.resize(n, 3);
    constexpr double limit = double(std::numeric_limits<network_scalar>::max());
    for (Index r = 0; r < n; ++r)
      for (Index c = 0; c < 3; ++c) {
        const double x = lr_rest_(r, c) + double(d(r, c));
        if (!std::isfinite(x) || std::abs((x - config_.norm_mean) / config_.norm_std) > limit)
          throw ArgumentError(what + " of vertex " + std::to_string(r) + " is " + std::to_string(double(d(r, c))) +
                              (std::isfinite(x) ? ": beyond the network's float range after normalization" : ": not finite"));
        positions_(r, c) = x;
      }
    nn::ensure_shape(out, n, 3);
    nn::normalized_displacements(positions_, lr0_, config_.norm_mean, config_.norm_std, out);
    if (config_.displacement_scale != 1.0) out *= network_scalar(config_.displacement_scale);
  }

  /// Frames of displacements as the trainer's normalized frames (HR through the same rule).
  nn::TrainingFrames<network_scalar> training_frames(const data::PairedFrames<Scalar>& frames, const std::string& what) const {
    const Index n = num_lr(), m = num_hr(), f = frames.num_frames();
    if (frames.num_lr() != n || frames.num_hr() != m)
      throw ShapeError("Learned::train: " + what + " (N, M)", {n, m}, {frames.num_lr(), frames.num_hr()});
    nn::TrainingFrames<network_scalar> t;
    t.n = n, t.m = m, t.frames = f, t.ids = frames.ids;
    t.ldx.resize(f * n, 3);
    t.hdx.resize(f * m, 3);
    const nn::Matrix<network_scalar> hr0 = nn::normalize_positions<network_scalar>(model_.geometry.hr_rest, config_.norm_mean, config_.norm_std);
    Points<double> hr_pos(m, 3);
    nn::Matrix<network_scalar> scratch;
    for (Index i = 0; i < f; ++i) {
      normalize_into(frames.lr(i), scratch, "Learned::train: " + what + ", frame " + std::to_string(frames.ids[std::size_t(i)]) + ", LR displacement");
      t.ldx.middleRows(i * n, n) = scratch;
      hr_pos = model_.geometry.hr_rest + frames.hr(i);
      if (!hr_pos.allFinite()) throw ArgumentError("Learned::train: " + what + ", frame " + std::to_string(frames.ids[std::size_t(i)]) + ": HR displacement not finite");
      nn::normalized_displacements(hr_pos, hr0, config_.norm_mean, config_.norm_std, t.hdx.middleRows(i * m, m));
      if (config_.displacement_scale != 1.0) t.hdx.middleRows(i * m, m) *= network_scalar(config_.displacement_scale);
    }
    return t;
  }

  void check_same_rest(const UpsamplingProblem<Scalar>& problem) const {
    const auto& g = model_.geometry;
    auto same = [](const Points<double>& a, const Points<double>& b) {
      return a.rows() == b.rows() && (a.rows() == 0 || (a - b).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + b.cwiseAbs().maxCoeff()));
    };
    if (!same(problem.lr.V, g.lr_rest) || !same(problem.hr.V, g.hr_rest))
      throw ArgumentError(loaded_from_ + ": the model was trained on other rest shapes (N = " + std::to_string(g.lr_rest.rows()) + ", M = " +
                          std::to_string(g.hr_rest.rows()) + ") than this problem's (N = " + std::to_string(problem.num_lr()) + ", M = " +
                          std::to_string(problem.num_hr()) + ")");
  }

  nn::NetworkConfig config_;
  std::uint64_t seed_ = 0;
  std::unique_ptr<Net> net_;
  std::unique_ptr<LocalLinear<Scalar>> base_;  ///< the local-linear residual base, until trained
  nn::ModelData model_;
  std::string loaded_from_;
  std::vector<nn::EpochReport> history_;
  std::int64_t steps_ = 0, gathers_ = 0, bytes_received_ = 0;
  Index epoch_ = 0, batch_size_ = 0;
  nn::Matrix<network_scalar> lr0_;
  Points<double> lr_rest_;
  mutable Points<double> positions_;
  mutable nn::Matrix<network_scalar> ldx_, pred_;
};

static_assert(assert_trainable_interpolator<Learned<>>());

}  // namespace simsr::interp
