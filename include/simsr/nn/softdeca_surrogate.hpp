#pragma once
/// \file
/// SoftDECA's learned surrogate (softdeca supplement §4, Fig. 1: fully connected layers only): a
/// network of the library's own layers (nn::Mlp of nn::Linear + LeakyReLU) from a sample's
/// expression weights and simulation parameters to the skin's displacement from the template's
/// rest skin, standing in for the layered-head simulation (scenario/softdeca/softdeca_simulator.hpp)
/// on the data of scenario/softdeca/softdeca_datagen.hpp (read by softdeca_dataset.hpp). In nn/, right of scenario/ in the data
/// flow: a network trained on simulated data, like the super-resolution network.
///
///   input   [expression weights (E), parameters (20: SoftDecaParameters::to_vector, weights as
///           log10)], each feature standardized by the training set's mean and deviation
///   hidden  FC widths (default 256, 256, 256), LeakyReLU(0.01) after each
///   output  FC to 3·#skin, the displacement standardized by the training mean displacement and
///           one global scale (so the loss weighs every vertex and axis alike, in metres)
///   base    optional (`SoftDecaSurrogateOptions::linear_base`): a ridge map of the 20
///           standardized simulation parameters (not the expression weights), fitted in closed
///           form on the training samples, its λ picked on the validation samples, added to the
///           output; the network then learns only what the linear map leaves (the residual
///           composition of the core paper's §3.3, with a linear map as its base). Why: the
///           skull's per-axis scaling moves the whole skin nearly linearly by centimetres, and
///           with the tens of samples a head affords the network learns that trend worse than a
///           closed-form fit does; the expressions act locally (below a millimetre over the whole
///           skin on the 1.2 cm head), and a linear map of 57 sparse weights from tens of samples
///           only fits noise (README, "SoftDECA").
///
/// Why these dimensions: the supplement's figure gives only the kind of layer; the inputs are few
/// (E + 20) and smooth in their effect, while the output is a whole skin, so a few hundred hidden
/// units carry the nonlinearity (the skull scaling's and gravity's interplay with the weights)
/// and the last layer acts as a learned displacement basis of 256 modes. On the sphere template's
/// 600 samples two layers of 128 did worse (README); `simsr train-surrogate --hidden` tries others.
///
/// Training: Adam (lr cosine-decayed to 1 % over the epochs), mean squared error of the
/// standardized displacement, mini-batches in a seeded order; the last `held_out` fraction of
/// the samples (by index, so a grown dataset keeps its held-out set) never enters training, and
/// the last `validation` fraction of the rest picks the epoch whose weights are kept (early
/// stopping: with few samples and 20 inputs, most of them weak, the network fits the training
/// samples long before it stops improving on others). The report compares the held-out error
/// with two baselines fitted on all training samples: the mean displacement and ridge
/// regression (a linear map of the same standardized inputs).
///
///     auto data = scenario::read_softdeca_dataset("out/softdeca");
///     nn::SoftDecaSurrogate net(data.expressions.cols(), data.skin_vertices(), {256, 256, 256}, 1);
///     auto report = nn::train_softdeca_surrogate(exec::omp, data, {}, net);
///     Eigen::MatrixXd d = net.predict(exec::omp, data.parameters, data.expressions);   // N × 3·#skin (m)
///     // or all of it, with the model, report and loss curve written (simsr train-surrogate):
///     auto j = nn::train_softdeca_surrogate_files(exec::omp, "out/softdeca", "out/surrogate", {256, 256, 256}, {});

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../core/types.hpp"
#include "../io/atomic_file.hpp"
#include "../io/npz.hpp"
#include "../scenario/softdeca/parameters.hpp"
#include "../scenario/softdeca/softdeca_dataset.hpp"
#include "adam.hpp"
#include "losses.hpp"
#include "mlp.hpp"
#include "model_file.hpp"
#include "parameters.hpp"

namespace simsr::nn {

/// How the surrogate is trained.
struct SoftDecaSurrogateOptions {
  Index epochs = 300;
  Index batch = 16;
  double lr = 1e-3;           ///< Adam's, cosine-decayed to lr_final_fraction · lr
  double lr_final_fraction = 0.01;
  double held_out = 0.2;      ///< the last fraction of the samples, never trained on
  /// The last fraction of the training samples that picks the epoch: the weights kept are those
  /// of the epoch with the least validation loss (early stopping; 0: the last epoch's).
  double validation = 0.15;
  double weight_decay = 0;    ///< Adam's L2 weight decay
  double ridge_lambda = 1e-3; ///< the ridge baseline's regularization (on standardized inputs)
  /// Add a ridge map of the parameters, fitted on the training samples (not the validation ones),
  /// and train the network on what it leaves (see the file comment). Its λ is the one of
  /// `base_lambdas` with the least validation error (ridge_lambda without validation samples).
  bool linear_base = false;
  std::vector<double> base_lambdas = {1e-4, 1e-3, 1e-2, 1e-1, 1, 10};
  std::uint64_t seed = 1;     ///< batch order
  std::function<void(Index epoch, double train_loss)> progress = {};
};

/// The network and its input/output standardization (see the file comment).
class SoftDecaSurrogate {
 public:
  /// E expressions, M skin vertices, hidden widths (≥ 1 layer), initialization seed.
  SoftDecaSurrogate(Index expressions, Index skin_vertices, std::vector<Index> hidden, std::uint64_t seed)
      : E_(expressions), M_(skin_vertices), hidden_(std::move(hidden)) {
    if (E_ < 0 || M_ < 1) throw ArgumentError("SoftDecaSurrogate: need >= 0 expressions and >= 1 skin vertex");
    if (hidden_.empty()) throw ArgumentError("SoftDecaSurrogate: needs at least one hidden layer");
    for (Index h : hidden_)
      if (h < 1 || h > 65536) throw ArgumentError("SoftDecaSurrogate: hidden widths must be in [1, 65536], got " + std::to_string(h));
    std::vector<MlpStage> stages;
    Index in = inputs();
    for (std::size_t i = 0; i < hidden_.size(); ++i) {
      stages.push_back(MlpStage::linear(in, hidden_[i], "fc" + std::to_string(i)).dims(0).then(Act::leaky_relu, 0.01));
      in = hidden_[i];
    }
    stages.push_back(MlpStage::linear(in, 3 * M_, "fc" + std::to_string(hidden_.size())).dims(0));
    Rng rng(seed);
    mlp_ = std::make_unique<Mlp<float>>(*store_, "surrogate", stages, rng);
    in_mean_ = VecX<>::Zero(inputs());
    in_scale_ = VecX<>::Ones(inputs());
    out_mean_ = VecX<>::Zero(3 * M_);
  }

  Index expressions() const { return E_; }
  Index skin_vertices() const { return M_; }
  Index inputs() const { return E_ + scenario::SoftDecaParameters::size; }
  const std::vector<Index>& hidden() const { return hidden_; }
  ParameterStore<float>& store() { return *store_; }
  Mlp<float>& mlp() { return *mlp_; }

  /// Fits the standardization to training inputs (N × inputs) and displacements (N × 3M): of the
  /// displacements themselves, or, with a linear base, of what the base leaves of them.
  void fit_normalization(const Eigen::MatrixXd& inputs_, const Eigen::MatrixXd& displacements) {
    check_inputs("fit_normalization", inputs_);
    if (displacements.rows() != inputs_.rows() || displacements.cols() != 3 * M_)
      throw ShapeError("SoftDecaSurrogate::fit_normalization: displacements", {inputs_.rows(), 3 * M_}, {displacements.rows(), displacements.cols()});
    in_mean_ = inputs_.colwise().mean().transpose();
    const VecX<> sd = ((inputs_.rowwise() - in_mean_.transpose()).array().square().colwise().mean()).sqrt().transpose();
    in_scale_ = sd.unaryExpr([](double s) { return s > 1e-12 ? s : 1.0; });  // a constant feature stays as it is
    fit_output_normalization(inputs_, displacements);
  }

  /// The linear base (see the file comment): W = argmin ‖[1, z] W − Y‖² + λN‖W without its
  /// intercept row‖² over the standardized parameters z of `inputs_` (fit_normalization first),
  /// stored with zero rows for the expression weights, then the output standardization refitted
  /// to what it leaves. λ > 0.
  void fit_linear_base(const Eigen::MatrixXd& inputs_, const Eigen::MatrixXd& displacements, double lambda) {
    base_ = parameter_ridge(inputs_, displacements, lambda);
    fit_output_normalization(inputs_, displacements);
  }
  /// The base fit_linear_base() would set, without setting it ((inputs + 1) × 3M).
  Eigen::MatrixXd parameter_ridge(const Eigen::MatrixXd& inputs_, const Eigen::MatrixXd& displacements, double lambda) const {
    check_inputs("fit_linear_base", inputs_);
    return parameter_ridge_of(with_intercept(inputs_), displacements, lambda);
  }
  /// parameter_ridge() of inputs already given as with_intercept() (a λ search fits several).
  Eigen::MatrixXd parameter_ridge_of(const Eigen::MatrixXd& A, const Eigen::MatrixXd& displacements, double lambda) const {
    if (A.cols() != inputs() + 1) throw ShapeError("SoftDecaSurrogate::parameter_ridge_of: [1, z]", {A.rows(), inputs() + 1}, {A.rows(), A.cols()});
    if (displacements.rows() != A.rows() || displacements.cols() != 3 * M_)
      throw ShapeError("SoftDecaSurrogate::fit_linear_base: displacements", {A.rows(), 3 * M_}, {displacements.rows(), displacements.cols()});
    if (!(lambda > 0)) throw ArgumentError("SoftDecaSurrogate::fit_linear_base: lambda must be > 0");
    const Index K = scenario::SoftDecaParameters::size;
    Eigen::MatrixXd Ap(A.rows(), K + 1);
    Ap << A.col(0), A.rightCols(K);
    const Eigen::MatrixXd Wp = ridge_fit(Ap, displacements, lambda);
    Eigen::MatrixXd W = Eigen::MatrixXd::Zero(inputs() + 1, 3 * M_);
    W.row(0) = Wp.row(0);
    W.bottomRows(K) = Wp.bottomRows(K);
    return W;
  }
  /// The linear base ((inputs + 1) × 3M: intercept row first), empty without one.
  const Eigen::MatrixXd& linear_base() const { return base_; }
  /// No linear base: the network alone (call fit_normalization again).
  void clear_linear_base() { base_.resize(0, 0); }

  /// The ridge solution of [1, z] W ≈ Y (the intercept not regularized), z standardized.
  static Eigen::MatrixXd ridge_fit(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Y, double lambda) {
    Eigen::MatrixXd G = A.transpose() * A;
    G.diagonal().tail(A.cols() - 1).array() += lambda * double(A.rows());
    return G.ldlt().solve(A.transpose() * Y);
  }
  /// [1, standardized inputs] (N × (inputs + 1)), in double.
  Eigen::MatrixXd with_intercept(const Eigen::MatrixXd& inputs_) const {
    check_inputs("with_intercept", inputs_);
    Eigen::MatrixXd A;
    standardize_into(inputs_.leftCols(E_), inputs_.rightCols(scenario::SoftDecaParameters::size), A);
    return A;
  }
  /// What the network is trained to output for these displacements: with a base, what it leaves.
  Eigen::MatrixXd network_part(const Eigen::MatrixXd& inputs_, const Eigen::MatrixXd& displacements) const {
    if (base_.size() == 0) return displacements;
    return displacements - with_intercept(inputs_) * base_;
  }

  /// [expression weights, parameters] per row (N × inputs()).
  Eigen::MatrixXd join(const Eigen::MatrixXd& parameters, const Eigen::MatrixXd& expressions) const {
    check_pair(parameters, expressions);
    Eigen::MatrixXd x(parameters.rows(), inputs());
    x << expressions, parameters;
    return x;
  }

  /// Standardized network input of raw inputs (N × inputs()), as float.
  Matrix<float> standardize(const Eigen::MatrixXd& inputs_) const { return with_intercept(inputs_).rightCols(inputs()).cast<float>(); }
  /// Standardized displacements (the training target).
  Matrix<float> standardize_output(const Eigen::MatrixXd& displacements) const {
    return ((displacements.rowwise() - out_mean_.transpose()) / out_scale_).cast<float>();
  }

  /// Skin displacements (N × 3M, m, vertex-major) at the given parameters and expressions, into
  /// `displacements` (resized only when N changes: a warm call of the same N allocates nothing
  /// but what the network's layers do).
  template <exec::HostPolicy P>
  void predict(P policy, const Eigen::MatrixXd& parameters, const Eigen::MatrixXd& expressions, Eigen::MatrixXd& displacements) {
    check_pair(parameters, expressions);
    if (!parameters.allFinite() || !expressions.allFinite()) throw ArgumentError("SoftDecaSurrogate::predict: non-finite input");
    standardize_into(expressions, parameters, z_);
    in_ = z_.rightCols(inputs()).cast<float>();
    mlp_->forward(policy, Mode::eval, in_, out_);
    displacements.resize(out_.rows(), out_.cols());
    displacements.noalias() = (out_.cast<double>() * out_scale_).rowwise() + out_mean_.transpose();
    if (base_.size() != 0) displacements.noalias() += z_ * base_;  // + [1, z] W, z in double
  }
  template <exec::HostPolicy P>
  Eigen::MatrixXd predict(P policy, const Eigen::MatrixXd& parameters, const Eigen::MatrixXd& expressions) {
    Eigen::MatrixXd d;
    predict(policy, parameters, expressions, d);
    return d;
  }

  /// Writes the model (state tensors, standardization, dimensions, `meta`) atomically.
  void save(const std::filesystem::path& path, const nlohmann::ordered_json& meta = {}) const {
    io::NpzArrays z;
    add_state(z, *store_);
    z["in_mean"] = io::make_npy(in_mean_);
    z["in_scale"] = io::make_npy(in_scale_);
    z["out_mean"] = io::make_npy(out_mean_);
    z["out_scale"] = io::make_npy<double>({}, &out_scale_);
    if (base_.size() != 0) z["linear_base"] = io::make_npy(base_);
    nlohmann::ordered_json j = {{"kind", "simsr softdeca surrogate"}, {"expressions", E_}, {"skin_vertices", M_}, {"hidden", hidden_},
                                {"linear_base", base_.size() != 0}};
    j["meta"] = meta;
    z["config"] = io::make_npy(std::vector<std::string>{j.dump()});
    io::write_npz(path, z);  // atomic (npz.hpp)
  }

  /// Reads a model written by save(). Error naming the file for another kind of file or a
  /// tensor of the wrong shape.
  static SoftDecaSurrogate load(const std::filesystem::path& path) {
    const io::NpzArrays z = io::read_npz(path);
    if (!z.contains("config")) throw Error("SoftDecaSurrogate::load: " + path.string() + " has no 'config' (not a surrogate model)");
    const auto j = nlohmann::json::parse(z.at("config").to_strings().at(0));
    if (j.value("kind", "") != "simsr softdeca surrogate") throw Error("SoftDecaSurrogate::load: " + path.string() + " is not a surrogate model");
    SoftDecaSurrogate s(j.at("expressions").get<Index>(), j.at("skin_vertices").get<Index>(), j.at("hidden").get<std::vector<Index>>(), 0);
    load_state(*s.store_, z);
    s.in_mean_ = z.at("in_mean").to_matrix<double>().reshaped();
    s.in_scale_ = z.at("in_scale").to_matrix<double>().reshaped();
    s.out_mean_ = z.at("out_mean").to_matrix<double>().reshaped();
    s.out_scale_ = z.at("out_scale").item<double>();
    if (j.value("linear_base", false)) {
      if (!z.contains("linear_base")) throw Error("SoftDecaSurrogate::load: " + path.string() + ": its config names a linear base the file does not hold");
      s.base_ = z.at("linear_base").to_matrix<double>();
      if (s.base_.rows() != s.inputs() + 1 || s.base_.cols() != 3 * s.M_ || !s.base_.allFinite())
        throw Error("SoftDecaSurrogate::load: " + path.string() + ": the linear base must be a finite (inputs + 1) x 3M matrix");
    }
    if (s.in_mean_.size() != s.inputs() || s.in_scale_.size() != s.inputs() || s.out_mean_.size() != 3 * s.M_)
      throw Error("SoftDecaSurrogate::load: " + path.string() + ": standardization arrays do not match the dimensions in its config");
    if (!s.in_mean_.allFinite() || !s.out_mean_.allFinite() || !(s.in_scale_.array() > 0).all() || !(s.out_scale_ > 0))
      throw Error("SoftDecaSurrogate::load: " + path.string() + ": standardization means must be finite and scales > 0");
    return s;
  }

 private:
  void check_pair(const Eigen::MatrixXd& parameters, const Eigen::MatrixXd& expressions) const {
    const Index K = scenario::SoftDecaParameters::size;
    if (parameters.cols() != K || expressions.cols() != E_ || parameters.rows() != expressions.rows())
      throw ShapeError("SoftDecaSurrogate: parameters (N x 20) and expressions (N x E)", {parameters.rows(), K + E_},
                       {expressions.rows(), parameters.cols() + expressions.cols()});
  }
  /// z = [1, standardized expression weights, standardized parameters] (N × (inputs + 1)): the one
  /// standardization of the network's input (as float) and the linear base's (resized only when N changes).
  void standardize_into(const Eigen::Ref<const Eigen::MatrixXd>& expressions, const Eigen::Ref<const Eigen::MatrixXd>& parameters,
                        Eigen::MatrixXd& z) const {
    const Index E = E_, K = scenario::SoftDecaParameters::size;
    z.resize(parameters.rows(), inputs() + 1);
    z.col(0).setOnes();
    z.middleCols(1, E) = (expressions.rowwise() - in_mean_.head(E).transpose()).array().rowwise() / in_scale_.head(E).transpose().array();
    z.rightCols(K) = (parameters.rowwise() - in_mean_.tail(K).transpose()).array().rowwise() / in_scale_.tail(K).transpose().array();
  }
  void fit_output_normalization(const Eigen::MatrixXd& inputs_, const Eigen::MatrixXd& displacements) {
    const Eigen::MatrixXd y = network_part(inputs_, displacements);
    out_mean_ = y.colwise().mean().transpose();
    const double spread = std::sqrt((y.rowwise() - out_mean_.transpose()).array().square().mean());
    out_scale_ = spread > 0 ? spread : 1.0;
  }
  void check_inputs(const char* what, const Eigen::MatrixXd& x) const {
    if (x.cols() != inputs()) throw ShapeError(std::string("SoftDecaSurrogate::") + what + ": inputs", {x.rows(), inputs()}, {x.rows(), x.cols()});
    if (!x.allFinite()) throw ArgumentError(std::string("SoftDecaSurrogate::") + what + ": non-finite input");
  }

  Index E_ = 0, M_ = 0;
  std::vector<Index> hidden_;
  // on the heap: the layers point into the store, and the surrogate is movable (load() returns one)
  std::unique_ptr<ParameterStore<float>> store_ = std::make_unique<ParameterStore<float>>();
  std::unique_ptr<Mlp<float>> mlp_;
  VecX<> in_mean_, in_scale_, out_mean_;
  double out_scale_ = 1;
  Eigen::MatrixXd base_;    // the linear base, empty without one
  Matrix<float> in_, out_;  // predict's buffers
  Eigen::MatrixXd z_;       // predict's [1, z] (standardize_into)
};

/// Errors of one predictor on a set of samples (per skin vertex, Euclidean, m).
struct SurrogateErrors {
  double mean = 0, rms = 0, max = 0;
  double relative = 0;  ///< mean error / mean ‖displacement − the training mean displacement‖ (1: no better than the mean)
  nlohmann::ordered_json to_json() const { return {{"mean_m", mean}, {"rms_m", rms}, {"max_m", max}, {"relative_to_mean_predictor", relative}}; }
};

/// What train_softdeca_surrogate measured.
struct SoftDecaSurrogateReport {
  Index train_samples = 0, validation_samples = 0, held_out_samples = 0, epochs = 0, parameters = 0;
  std::vector<double> loss;             ///< per epoch, the mean training loss (standardized MSE)
  std::vector<double> validation_loss;  ///< per epoch, on the validation samples (empty without)
  Index best_epoch = 0;                 ///< the epoch whose weights were kept (0-based)
  double base_lambda = 0;               ///< the linear base's λ (0: no base)
  SurrogateErrors train, held_out, mean_baseline, ridge_baseline;  ///< the last three on the held-out samples
  SurrogateErrors base_alone;  ///< the linear base without the network, on the held-out samples (with a base)
  /// On the validation samples (none without): the predictor with the kept weights, and the
  /// linear base alone (with a base). In metres, so settings (widths, decay, with or without a
  /// base) can be chosen on them and the held-out samples stay unseen by every choice.
  SurrogateErrors validation, validation_base_alone;
  double train_seconds = 0;
  double inference_seconds = 0;  ///< one sample (batch of 1), median of repeated calls, the policy's threads
  double solver_seconds = 0;     ///< mean simulation time of the held-out samples (from the dataset)
  nlohmann::ordered_json to_json() const {
    return {{"train_samples", train_samples},
            {"validation_samples", validation_samples},
            {"held_out_samples", held_out_samples},
            {"epochs", epochs},
            {"best_epoch", best_epoch + 1},
            {"linear_base_lambda", base_lambda},
            {"network_parameters", parameters},
            {"final_train_loss", loss.empty() ? 0.0 : loss.back()},
            {"best_validation_loss", validation_loss.empty() ? 0.0 : validation_loss[std::size_t(best_epoch)]},
            {"train", train.to_json()},
            {"held_out", held_out.to_json()},
            {"held_out_mean_baseline", mean_baseline.to_json()},
            {"held_out_ridge_baseline", ridge_baseline.to_json()},
            {"held_out_linear_base_alone", base_lambda > 0 ? base_alone.to_json() : nlohmann::ordered_json()},
            {"validation", validation_samples > 0 ? validation.to_json() : nlohmann::ordered_json()},
            {"validation_linear_base_alone", validation_samples > 0 && base_lambda > 0 ? validation_base_alone.to_json() : nlohmann::ordered_json()},
            {"train_seconds", train_seconds},
            {"inference_seconds_per_sample", inference_seconds},
            {"solver_seconds_per_sample", solver_seconds},
            {"speedup", inference_seconds > 0 ? solver_seconds / inference_seconds : 0.0}};
  }
};

/// Per-vertex Euclidean errors of `pred` against `truth` (N × 3M), relative to `reference`'s
/// (the training mean displacement's) distance from the truth.
inline SurrogateErrors surrogate_errors(const Eigen::MatrixXd& pred, const Eigen::MatrixXd& truth, const VecX<>& reference) {
  SurrogateErrors e;
  const Index N = truth.rows(), M = truth.cols() / 3;
  if (N == 0) return e;
  double sum = 0, sq = 0, ref = 0;
  for (Index i = 0; i < N; ++i)
    for (Index v = 0; v < M; ++v) {
      const double d = (pred.row(i).segment<3>(3 * v) - truth.row(i).segment<3>(3 * v)).norm();
      sum += d;
      sq += d * d;
      e.max = std::max(e.max, d);
      ref += (reference.segment<3>(3 * v).transpose() - truth.row(i).segment<3>(3 * v)).norm();
    }
  const double n = double(N * M);
  e.mean = sum / n;
  e.rms = std::sqrt(sq / n);
  e.relative = ref > 0 ? sum / ref : 0;
  return e;
}

/// Trains `net` on the first (1 − held_out) of `data`'s samples and reports (see the file
/// comment). ArgumentError when fewer than 2 samples would be trained on or none held out.
template <exec::HostPolicy P>
SoftDecaSurrogateReport train_softdeca_surrogate(P policy, const scenario::SoftDecaDataset& data, const SoftDecaSurrogateOptions& o, SoftDecaSurrogate& net) {
  const Index N = data.size();
  if (data.expressions.cols() != net.expressions() || data.skin_vertices() != net.skin_vertices())
    throw ShapeError("train_softdeca_surrogate: the network's expressions and skin vertices vs the dataset's", {net.expressions(), net.skin_vertices()},
                     {data.expressions.cols(), data.skin_vertices()});
  if (!(o.held_out > 0 && o.held_out < 1)) throw ArgumentError("train_softdeca_surrogate: held_out must be in (0, 1)");
  if (!(o.validation >= 0 && o.validation < 1)) throw ArgumentError("train_softdeca_surrogate: validation must be in [0, 1)");
  if (o.epochs < 1 || o.batch < 1 || !(o.lr > 0)) throw ArgumentError("train_softdeca_surrogate: need epochs >= 1, batch >= 1, lr > 0");
  const Index test = std::max<Index>(1, Index(std::llround(o.held_out * double(N)))), train = N - test;
  const Index val = o.validation > 0 ? std::max<Index>(1, Index(std::llround(o.validation * double(train)))) : 0, fit = train - val;
  if (fit < 2) throw ArgumentError("train_softdeca_surrogate: " + std::to_string(N) + " samples leave fewer than 2 to train on");
  const auto t0 = std::chrono::steady_clock::now();
  SoftDecaSurrogateReport r;
  r.train_samples = fit;
  r.validation_samples = val;
  r.held_out_samples = test;
  r.epochs = o.epochs;
  r.parameters = net.store().num_parameters();

  const Eigen::MatrixXd X = net.join(data.parameters, data.expressions);
  const Eigen::MatrixXd Xtr = X.topRows(train), Xte = X.bottomRows(test);
  const Eigen::MatrixXd Ytr = data.displacements.topRows(train), Yte = data.displacements.bottomRows(test);
  net.clear_linear_base();  // a network trained before starts from its standardization alone
  net.fit_normalization(Xtr, Ytr);
  if (o.linear_base) {  // fitted on the fit samples, its λ picked on the validation ones
    double lambda = o.ridge_lambda, least = std::numeric_limits<double>::infinity();
    if (val > 0) {
      const Eigen::MatrixXd Afit = net.with_intercept(Xtr.topRows(fit)), Aval = net.with_intercept(Xtr.bottomRows(val));
      for (double l : o.base_lambdas) {
        const double e = (Aval * net.parameter_ridge_of(Afit, Ytr.topRows(fit), l) - Ytr.bottomRows(val)).squaredNorm();
        if (e < least) least = e, lambda = l;
      }
    }
    net.fit_linear_base(Xtr.topRows(fit), Ytr.topRows(fit), lambda);
    r.base_lambda = lambda;
  }
  const Matrix<float> in = net.standardize(Xtr), target = net.standardize_output(net.network_part(Xtr, Ytr));

  Adam<float> adam(net.store(), {.lr = o.lr, .weight_decay = o.weight_decay});
  Rng rng(o.seed);
  std::vector<Index> order(static_cast<std::size_t>(fit));
  std::iota(order.begin(), order.end(), Index(0));
  Matrix<float> xb, yb, out, diff, d_out, val_out;
  const Index steps_per_epoch = (fit + o.batch - 1) / o.batch;
  std::vector<float> best(net.store().values().data(), net.store().values().data() + net.store().num_parameters());
  double best_loss = std::numeric_limits<double>::infinity();
  for (Index epoch = 0; epoch < o.epochs; ++epoch) {
    const double progress = double(epoch) / double(std::max<Index>(1, o.epochs - 1));
    adam.set_lr(o.lr * (o.lr_final_fraction + (1 - o.lr_final_fraction) * 0.5 * (1 + std::cos(3.14159265358979323846 * progress))));
    std::shuffle(order.begin(), order.end(), rng);
    double loss = 0;
    for (Index s = 0; s < steps_per_epoch; ++s) {
      const Index b = s * o.batch, n = std::min(o.batch, fit - b);
      xb.resize(n, in.cols());
      yb.resize(n, target.cols());
      for (Index k = 0; k < n; ++k) {
        xb.row(k) = in.row(order[std::size_t(b + k)]);
        yb.row(k) = target.row(order[std::size_t(b + k)]);
      }
      net.store().zero_grad();
      net.mlp().forward(policy, Mode::train, xb, out);
      diff.noalias() = out - yb;
      loss += double(mean_square(policy, diff, &d_out)) * double(n);
      net.mlp().backward(policy, xb, out, d_out, nullptr);
      adam.step(policy);
    }
    r.loss.push_back(loss / double(fit));
    if (!std::isfinite(r.loss.back())) throw ConvergenceError("train_softdeca_surrogate (the loss is not finite)", epoch, r.loss.back());
    if (val > 0) {
      net.mlp().forward(policy, Mode::eval, in.bottomRows(val), val_out);
      const double v = double((val_out - target.bottomRows(val)).squaredNorm()) / double(val_out.size());
      r.validation_loss.push_back(v);
      if (v < best_loss) {
        best_loss = v;
        r.best_epoch = epoch;
        std::copy_n(net.store().values().data(), best.size(), best.begin());
      }
    } else {
      r.best_epoch = epoch;
    }
    if (o.progress) o.progress(epoch, r.loss.back());
  }
  if (val > 0) std::copy(best.begin(), best.end(), net.store().values().data());
  r.train_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const VecX<> mean = Ytr.colwise().mean().transpose();
  // the surrogate's (or the linear base's alone) errors on samples [first, first + n)
  const auto surrogate_on = [&](Index first, Index n) {
    return surrogate_errors(net.predict(policy, data.parameters.middleRows(first, n), data.expressions.middleRows(first, n)),
                            data.displacements.middleRows(first, n), mean);
  };
  const auto base_on = [&](Index first, Index n) {
    return surrogate_errors(net.with_intercept(X.middleRows(first, n)) * net.linear_base(), data.displacements.middleRows(first, n), mean);
  };
  r.train = surrogate_on(0, train);
  r.held_out = surrogate_on(train, test);
  r.mean_baseline = surrogate_errors(Eigen::MatrixXd(mean.transpose().replicate(test, 1)), Yte, mean);
  if (o.linear_base) r.base_alone = base_on(train, test);
  if (val > 0) {
    r.validation = surrogate_on(fit, val);
    if (o.linear_base) r.validation_base_alone = base_on(fit, val);
  }
  // ridge on the same standardized inputs, [1, z] → y, fitted on every training sample
  r.ridge_baseline = surrogate_errors(net.with_intercept(Xte) * SoftDecaSurrogate::ridge_fit(net.with_intercept(Xtr), Ytr, o.ridge_lambda), Yte, mean);
  // speed: one sample at a time, as a solver would be asked
  {
    const Eigen::MatrixXd p1 = data.parameters.bottomRows(1), e1 = data.expressions.bottomRows(1);
    Eigen::MatrixXd d1;
    net.predict(policy, p1, e1, d1);  // warm-up: buffers sized
    std::vector<double> times;
    for (int k = 0; k < 21; ++k) {
      const auto a = std::chrono::steady_clock::now();
      net.predict(policy, p1, e1, d1);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
    }
    std::nth_element(times.begin(), times.begin() + 10, times.end());
    r.inference_seconds = times[10];
  }
  r.solver_seconds = data.seconds.tail(test).mean();
  return r;
}

/// What `simsr train-surrogate` does: reads a datagen output (`data`: its directory or its
/// softdeca_samples.npz), trains a surrogate of the given hidden widths and writes, atomically,
/// OUT/surrogate.npz (the model, naming its data's fingerprint), OUT/surrogate_report.json (the
/// report with the run's settings) and OUT/surrogate_loss.csv (training and validation loss per
/// epoch). Returns the report's JSON. `say` gets a line at the start and every 25 epochs.
template <exec::HostPolicy P>
nlohmann::ordered_json train_softdeca_surrogate_files(P policy, const std::filesystem::path& data_path, const std::filesystem::path& out,
                                                      const std::vector<Index>& hidden, SoftDecaSurrogateOptions o,
                                                      const std::function<void(const std::string&)>& say = {}) {
  const scenario::SoftDecaDataset data = scenario::read_softdeca_dataset(data_path);
  const auto tell = [&](const std::string& line) {
    if (say) say(line);
  };
  tell(std::to_string(data.size()) + " samples, " + std::to_string(data.skin_vertices()) + " skin vertices, " +
       std::to_string(data.expressions.cols()) + " expressions");
  SoftDecaSurrogate net(data.expressions.cols(), data.skin_vertices(), hidden, o.seed);
  const auto user_progress = o.progress;
  o.progress = [&](Index epoch, double loss) {
    if (user_progress) user_progress(epoch, loss);
    if (epoch == 0 || (epoch + 1) % 25 == 0 || epoch + 1 == o.epochs)
      tell("epoch " + std::to_string(epoch + 1) + "/" + std::to_string(o.epochs) + " loss " + std::to_string(loss));
  };
  const SoftDecaSurrogateReport r = train_softdeca_surrogate(policy, data, o, net);
  std::filesystem::create_directories(out);
  net.save(out / "surrogate.npz", {{"data", data_path.string()}, {"data_fingerprint", data.fingerprint}});
  nlohmann::ordered_json j = r.to_json();
  j["data"] = data_path.string();
  j["data_fingerprint"] = data.fingerprint;
  j["hidden"] = hidden;
  j["batch"] = o.batch;
  j["lr"] = o.lr;
  j["weight_decay"] = o.weight_decay;
  j["linear_base"] = o.linear_base;
  j["seed"] = o.seed;
  io::write_file_atomic(out / "surrogate_report.json", j.dump(2) + "\n");
  std::string csv = "epoch,train_loss,validation_loss\n";
  for (std::size_t e = 0; e < r.loss.size(); ++e) {
    char row[96];
    std::snprintf(row, sizeof row, "%zu,%.9g,", e + 1, r.loss[e]);  // validation loss after the comma, or empty
    csv += row;
    if (e < r.validation_loss.size()) {
      std::snprintf(row, sizeof row, "%.9g", r.validation_loss[e]);
      csv += row;
    }
    csv += '\n';
  }
  io::write_file_atomic(out / "surrogate_loss.csv", csv);
  return j;
}

}  // namespace simsr::nn
