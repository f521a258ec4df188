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
  /// Δx^H = Embedded(Δx^L) + network output: the network learns what the embedding misses.
  bool residual = false;
  // --- data normalization (official dataset.py) ---------------------------------------------------
  double norm_mean = 0.5 * (0.04998 - 0.05092);
  double norm_std = 0.5 * (0.04998 + 0.05092);
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

  /// Width of the LR code z: D₀ + D₁ + … (or D₀ without feature embedding).
  Index latent_dim() const {
    if (!feature_embedding) return emb_feat_dims.at(0);
    Index d = 0;
    for (Index x : emb_feat_dims) d += x;
    return d;
  }

  /// ArgumentError naming the first inconsistent field.
  void validate() const {
    auto fail = [](const std::string& m) { throw ArgumentError("nn::NetworkConfig: " + m); };
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
    if (!(lr > 0)) fail("lr must be > 0");
    if (batch_size < 1) fail("batch_size must be >= 1");
    if (epochs < 0) fail("epochs must be >= 0");
    if (!(w_recon >= 0) || !(w_fn >= 0) || !(w_zreg >= 0) || !(zreg_start >= 0) || !(zreg_end >= 0)) fail("loss weights must be >= 0");
    if (zreg_ramp_steps < 0) fail("zreg_ramp_steps must be >= 0");
  }

  nlohmann::json to_json() const {
    nlohmann::json j;
    j["profile"] = profile;
    j["pos_feat_dim"] = pos_feat_dim;
    j["emb_feat_dims"] = emb_feat_dims;
    j["feature_embedding"] = feature_embedding;
    j["knn"] = knn;
    j["edge_batch_norm"] = edge_batch_norm;
    j["fc_out_batch_norm"] = fc_out_batch_norm;
    j["dropout"] = dropout;
    j["upK"] = up_k;
    j["upsampling"] = upsampling == UpsamplingKind::mlp ? "mlp" : "table";
    j["up_hidden"] = up_hidden;
    j["w_up_feat_dim"] = up_hidden.empty() ? Index(0) : up_hidden.front();
    j["n_upscale_layers"] = Index(up_hidden.size());
    j["up_batch_norm"] = up_batch_norm;
    j["up_w0_initial"] = up_w0_initial;
    j["up_w0"] = up_w0;
    j["up_siren_init"] = up_siren_init;
    j["decoder_dims"] = decoder_dims;
    j["decoder_dim"] = decoder_dims.size() > 1 ? decoder_dims[1] : Index(0);
    j["decoder_dead_layer"] = decoder_dead_layer;
    j["w0_initial"] = w0_initial;
    j["w0"] = w0;
    j["leaky_relu_slope"] = leaky_relu_slope;
    j["batchnorm_eps"] = batchnorm_eps;
    j["batchnorm_momentum"] = batchnorm_momentum;
    j["residual"] = residual;
    j["norm_mean"] = norm_mean;
    j["norm_std"] = norm_std;
    j["lr"] = lr;
    j["batch_size"] = batch_size;
    j["n_epochs"] = epochs;
    j["w_recon"] = w_recon;
    j["recon_divide_by_batch"] = recon_divide_by_batch;
    j["w_fn"] = w_fn;
    j["sum_reductions"] = sum_reductions;
    j["zreg"] = zreg == LatentRegularizer::mean_abs ? "mean_abs" : zreg == LatentRegularizer::mean_square ? "mean_square" : "ramped_norm";
    j["w_zreg"] = w_zreg;
    j["zreg_start"] = zreg_start;
    j["zreg_end"] = zreg_end;
    j["zreg_ramp_steps"] = zreg_ramp_steps;
    return j;
  }

  /// Reads what to_json writes, or a config of scripts/torch_to_simsr.py (official config.py
  /// keys: the official defaults fill what it lacks; `w_up_feat_dim` × `n_upscale_layers` gives
  /// up_hidden, `decoder_dim` gives the halving SIREN widths when `decoder_dims` is absent).
  /// Unknown keys are ignored; a key of the wrong type is an ArgumentError naming it.
  static NetworkConfig from_json(const nlohmann::json& j) {
    if (!j.is_object()) throw ArgumentError("nn::NetworkConfig: the config is not a JSON object");
    NetworkConfig c = preset(j.value("profile", std::string("official")));
    auto get = [&](const char* key, auto& field) {
      if (!j.contains(key)) return;
      try {
        j.at(key).get_to(field);
      } catch (const nlohmann::json::exception& e) {
        throw ArgumentError(std::string("nn::NetworkConfig: key '") + key + "': " + e.what());
      }
    };
    auto get_enum = [&](const char* key, auto& field, auto&& parse) {
      if (!j.contains(key)) return;
      std::string s;
      get(key, s);
      field = parse(s);
    };
    get("pos_feat_dim", c.pos_feat_dim);
    get("emb_feat_dims", c.emb_feat_dims);
    get("feature_embedding", c.feature_embedding);
    get("knn", c.knn);
    get("edge_batch_norm", c.edge_batch_norm);
    get("fc_out_batch_norm", c.fc_out_batch_norm);
    get("dropout", c.dropout);
    get("upK", c.up_k);
    get_enum("upsampling", c.upsampling, [](const std::string& s) {
      if (s == "mlp") return UpsamplingKind::mlp;
      if (s == "table") return UpsamplingKind::table;
      throw ArgumentError("nn::NetworkConfig: upsampling '" + s + "' (mlp, table)");
    });
    if (j.contains("up_hidden")) {
      get("up_hidden", c.up_hidden);
    } else if (j.contains("w_up_feat_dim") || j.contains("n_upscale_layers")) {
      Index width = c.up_hidden.empty() ? 128 : c.up_hidden.front(), layers = Index(c.up_hidden.size());
      get("w_up_feat_dim", width);
      get("n_upscale_layers", layers);
      if (layers < 0) throw ArgumentError("nn::NetworkConfig: n_upscale_layers must be >= 0");
      c.up_hidden.assign(std::size_t(layers), width);
    }
    get("up_batch_norm", c.up_batch_norm);
    get("up_w0_initial", c.up_w0_initial);
    get("up_w0", c.up_w0);
    get("up_siren_init", c.up_siren_init);
    if (j.contains("decoder_dims")) {
      get("decoder_dims", c.decoder_dims);
    } else if (j.contains("decoder_dim")) {
      Index h = 0;
      get("decoder_dim", h);
      c.decoder_dims = {c.latent_dim(), h, h / 2, h / 4, h / 8, h / 16, 3};
    }
    get("decoder_dead_layer", c.decoder_dead_layer);
    get("w0_initial", c.w0_initial);
    get("w0", c.w0);
    get("leaky_relu_slope", c.leaky_relu_slope);
    get("batchnorm_eps", c.batchnorm_eps);
    get("batchnorm_momentum", c.batchnorm_momentum);
    get("residual", c.residual);
    get("norm_mean", c.norm_mean);
    get("norm_std", c.norm_std);
    get("lr", c.lr);
    get("batch_size", c.batch_size);
    get("n_epochs", c.epochs);
    get("w_recon", c.w_recon);
    get("recon_divide_by_batch", c.recon_divide_by_batch);
    get("w_fn", c.w_fn);
    get("sum_reductions", c.sum_reductions);
    get_enum("zreg", c.zreg, [](const std::string& s) {
      if (s == "mean_abs") return LatentRegularizer::mean_abs;
      if (s == "mean_square") return LatentRegularizer::mean_square;
      if (s == "ramped_norm") return LatentRegularizer::ramped_norm;
      throw ArgumentError("nn::NetworkConfig: zreg '" + s + "' (mean_abs, mean_square, ramped_norm)");
    });
    get("w_zreg", c.w_zreg);
    get("zreg_start", c.zreg_start);
    get("zreg_end", c.zreg_end);
    get("zreg_ramp_steps", c.zreg_ramp_steps);
    c.validate();
    return c;
  }
};

}  // namespace simsr::nn
