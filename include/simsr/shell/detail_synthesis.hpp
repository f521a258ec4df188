#pragma once
/// \file
/// The transduction network of Chen et al. 2023 (supplement §3) put together, trained and run:
/// coarse TS-ACAP features → coarse encoder → DeformTransformer (with the fine latents of the
/// frames before) → fine latent → fine decoder → fine TS-ACAP features → positions.
///
///     shell::DetailSynthesisNet<float> net(coarse_rest, fine_rest, {}, /*seed*/ 1);
///     net.fit_scaling(train_sequences);                         // per-channel mean and std
///     const auto loss = net.train_step(exec::omp, batch, rng);  // one Adam step
///     const auto fine = net.synthesize(exec::omp, coarse_features);
///
/// Training, per window of T consecutive frames s..s+T−1 of one sequence (the supplement prints
/// no loss; these are the terms an encoder–transformer–decoder needs):
///   L = ‖D(ẑ) − f‖² + ‖D(E_f(f)) − f‖² + ‖ẑ − sg(E_f(f))‖² / sg(‖E_f(f)‖²)   (means over entries)
/// with f the fine features of the window (normalized), ẑ = Transformer(E_c(c + n), E_f(f shifted
/// by one frame)) and n ~ N(0, 0.001) the supplement's noise on the coarse inputs (variance
/// 0.001). The second term makes D the decoder of E_f's latent space (so the fine latents fed back
/// at inference decode to meshes); the third pulls the transformer's output onto that space;
/// sg = no gradient to the target (both sides moving would let the latents shrink together).
/// The frame before s is the rest mesh (features of the identity) when s = 0.
///
/// Inference (synthesize): frame t uses the window t−T+1..t (0..T−1 while t < T−1, reading
/// position t: a look-ahead of at most T−1 coarse frames at a sequence's start only) and the
/// network's own fine latents of the previous frames, never the ground truth.

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../io/atomic_file.hpp"
#include "../io/npz.hpp"
#include "../nn/adam.hpp"
#include "../nn/model_file.hpp"
#include "deform_transformer.hpp"
#include "mesh_autoencoder.hpp"
#include "ts_acap.hpp"

namespace simsr::shell {

/// Per-channel affine scaling of TS-ACAP features: (f − mean) / std over all vertices and
/// training frames (std floored at 1e-6 so a constant channel cannot divide by zero).
struct FeatureScaling {
  Eigen::Matrix<double, ts_acap_feature_dim, 1> mean = Eigen::Matrix<double, ts_acap_feature_dim, 1>::Zero();
  Eigen::Matrix<double, ts_acap_feature_dim, 1> scale = Eigen::Matrix<double, ts_acap_feature_dim, 1>::Ones();

  /// From every row of every matrix in `frames` (each #V×9).
  static FeatureScaling fit(const std::vector<const TsAcapFeatures<double>*>& frames) {
    FeatureScaling s;
    Eigen::Matrix<double, ts_acap_feature_dim, 1> sum = decltype(sum)::Zero(), sq = decltype(sq)::Zero();
    double n = 0;
    for (const auto* f : frames) {
      sum += f->colwise().sum().transpose();
      sq += f->cwiseAbs2().colwise().sum().transpose();
      n += double(f->rows());
    }
    if (n == 0) throw ArgumentError("FeatureScaling::fit: no frames");
    s.mean = sum / n;
    s.scale = (sq / n - s.mean.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt().cwiseMax(1e-6);
    return s;
  }
  /// Normalized rows of f appended to `out` at row `row` (out must have the room).
  template <class S>
  void normalize(const TsAcapFeatures<double>& f, nn::Matrix<S>& out, Index row) const {
    for (Index i = 0; i < f.rows(); ++i)
      for (Index c = 0; c < ts_acap_feature_dim; ++c) out(row + i, c) = S((f(i, c) - mean[c]) / scale[c]);
  }
  template <class S>
  TsAcapFeatures<double> denormalize(const nn::ConstView<S>& rows) const {
    TsAcapFeatures<double> f(rows.rows(), ts_acap_feature_dim);
    for (Index i = 0; i < rows.rows(); ++i)
      for (Index c = 0; c < ts_acap_feature_dim; ++c) f(i, c) = double(rows(i, c)) * scale[c] + mean[c];
    return f;
  }
};

/// The rest mesh's features: no rotation, identity stretch.
inline TsAcapFeatures<double> rest_features(Index n) {
  TsAcapFeatures<double> f(n, ts_acap_feature_dim);
  f.rowwise() = Eigen::Matrix<double, 1, ts_acap_feature_dim>({0, 0, 0, 1, 0, 0, 1, 0, 1});
  return f;
}

/// What the fine side of the network (the fine encoder's input, the decoder's output) holds.
enum class FineTarget {
  features,  ///< the fine TS-ACAP features themselves (the supplement)
  /// their difference from the TS-ACAP features of the Loop-subdivided coarse frame: a network
  /// that outputs zero gives back (the Poisson solve of) the subdivided mesh, so what it learns
  /// is the fine simulation's departure from it, not the whole shape through a 16-d bottleneck
  residual,
};

inline const char* fine_target_name(FineTarget t) { return t == FineTarget::residual ? "residual" : "features"; }
/// ArgumentError for a name other than "features" or "residual".
inline FineTarget parse_fine_target(const std::string& name) {
  if (name == "features") return FineTarget::features;
  if (name == "residual") return FineTarget::residual;
  throw ArgumentError("fine target '" + name + "': expected 'features' or 'residual'");
}

/// Which axis–angle forms a residual target's fine rotation vectors take before the subdivided
/// coarse frame's are subtracted. The two sides are lifted by their own integer problems (Eq. 2–4)
/// and can differ by 2π where those chose differently (on DISK's fine cloth 1.6 % of edge-frames
/// jump by more than π); every form decodes alike, so the choice changes only what is learnt.
enum class ResidualLift {
  nearest,  ///< each vertex's form nearest the subdivided frame's (lift_rotations_toward): the residual is the rotation between them
  own,      ///< the fine sequence's own forms, as the features target holds them
};

inline const char* residual_lift_name(ResidualLift l) { return l == ResidualLift::nearest ? "nearest" : "own"; }
/// ArgumentError for a name other than "nearest" or "own".
inline ResidualLift parse_residual_lift(const std::string& name) {
  if (name == "nearest") return ResidualLift::nearest;
  if (name == "own") return ResidualLift::own;
  throw ArgumentError("residual lift '" + name + "': expected 'nearest' or 'own'");
}

struct DetailSynthesisOptions {
  MeshCodecOptions codec;  ///< encoders and decoder: 9 channels, 16-d latent
  DeformTransformerOptions transformer;
  double noise_variance = 0.001;  ///< on the normalized coarse inputs in training (supplement §3)
  double lr = 1e-3;               ///< Adam; ×lr_decay every lr_step epochs (supplement §3)
  double lr_decay = 0.1;
  Index lr_step = 20;
  FineTarget fine_target = FineTarget::residual;  ///< see FineTarget; the README gives both's figures
  ResidualLift residual_lift = ResidualLift::nearest;  ///< a residual target's rotation forms (see ResidualLift)
};

/// One training batch: `windows` (sequence, first frame) pairs into the sequences' features.
struct SynthesisBatch {
  std::vector<std::pair<Index, Index>> windows;
};

/// The loss terms of one step (means over entries, normalized feature units).
struct SynthesisLoss {
  double synthesis = 0, reconstruction = 0, latent = 0;
  double total() const { return synthesis + reconstruction + latent; }
};

/// A sequence's normalized features: coarse (F·N)×9, fine (F·M)×9 (fine empty at inference).
template <class S>
struct SequenceFeatures {
  nn::Matrix<S> coarse, fine;
  Index frames = 0;
};

template <class S = float>
class DetailSynthesisNet {
 public:
  using scalar_type = S;

  DetailSynthesisNet(const Adjacency& coarse, const Adjacency& fine, DetailSynthesisOptions options, std::uint64_t seed)
      : opt_(check(options)), n_(coarse.num_vertices()), m_(fine.num_vertices()), rng_(seed),
        coarse_enc_(store_, "coarse_enc", coarse, options.codec, rng_),
        fine_enc_(store_, "fine_enc", fine, options.codec, rng_),
        transformer_(store_, "transformer", options.transformer, rng_),
        fine_dec_(store_, "fine_dec", fine, options.codec, rng_),
        adam_(store_, {.lr = options.lr}) {
    rest_.resize(m_, ts_acap_feature_dim);
    set_scaling(FeatureScaling{}, FeatureScaling{});
  }

  Index num_coarse() const { return n_; }
  Index num_fine() const { return m_; }
  Index frames() const { return opt_.transformer.frames; }
  const DetailSynthesisOptions& options() const { return opt_; }
  nn::ParameterStore<S>& store() { return store_; }
  const nn::ParameterStore<S>& store() const { return store_; }
  /// The feature scalings (from the training frames: FeatureScaling::fit); the rest mesh's
  /// normalized features, the fine input before a sequence's first frame, follow from the fine one
  /// (as a residual the rest mesh is zero: the subdivided rest mesh is the fine rest mesh).
  void set_scaling(const FeatureScaling& coarse, const FeatureScaling& fine) {
    scale_c_ = coarse;
    scale_f_ = fine;
    if (opt_.fine_target == FineTarget::residual) scale_f_.normalize(TsAcapFeatures<double>::Zero(m_, ts_acap_feature_dim), rest_, 0);
    else scale_f_.normalize(rest_features(m_), rest_, 0);
  }
  const FeatureScaling& coarse_scaling() const { return scale_c_; }
  const FeatureScaling& fine_scaling() const { return scale_f_; }
  nn::Adam<S>& optimizer() { return adam_; }
  const nn::Adam<S>& optimizer() const { return adam_; }

  /// The normalized features of one sequence (fine may be empty: inference).
  SequenceFeatures<S> normalize(const std::vector<TsAcapFeatures<double>>& coarse, const std::vector<TsAcapFeatures<double>>& fine) const {
    SequenceFeatures<S> out;
    out.frames = static_cast<Index>(coarse.size());
    if (!fine.empty() && fine.size() != coarse.size())
      throw ShapeError("DetailSynthesisNet::normalize: fine frames (as many as coarse)", {out.frames}, {static_cast<Index>(fine.size())});
    out.coarse.resize(out.frames * n_, ts_acap_feature_dim);
    for (Index f = 0; f < out.frames; ++f) {
      if (coarse[std::size_t(f)].rows() != n_) throw ShapeError("DetailSynthesisNet: coarse features", {n_, 9}, {coarse[std::size_t(f)].rows(), 9});
      scale_c_.normalize(coarse[std::size_t(f)], out.coarse, f * n_);
    }
    if (!fine.empty()) {
      out.fine.resize(out.frames * m_, ts_acap_feature_dim);
      for (Index f = 0; f < out.frames; ++f) {
        if (fine[std::size_t(f)].rows() != m_) throw ShapeError("DetailSynthesisNet: fine features", {m_, 9}, {fine[std::size_t(f)].rows(), 9});
        scale_f_.normalize(fine[std::size_t(f)], out.fine, f * m_);
      }
    }
    return out;
  }

  /// One Adam step on `batch` (forward, backward, update); returns the loss before the update.
  template <exec::HostPolicy P>
  SynthesisLoss train_step(P policy, const std::vector<SequenceFeatures<S>>& seqs, const SynthesisBatch& batch, nn::Rng& rng) {
    const Index T = frames(), B = static_cast<Index>(batch.windows.size());
    if (B == 0) throw ArgumentError("DetailSynthesisNet::train_step: an empty batch");
    coarse_in_.resize(B * T * n_, ts_acap_feature_dim);
    fine_all_.resize(B * (T + 1) * m_, ts_acap_feature_dim);
    target_.resize(B * T * m_, ts_acap_feature_dim);
    std::normal_distribution<double> noise(0.0, std::sqrt(opt_.noise_variance));
    for (Index b = 0; b < B; ++b) {
      const auto [q, s] = batch.windows[std::size_t(b)];
      if (q < 0 || q >= static_cast<Index>(seqs.size()) || s < 0 || s + T > seqs[std::size_t(q)].frames || seqs[std::size_t(q)].fine.rows() == 0)
        throw ArgumentError("DetailSynthesisNet::train_step: window (" + std::to_string(q) + ", " + std::to_string(s) + ") is outside the data");
      const SequenceFeatures<S>& sq = seqs[std::size_t(q)];
      coarse_in_.middleRows(b * T * n_, T * n_) = sq.coarse.middleRows(s * n_, T * n_);
      if (s == 0) fine_all_.middleRows(b * (T + 1) * m_, m_) = rest_;
      else fine_all_.middleRows(b * (T + 1) * m_, m_) = sq.fine.middleRows((s - 1) * m_, m_);
      fine_all_.middleRows((b * (T + 1) + 1) * m_, T * m_) = sq.fine.middleRows(s * m_, T * m_);
      target_.middleRows(b * T * m_, T * m_) = sq.fine.middleRows(s * m_, T * m_);
    }
    if (opt_.noise_variance > 0)
      for (Index i = 0; i < coarse_in_.size(); ++i) coarse_in_.data()[i] += S(noise(rng));

    store_.zero_grad();
    coarse_enc_.forward(policy, nn::Mode::train, coarse_in_, zc_);
    fine_enc_.forward(policy, nn::Mode::train, fine_all_, zf_);
    const Index L = opt_.codec.latent;
    fine_in_.resize(B * T, L);
    z_target_.resize(B * T, L);
    for (Index b = 0; b < B; ++b)
      for (Index t = 0; t < T; ++t) {
        fine_in_.row(b * T + t) = zf_.row(b * (T + 1) + t);
        z_target_.row(b * T + t) = zf_.row(b * (T + 1) + t + 1);
      }
    transformer_.forward(policy, nn::Mode::train, zc_, fine_in_, z_hat_);

    SynthesisLoss loss;
    const double nz = double(z_hat_.size()), nf = double(target_.size());
    // ‖ẑ − sg(z)‖² / sg(mean z²): relative to the latents' own scale, which nothing else fixes
    // (the decoder takes any scale; on SHEET at 81 / 1,089 vertices the absolute term grew to
    // ~2,000 in 5 epochs and its gradient swamped the synthesis term's)
    d_z_hat_ = z_hat_ - z_target_;
    const double scale = double(z_target_.squaredNorm()) / nz + 1e-12;
    loss.latent = double(d_z_hat_.squaredNorm()) / nz / scale;
    d_z_hat_ *= S(2.0 / nz / scale);
    // ‖D(E_f(f)) − f‖²: gradient into the fine encoder's target rows
    fine_dec_.forward(policy, nn::Mode::train, z_target_, dec_out_);
    d_dec_ = dec_out_ - target_;
    loss.reconstruction = double(d_dec_.squaredNorm()) / nf;
    d_dec_ *= S(2.0 / nf);
    fine_dec_.backward(policy, z_target_, dec_out_, d_dec_, &d_z_target_);
    // ‖D(ẑ) − f‖²
    fine_dec_.forward(policy, nn::Mode::train, z_hat_, dec_out_);
    d_dec_ = dec_out_ - target_;
    loss.synthesis = double(d_dec_.squaredNorm()) / nf;
    d_dec_ *= S(2.0 / nf);
    fine_dec_.backward(policy, z_hat_, dec_out_, d_dec_, &d_tmp_);
    d_z_hat_ += d_tmp_;
    transformer_.backward(policy, zc_, fine_in_, z_hat_, d_z_hat_, &d_zc_, &d_fine_in_);
    d_zf_.setZero(zf_.rows(), L);
    for (Index b = 0; b < B; ++b)
      for (Index t = 0; t < T; ++t) {
        d_zf_.row(b * (T + 1) + t) += d_fine_in_.row(b * T + t);
        d_zf_.row(b * (T + 1) + t + 1) += d_z_target_.row(b * T + t);
      }
    fine_enc_.backward(policy, fine_all_, zf_, d_zf_, nullptr);
    coarse_enc_.backward(policy, coarse_in_, zc_, d_zc_, nullptr);
    if (!std::isfinite(loss.total())) throw NumericalError("DetailSynthesisNet::train_step", "the loss", std::int64_t(adam_.steps()), loss.total());
    adam_.step(policy);
    return loss;
  }

  /// Normalized fine features (F·M)×9 of a sequence from its normalized coarse features (F·N)×9,
  /// frame by frame with the network's own previous fine latents (see the file comment).
  /// ArgumentError for a sequence shorter than T frames.
  template <exec::HostPolicy P>
  nn::Matrix<S> synthesize(P policy, const nn::ConstView<S>& coarse) {
    const Index T = frames(), L = opt_.codec.latent;
    if (coarse.cols() != ts_acap_feature_dim || coarse.rows() % n_ != 0)
      throw ShapeError("DetailSynthesisNet::synthesize: coarse features (F·N rows)", {-1, 9}, {coarse.rows(), coarse.cols()});
    const Index F = coarse.rows() / n_;
    if (F < T) throw ArgumentError("DetailSynthesisNet::synthesize: a sequence needs >= " + std::to_string(T) + " frames, got " + std::to_string(F));
    coarse_enc_.forward(policy, nn::Mode::eval, coarse, zc_);
    fine_enc_.forward(policy, nn::Mode::eval, rest_, zf_);
    nn::Matrix<S> z(F + 1, L);  // row t+1: frame t's fine latent; row 0: the rest mesh's
    z.row(0) = zf_.row(0);
    fine_in_.resize(T, L);
    for (Index t = 0; t < F; ++t) {
      const Index s = std::max<Index>(0, t - T + 1);
      // position j's fine input is frame s+j−1 (z row s+j); rows past frame t−1 are not known yet
      // and the causal decoder does not read them at position t − s: the last known row fills them
      for (Index j = 0; j < T; ++j) fine_in_.row(j) = z.row(std::min(s + j, t));
      transformer_.forward(policy, nn::Mode::eval, zc_.middleRows(s, T), fine_in_, z_hat_);
      z.row(t + 1) = z_hat_.row(t - s);
    }
    nn::Matrix<S> out;
    fine_dec_.forward(policy, nn::Mode::eval, z.bottomRows(F), out);
    return out;
  }

  /// Writes the weights, the scalings and the options to an npz (atomically).
  void save(const std::filesystem::path& file) const {
    io::NpzArrays z;
    nn::add_state(z, store_);
    nlohmann::json j{{"kind", "shell::DetailSynthesisNet"}, {"coarse_vertices", n_}, {"fine_vertices", m_},
                     {"latent", opt_.codec.latent}, {"channels", opt_.codec.channels}, {"d_model", opt_.transformer.d_model},
                     {"feed_forward", opt_.transformer.feed_forward}, {"heads", opt_.transformer.heads},
                     {"blocks", opt_.transformer.blocks}, {"frames", opt_.transformer.frames},
                     {"fine_target", fine_target_name(opt_.fine_target)}};
    if (opt_.fine_target == FineTarget::residual) j["residual_lift"] = residual_lift_name(opt_.residual_lift);  // how it was trained
    z["config"] = io::make_npy(std::vector<std::string>{j.dump()});
    for (const auto& [name, s] : {std::pair{"coarse", &scale_c_}, std::pair{"fine", &scale_f_}}) {
      z[std::string("scaling/") + name + "_mean"] = io::make_npy<double>({ts_acap_feature_dim}, s->mean.data());
      z[std::string("scaling/") + name + "_scale"] = io::make_npy<double>({ts_acap_feature_dim}, s->scale.data());
    }
    io::write_npz(file, z);
  }

  /// Reads what save() wrote into this network; ArgumentError when the file is of another
  /// network shape or mesh, ParseError when it is not such a file.
  void load(const std::filesystem::path& file) {
    const io::NpzArrays z = io::read_npz(file);
    const nlohmann::json j = model_config(z, file);
    if (j.at("coarse_vertices").get<Index>() != n_ || j.at("fine_vertices").get<Index>() != m_)
      throw ArgumentError(file.string() + ": a model of " + std::to_string(j["coarse_vertices"].get<Index>()) + " / " +
                          std::to_string(j["fine_vertices"].get<Index>()) + " vertices, this mesh pair has " + std::to_string(n_) + " / " +
                          std::to_string(m_));
    if (const FineTarget t = named_option(j, "fine_target", "features", parse_fine_target, file); t != opt_.fine_target)
      throw ArgumentError(file.string() + ": a model whose fine side holds '" + fine_target_name(t) + "', this network's holds '" +
                          fine_target_name(opt_.fine_target) + "'");
    nn::load_state(store_, z);
    FeatureScaling sc[2];
    for (int r = 0; r < 2; ++r) {
      const std::string name = std::string("scaling/") + (r == 0 ? "coarse" : "fine");
      if (!z.contains(name + "_mean") || !z.contains(name + "_scale")) throw ParseError(file.string(), 0, "no feature scaling '" + name + "'");
      const auto m = z.at(name + "_mean").template to_vector<double>();
      const auto c = z.at(name + "_scale").template to_vector<double>();
      if (m.size() != 9 || c.size() != 9) throw ParseError(file.string(), 0, "feature scaling of the wrong size");
      for (int k = 0; k < 9; ++k) {
        if (!std::isfinite(m[std::size_t(k)]) || !(c[std::size_t(k)] > 0)) throw ParseError(file.string(), 0, "feature scaling '" + name + "' not finite or not positive");
        sc[r].mean[k] = m[std::size_t(k)], sc[r].scale[k] = c[std::size_t(k)];
      }
    }
    set_scaling(sc[0], sc[1]);
  }

  /// The options a saved model was built with (so a caller can construct the network to load it).
  static DetailSynthesisOptions saved_options(const std::filesystem::path& file) {
    const nlohmann::json j = model_config(io::read_npz(file), file);
    DetailSynthesisOptions o;
    o.codec.latent = j.at("latent").get<Index>();
    o.codec.channels = j.at("channels").get<Index>();
    o.transformer.latent = o.codec.latent;
    o.transformer.d_model = j.at("d_model").get<Index>();
    o.transformer.feed_forward = j.at("feed_forward").get<Index>();
    o.transformer.heads = j.at("heads").get<Index>();
    o.transformer.blocks = j.at("blocks").get<Index>();
    o.transformer.frames = j.at("frames").get<Index>();
    // files written before these options held features, and lifted residuals as their own integer steps did
    o.fine_target = named_option(j, "fine_target", "features", parse_fine_target, file);
    o.residual_lift = named_option(j, "residual_lift", "own", parse_residual_lift, file);
    return o;
  }

 private:
  /// The JSON config of a file save() wrote; ParseError when the file is not such a model.
  static nlohmann::json model_config(const io::NpzArrays& z, const std::filesystem::path& file) {
    if (!z.contains("config")) throw ParseError(file.string(), 0, "not a detail-synthesis model (no 'config')");
    const auto text = z.at("config").to_strings();
    const nlohmann::json j = text.empty() ? nlohmann::json() : nlohmann::json::parse(text[0], nullptr, false);
    if (j.is_discarded() || !j.is_object() || j.value("kind", "") != "shell::DetailSynthesisNet")
      throw ParseError(file.string(), 0, "not a detail-synthesis model");
    return j;
  }
  /// A saved model's option `key` parsed by `parse` (`missing` where the file predates it);
  /// ParseError naming the file and the key for a value `parse` refuses.
  template <class Parse>
  static auto named_option(const nlohmann::json& j, const char* key, const char* missing, Parse parse, const std::filesystem::path& file) {
    try {
      return parse(j.value(key, std::string(missing)));
    } catch (const std::exception& e) {
      throw ParseError(file.string(), 0, std::string("the model's ") + key + ": " + e.what());
    }
  }
  static DetailSynthesisOptions check(DetailSynthesisOptions o) {
    if (o.transformer.latent != o.codec.latent)
      throw ArgumentError("DetailSynthesisNet: the transformer's latent (" + std::to_string(o.transformer.latent) + ") must be the codec's (" +
                          std::to_string(o.codec.latent) + ")");
    if (!(o.noise_variance >= 0) || !(o.lr > 0) || !(o.lr_decay > 0) || o.lr_step < 1)
      throw ArgumentError("DetailSynthesisNet: noise_variance >= 0, lr > 0, lr_decay > 0 and lr_step >= 1 are required");
    return o;
  }

  DetailSynthesisOptions opt_;
  Index n_, m_;
  nn::Rng rng_;
  nn::ParameterStore<S> store_;
  MeshEncoder<S> coarse_enc_, fine_enc_;
  DeformTransformer<S> transformer_;
  MeshDecoder<S> fine_dec_;
  nn::Adam<S> adam_;
  FeatureScaling scale_c_, scale_f_;
  nn::Matrix<S> rest_, coarse_in_, fine_all_, target_, zc_, zf_, fine_in_, z_target_, z_hat_, d_z_hat_, dec_out_, d_dec_, d_z_target_, d_tmp_,
      d_zc_, d_fine_in_, d_zf_;
};

}  // namespace simsr::shell
