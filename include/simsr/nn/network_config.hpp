#pragma once
/// \file
/// The architecture and training settings of the super-resolution network (SPEC §7), as one
/// value: the `official` and `paper` profiles are two presets of it, the ablations (w/o FE,
/// w/o CU, residual, k sweeps) one field away. It travels inside a model file as JSON with the
/// key names of the official config.py (plus simsr's own for what config.py cannot express), so a
/// file written by scripts/torch_to_simsr.py reads back here.
///
///     auto cfg = nn::NetworkConfig::official();   // or ::paper()
///     cfg.up_k = 20;                              // the paper's Table 3 value
///     cfg.feature_embedding = false;              // the w/o-FE ablation
///     std::string text = cfg.to_json().dump();

#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "../core/error.hpp"
#include "../core/types.hpp"

namespace simsr::nn {

/// How the upsampling weights w_ij (Eq. 1, 3) are produced.
enum class UpsamplingKind {
  mlp,   ///< the coordinate-based network f_θ(u_ij) of §3.2 (official and paper)
  table  ///< w/o CU: one free logit per (HR vertex, neighbour), not a function of coordinates
};

/// What the residual composition (NetworkConfig::residual) adds the network's output to.
enum class ResidualBase {
  embedded,     ///< the Embedded (barycentric) interpolation of the LR displacements, fixed by the rest shapes
  local_linear  ///< simsr: interp::LocalLinear fitted on the training frames (each HR vertex a 3×3-block
                ///< linear map of its upsampling neighbours' displacements); the network learns what it misses
};

/// The latent regularizer of the loss (Eq. 7's β·L_reg).
enum class LatentRegularizer {
  mean_abs,     ///< official model.py: w_zreg·mean|z| over z = [h⁰, h¹, h²]
  mean_square,  ///< the variant the reference's comments name: w_zreg·mean z²
  ramped_norm   ///< paper Eq. 6: β·Σ_s Σ_i ‖h^s_i‖₂, β ramped from zreg_start to zreg_end
};

struct NetworkConfig {
  std::string profile = "official";
  // --- feature encoding (§3.1) -----------------------------------------------------------------
  Index pos_feat_dim = 32;                 ///< PE channels; h⁰ = [Δx (3), PE]
  std::vector<Index> emb_feat_dims{35, 64, 128};  ///< D₀ = 3 + pos_feat_dim, D₁, D₂ (Table 3)
  bool feature_embedding = true;           ///< false: w/o FE (z = h⁰ straight to upsampling)
  Index knn = 5;                           ///< k of both EdgeConv graphs
  bool edge_batch_norm = true;             ///< official: 2-layer edge MLP with BatchNorm; paper: 1 linear
  bool fc_out_batch_norm = true;           ///< BatchNorm inside each block's fc_out (official)
  double dropout = 0.0;                    ///< after each block (official config: 0)
  // --- upsampling (§3.2) -------------------------------------------------------------------------
  Index up_k = 10;                         ///< interpolation neighbours (config.py 10, Table 3: 20)
  UpsamplingKind upsampling = UpsamplingKind::mlp;
  std::vector<Index> up_hidden{128, 128, 128, 128, 128, 128, 128, 128};  ///< hidden widths of f_θ
  bool up_batch_norm = true;               ///< official: Linear (no bias) → BatchNorm → sin per layer
  double up_w0_initial = 1.0;              ///< ω₀ of f_θ's first sine (paper: 30)
  double up_w0 = 1.0;                      ///< ω₀ of its later sines
  bool up_siren_init = false;              ///< SIREN init of f_θ (paper) instead of PyTorch's default
  // --- surface reconstruction (§3.3) -------------------------------------------------------------
  std::vector<Index> decoder_dims{227, 256, 128, 64, 32, 16, 3};  ///< SIREN widths, in → … → 3
  bool decoder_dead_layer = true;          ///< official: a sine layer dims[-2]→dims[-1] built, never used
  double w0_initial = 30.0, w0 = 1.0;
  double leaky_relu_slope = 0.2;
  double batchnorm_eps = 1e-5, batchnorm_momentum = 0.1;
  /// Δx^H = base(Δx^L) + network output: the network learns what the base misses.
  bool residual = false;
  /// The base of the residual composition. local_linear is fitted by interp::Learned::train on the
  /// training frames before the first step, and travels in the model file as a 3M×3N matrix.
  ResidualBase residual_base = ResidualBase::embedded;
  Index residual_base_k = 20;              ///< local_linear: upsampling neighbours per HR vertex
  // --- data normalization (official dataset.py) ---------------------------------------------------
  double norm_mean = 0.5 * (0.04998 - 0.05092);
  double norm_std = 0.5 * (0.04998 + 0.05092);
  /// simsr: displacements (the network's inputs and targets) are multiplied by this after the
  /// official normalization, predictions divided by it; rest positions keep (x − μ)/σ. 1 is the
  /// official code. Why: σ normalizes *positions* of a 10 cm bunny; a face's displacements of a few
  /// mm, and the millimetre residual the network learns over Embedded, are then 1e-2…1e-3 in network
  /// units, where Adam's fixed step size (lr) dwarfs the targets. NetworkRecipe picks it from the
  /// training frames (the RMS of the normalized HR displacement → 1).
  double displacement_scale = 1.0;
  // --- training ------------------------------------------------------------------------------------
  double lr = 2e-4;
  Index batch_size = 32;
  Index epochs = 200;
  double w_recon = 10.0;
  bool recon_divide_by_batch = true;       ///< official: L1Loss(mean)/B (its quirk, kept)
  double w_fn = 1e-3;                      ///< α of Eq. 7
  /// false (official): every term a mean over its entries; true (paper Eq. 4–6): sums over the
  /// HR vertices, faces and LR points of an item, averaged over the batch items.
  bool sum_reductions = false;
  LatentRegularizer zreg = LatentRegularizer::mean_abs;
  double w_zreg = 2.0;                     ///< official weight; ramped_norm uses zreg_start→zreg_end
  double zreg_start = 0.001, zreg_end = 20.0;
  Index zreg_ramp_steps = 0;               ///< 0: ramp over the whole run
  /// simsr, beyond the paper (§6.1's future work; nn/contact_loss.hpp): the weight of the contact
  /// term that keeps two patches of the HR surface (the lips) from passing through each other
  /// (0: off, the official loss). Its patches come with the training data (Trainer::set_contact).
  double w_contact = 0.0;
  double contact_radius = 0.0;             ///< mesh units: candidate pairs closer than this at rest (> 0 when w_contact > 0)
  double contact_margin = 0.0;             ///< mesh units: the clearance asked for (at most half a pair's rest distance)

  /// The public PyTorch implementation's network (706,871 parameters at these defaults).
  static NetworkConfig official() { return NetworkConfig{}; }

  /// A literal reading of §3 and Table 3: single-linear EdgeConv, no BatchNorm, SIREN f_θ
  /// 7→64→64→1 (ω₀ = 30) over 20 neighbours, SIREN decoder 227→512→512→448→3, L1 + 0.001·L_fn +
  /// β·Σ‖h‖₂ with β ramped 0.001→20, Adam 1e-4.
  static NetworkConfig paper() {
    NetworkConfig c;
    c.profile = "paper";
    c.edge_batch_norm = false;
    c.fc_out_batch_norm = false;
    c.up_k = 20;
    c.up_hidden = {64, 64};
    c.up_batch_norm = false;
    c.up_w0_initial = 30.0;
    c.up_w0 = 1.0;
    c.up_siren_init = true;
    c.decoder_dims = {227, 512, 512, 448, 3};
    c.decoder_dead_layer = false;
    c.lr = 1e-4;
    c.w_recon = 1.0;
    c.recon_divide_by_batch = false;
    c.sum_reductions = true;
    c.zreg = LatentRegularizer::ramped_norm;
    return c;
  }

  /// The preset named `name` ("official" or "paper"); ArgumentError otherwise.
  static NetworkConfig preset(const std::string& name) {
    if (name == "official") return official();
    if (name == "paper") return paper();
    throw ArgumentError("nn::NetworkConfig: unknown profile '" + name + "' (official, paper)");
  }

  /// The w/o-FE ablation: z = h⁰ goes straight to the upsampling, so the decoder's input
  /// narrows to D₀ (the one place that knows both fields must change together).
  void disable_feature_embedding() {
    feature_embedding = false;
    if (!decoder_dims.empty()) decoder_dims.front() = latent_dim();
  }

  /// Mesh units per network unit of displacement: σ / displacement_scale.
  double displacement_unit() const { return norm_std / displacement_scale; }

  /// Width of the LR code z: D₀ + D₁ + … (or D₀ without feature embedding).
  Index latent_dim() const {
    if (!feature_embedding) return emb_feat_dims.at(0);
    Index d = 0;
    for (Index x : emb_feat_dims) d += x;
    return d;
  }

  /// validate()'s upper bounds: any layer width, entries of a width list, knn and upK.
  static constexpr Index max_width = 8192, max_layers = 64, max_neighbors = 1024;

  /// ArgumentError naming the first inconsistent or out-of-bounds field.
  void validate() const {
    auto fail = [](const std::string& m) { throw ArgumentError("nn::NetworkConfig: " + m); };
    // Upper bounds first (a model file's config is untrusted input: a few bytes of JSON must not
    // ask for a network of hundreds of GB), far above any published network (widths ≤ 512).
    auto at_most = [&](const char* field, Index value, Index bound) {
      if (value > bound) fail(std::string(field) + " = " + std::to_string(value) + " exceeds the sane bound " + std::to_string(bound));
    };
    auto widths_at_most = [&](const char* field, const std::vector<Index>& v) {
      at_most((std::string(field) + " (number of entries)").c_str(), Index(v.size()), max_layers);
      for (Index d : v) at_most(field, d, max_width);
    };
    at_most("pos_feat_dim", pos_feat_dim, max_width);
    widths_at_most("emb_feat_dims", emb_feat_dims);
    widths_at_most("up_hidden", up_hidden);
    widths_at_most("decoder_dims", decoder_dims);
    at_most("knn", knn, max_neighbors);
    at_most("upK", up_k, max_neighbors);
    at_most("batch_size", batch_size, Index(1) << 20);
    at_most("n_epochs", epochs, Index(1) << 24);
    at_most("zreg_ramp_steps", zreg_ramp_steps, Index(1) << 40);
    for (double v : {w0_initial, w0, up_w0_initial, up_w0, leaky_relu_slope, batchnorm_eps, batchnorm_momentum, lr, w_recon, w_fn, w_zreg,
                     zreg_start, zreg_end, norm_mean, norm_std, dropout, displacement_scale, w_contact, contact_radius, contact_margin})
      if (!std::isfinite(v)) fail("every real-valued field must be finite");
    if (!(batchnorm_eps > 0) || !(batchnorm_momentum >= 0 && batchnorm_momentum <= 1)) fail("batchnorm eps must be > 0 and momentum in [0, 1]");
    if (pos_feat_dim < 2 || pos_feat_dim % 2) fail("pos_feat_dim must be even and >= 2");
    if (emb_feat_dims.empty() || emb_feat_dims[0] != 3 + pos_feat_dim)
      fail("emb_feat_dims[0] must be 3 + pos_feat_dim = " + std::to_string(3 + pos_feat_dim));
    if (feature_embedding && emb_feat_dims.size() < 2) fail("feature embedding needs at least one block (emb_feat_dims of size >= 2)");
    for (Index d : emb_feat_dims)
      if (d < 1) fail("emb_feat_dims entries must be >= 1");
    if (knn < 1) fail("knn must be >= 1");
    if (up_k < 1) fail("upK must be >= 1");
    for (Index d : up_hidden)
      if (d < 1) fail("up_hidden entries must be >= 1");
    if (decoder_dims.size() < 2 || decoder_dims.front() != latent_dim() || decoder_dims.back() != 3)
      fail("decoder_dims must run from the latent width " + std::to_string(latent_dim()) + " to 3");
    for (Index d : decoder_dims)
      if (d < 1) fail("decoder_dims entries must be >= 1");
    if (!(w0_initial > 0) || !(w0 > 0) || !(up_w0_initial > 0) || !(up_w0 > 0)) fail("every ω₀ must be > 0");
    if (!(dropout >= 0 && dropout < 1)) fail("dropout must be in [0, 1)");
    if (!(norm_std > 0) || !std::isfinite(norm_mean)) fail("norm_std must be > 0 and norm_mean finite");
    if (!(displacement_scale > 0)) fail("displacement_scale must be > 0");
    if (!(lr > 0)) fail("lr must be > 0");
    if (batch_size < 1) fail("batch_size must be >= 1");
    if (epochs < 0) fail("epochs must be >= 0");
    if (!(w_recon >= 0) || !(w_fn >= 0) || !(w_zreg >= 0) || !(zreg_start >= 0) || !(zreg_end >= 0)) fail("loss weights must be >= 0");
    if (zreg_ramp_steps < 0) fail("zreg_ramp_steps must be >= 0");
    if (residual_base_k < 1 || residual_base_k > max_neighbors) fail("residual_base_k must be in [1, " + std::to_string(max_neighbors) + "]");
    if (!(w_contact >= 0) || !(contact_radius >= 0) || !(contact_margin >= 0)) fail("w_contact, contact_radius and contact_margin must be >= 0");
    if (w_contact > 0 && !(contact_radius > 0)) fail("w_contact > 0 needs contact_radius > 0 (the candidate pairs' distance at rest)");
  }

  /// Calls f(key, field) for every field stored under one JSON key (config.py's names where it
  /// has one): the single list to_json and from_json share, so a new field is one line here.
  /// up_hidden and decoder_dims are listed too; from_json also accepts config.py's shorthands.
  template <class Self, class F>
  static void each_field(Self& c, F&& f) {
    f("profile", c.profile);
    f("pos_feat_dim", c.pos_feat_dim);
    f("emb_feat_dims", c.emb_feat_dims);
    f("feature_embedding", c.feature_embedding);
    f("knn", c.knn);
    f("edge_batch_norm", c.edge_batch_norm);
    f("fc_out_batch_norm", c.fc_out_batch_norm);
    f("dropout", c.dropout);
    f("upK", c.up_k);
    f("upsampling", c.upsampling);
    f("up_hidden", c.up_hidden);
    f("up_batch_norm", c.up_batch_norm);
    f("up_w0_initial", c.up_w0_initial);
    f("up_w0", c.up_w0);
    f("up_siren_init", c.up_siren_init);
    f("decoder_dims", c.decoder_dims);
    f("decoder_dead_layer", c.decoder_dead_layer);
    f("w0_initial", c.w0_initial);
    f("w0", c.w0);
    f("leaky_relu_slope", c.leaky_relu_slope);
    f("batchnorm_eps", c.batchnorm_eps);
    f("batchnorm_momentum", c.batchnorm_momentum);
    f("residual", c.residual);
    f("residual_base", c.residual_base);
    f("residual_base_k", c.residual_base_k);
    f("norm_mean", c.norm_mean);
    f("norm_std", c.norm_std);
    f("displacement_scale", c.displacement_scale);
    f("lr", c.lr);
    f("batch_size", c.batch_size);
    f("n_epochs", c.epochs);
    f("w_recon", c.w_recon);
    f("recon_divide_by_batch", c.recon_divide_by_batch);
    f("w_fn", c.w_fn);
    f("sum_reductions", c.sum_reductions);
    f("zreg", c.zreg);
    f("w_zreg", c.w_zreg);
    f("zreg_start", c.zreg_start);
    f("zreg_end", c.zreg_end);
    f("zreg_ramp_steps", c.zreg_ramp_steps);
    f("w_contact", c.w_contact);
    f("contact_radius", c.contact_radius);
    f("contact_margin", c.contact_margin);
  }

  nlohmann::json to_json() const {
    nlohmann::json j;
    each_field(*this, [&](const char* key, const auto& field) {
      if constexpr (std::is_enum_v<std::remove_cvref_t<decltype(field)>>)
        j[key] = enum_name(field);
      else
        j[key] = field;
    });
    // config.py's shorthands, for readers of the official layout
    j["w_up_feat_dim"] = up_hidden.empty() ? Index(0) : up_hidden.front();
    j["n_upscale_layers"] = Index(up_hidden.size());
    j["decoder_dim"] = decoder_dims.size() > 1 ? decoder_dims[1] : Index(0);
    return j;
  }

  /// Reads what to_json writes, or a config of scripts/torch_to_simsr.py (official config.py
  /// keys: the official defaults fill what it lacks; `w_up_feat_dim` × `n_upscale_layers` gives
  /// up_hidden, `decoder_dim` gives the halving SIREN widths when `decoder_dims` is absent).
  /// Unknown keys are ignored; a key of the wrong type or an unknown enum name is an
  /// ArgumentError naming it.
  static NetworkConfig from_json(const nlohmann::json& j) {
    if (!j.is_object()) throw ArgumentError("nn::NetworkConfig: the config is not a JSON object");
    if (j.contains("profile") && !j.at("profile").is_string()) throw ArgumentError("nn::NetworkConfig: key 'profile' must be a string");
    NetworkConfig c = preset(j.value("profile", std::string("official")));
    auto get = [&](const char* key, auto& field) {
      if (!j.contains(key)) return;
      try {
        using T = std::remove_cvref_t<decltype(field)>;
        if constexpr (std::is_enum_v<T>)
          field = parse_enum<T>(key, j.at(key).get<std::string>());
        else
          j.at(key).get_to(field);
      } catch (const nlohmann::json::exception& e) {
        throw ArgumentError(std::string("nn::NetworkConfig: key '") + key + "': " + e.what());
      }
    };
    each_field(c, get);
    if (!j.contains("up_hidden") && (j.contains("w_up_feat_dim") || j.contains("n_upscale_layers"))) {
      Index width = c.up_hidden.empty() ? 128 : c.up_hidden.front(), layers = Index(c.up_hidden.size());
      get("w_up_feat_dim", width);
      get("n_upscale_layers", layers);
      if (layers < 0 || layers > max_layers)
        throw ArgumentError("nn::NetworkConfig: n_upscale_layers = " + std::to_string(layers) + " is outside [0, " + std::to_string(max_layers) + "]");
      c.up_hidden.assign(std::size_t(layers), width);
    }
    if (!j.contains("decoder_dims") && j.contains("decoder_dim")) {
      Index h = 0;
      get("decoder_dim", h);
      c.decoder_dims = {c.latent_dim(), h, h / 2, h / 4, h / 8, h / 16, 3};
    }
    c.validate();
    return c;
  }

  /// The preset `preset` with the fields given in `fields` (keys of to_json), strictly: where
  /// from_json (a reader of other tools' files) ignores an unknown key and lets `decoder_dims` or
  /// `up_hidden` override config.py's shorthands, this refuses both — an unknown key, or a field
  /// that does not read back as given — with an ArgumentError naming it. For configs a user writes
  /// field by field (the Python module's `simsr.Network(knn=3, ...)`).
  static NetworkConfig with_fields(const std::string& preset_name, const nlohmann::json& fields) {
    if (!fields.is_object()) throw ArgumentError("nn::NetworkConfig: the fields are not a JSON object");
    nlohmann::json j = preset(preset_name).to_json();
    for (const auto& [key, value] : fields.items()) {
      if (key == "profile") throw ArgumentError("nn::NetworkConfig: 'profile' is the preset, not a field");
      if (!j.contains(key)) throw ArgumentError("nn::NetworkConfig: unknown field '" + key + "'");
      j[key] = value;
    }
    j["profile"] = preset_name;
    NetworkConfig c = from_json(j);
    const nlohmann::json read = c.to_json();
    for (const auto& [key, value] : fields.items())
      if (read.at(key) != value)
        throw ArgumentError("nn::NetworkConfig: field '" + key + "' = " + value.dump() + " does not hold (the config reads " + read.at(key).dump() +
                            "): set the field it abbreviates (decoder_dims, up_hidden) instead");
    return c;
  }

 private:
  static constexpr std::pair<UpsamplingKind, const char*> upsampling_names[] = {{UpsamplingKind::mlp, "mlp"}, {UpsamplingKind::table, "table"}};
  static constexpr std::pair<LatentRegularizer, const char*> zreg_names[] = {
      {LatentRegularizer::mean_abs, "mean_abs"}, {LatentRegularizer::mean_square, "mean_square"}, {LatentRegularizer::ramped_norm, "ramped_norm"}};
  static constexpr std::pair<ResidualBase, const char*> residual_base_names[] = {{ResidualBase::embedded, "embedded"},
                                                                                {ResidualBase::local_linear, "local_linear"}};
  template <class E>
  static constexpr const auto& names_of() {
    if constexpr (std::is_same_v<E, UpsamplingKind>)
      return upsampling_names;
    else if constexpr (std::is_same_v<E, ResidualBase>)
      return residual_base_names;
    else
      return zreg_names;
  }
  template <class E>
  static const char* enum_name(E e) {
    for (const auto& [v, n] : names_of<E>())
      if (v == e) return n;
    throw ArgumentError("nn::NetworkConfig: unnamed enum value");
  }
  template <class E>
  static E parse_enum(const char* key, const std::string& s) {
    std::string known;
    for (const auto& [v, n] : names_of<E>()) {
      if (s == n) return v;
      known += (known.empty() ? "" : ", ") + std::string(n);
    }
    throw ArgumentError(std::string("nn::NetworkConfig: ") + key + " '" + s + "' (" + known + ")");
  }
};

}  // namespace simsr::nn
