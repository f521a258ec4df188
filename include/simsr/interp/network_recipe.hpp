#pragma once
/// \file
/// How a network is trained here, as one value the tools share (`simsr train`, `simsr demo`): the
/// architecture preset, the §5.4 ablation switches and the training schedule, with the defaults
/// measured on this 2-core CPU machine — not the official GPU recipe, which nn::NetworkConfig's
/// presets keep unchanged.
///
/// Why the defaults differ from the official code (batch 32, Adam 2e-4, 200 epochs, w_zreg 2, the
/// network alone): that is days of CPU time. Batches of 8 at 1e-3 and the
/// residual composition over Embedded improve on Embedded within minutes; with displacements at
/// unit RMS (displacement_scale 0), the rate halved every 12 epochs and 60 epochs, the defaults
/// are the measured bunny recipe of `simsr train` (README, "Training on the bunny").
///
///     interp::NetworkRecipe r;  r.epochs = 6;  r.knn = 3;      // an EdgeConv-k ablation
///     interp::Learned<> net(r.config(), r.seed);

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "../core/error.hpp"
#include "../nn/network_config.hpp"

namespace simsr::interp {

struct NetworkRecipe {
  std::string profile = "official";  ///< nn::NetworkConfig preset: official | paper
  Index epochs = -1;                 ///< −1: default_epochs(profile)
  Index batch_size = 8;
  double lr = 1e-3;                  ///< Adam
  Index lr_decay_epochs = 12;        ///< halve the learning rate every that many epochs (0: never)
  double w_recon = -1, w_zreg = -1, w_fn = -1;  ///< −1: the preset's
  bool residual = true;              ///< Δx = base + network
  /// The residual's base: "embedded" (the official geometry's barycentric interpolation) or
  /// "local_linear" (interp::LocalLinear fitted on the training frames; README, "The network on the face").
  std::string residual_base = "embedded";
  Index knn = -1, up_k = -1;         ///< EdgeConv k, interpolation neighbours (−1: the preset's)
  bool without_fe = false, without_cu = false;  ///< §5.4 ablations
  std::uint64_t seed = 0;            ///< initial weights and shuffling
  /// nn::NetworkConfig::displacement_scale: > 0 as given; 0: from the training frames (the RMS of
  /// their normalized HR displacement becomes 1; config(frames)).
  double displacement_scale = 0.0;
  /// The lip-contact term (nn/contact_loss.hpp; issue #12 item 7): weight (0: off), the candidate
  /// pairs' rest distance (also how far behind a triangle a vertex still counts as through it) and the
  /// clearance, in mesh units (the face's defaults: 5 mm, 0.2 mm; see the README on the radius).
  double w_contact = 0.0;
  double contact_radius = 0.005, contact_margin = 2e-4;

  /// Epochs when `epochs` < 0: 60 for the official profile (with the defaults above the residual
  /// reaches 0.22× Embedded's held-out error on the bunny, the network alone 0.49×, in 17–20
  /// minutes on 2 cores; README, "Training on the bunny"); 10 for the paper profile.
  static Index default_epochs(const std::string& profile) { return profile == "paper" ? 10 : 60; }
  Index resolved_epochs() const { return epochs >= 0 ? epochs : default_epochs(profile); }

  /// The network configuration (validated: ArgumentError naming the bad field).
  nn::NetworkConfig config() const {
    nn::NetworkConfig cfg = nn::NetworkConfig::preset(profile);
    if (knn > 0) cfg.knn = knn;
    if (up_k > 0) cfg.up_k = up_k;
    cfg.residual = residual;
    if (residual_base == "local_linear")
      cfg.residual_base = nn::ResidualBase::local_linear;
    else if (residual_base != "embedded")
      throw ArgumentError("network recipe: residual base must be embedded or local_linear (got '" + residual_base + "')");
    if (without_fe) cfg.disable_feature_embedding();
    if (without_cu) cfg.upsampling = nn::UpsamplingKind::table;
    cfg.epochs = resolved_epochs();
    if (batch_size < 1) throw ArgumentError("network recipe: batch size must be >= 1 (got " + std::to_string(batch_size) + ")");
    cfg.batch_size = batch_size;
    cfg.lr = lr;
    if (w_recon >= 0) cfg.w_recon = w_recon;
    if (w_zreg >= 0) cfg.w_zreg = w_zreg;
    if (w_fn >= 0) cfg.w_fn = w_fn;
    if (lr_decay_epochs < 0) throw ArgumentError("network recipe: lr decay epochs must be >= 0 (got " + std::to_string(lr_decay_epochs) + ")");
    cfg.w_contact = w_contact;  // validate() below refuses a negative or non-finite one
    if (w_contact > 0) {  // off, the geometry stays out of the config (and of older model files' comparisons)
      cfg.contact_radius = contact_radius;
      cfg.contact_margin = contact_margin;
    }
    if (displacement_scale > 0) cfg.displacement_scale = displacement_scale;
    else if (displacement_scale < 0 || !std::isfinite(displacement_scale)) throw ArgumentError("network recipe: displacement scale must be >= 0 (0: from the data)");
    cfg.validate();
    return cfg;
  }

  /// config(), with displacement_scale 0 resolved from the training frames (displacements, as
  /// interp::Learned::train takes them): 1 / RMS of every HR coordinate divided by σ.
  template <class Frames>
  nn::NetworkConfig config(const Frames& train_displacements) const {
    nn::NetworkConfig cfg = config();
    if (displacement_scale == 0) {
      const double rms = std::sqrt(train_displacements.highres.squaredNorm() / double(std::max<Index>(1, train_displacements.highres.size()))) / cfg.norm_std;
      if (!(rms > 0) || !std::isfinite(rms)) throw ArgumentError("network recipe: the training frames' HR displacements are all zero (or not finite): no displacement scale");
      cfg.displacement_scale = 1.0 / rms;
    }
    return cfg;
  }

  /// Every field, for reports and the fingerprints of pipeline stages (the residual base when not
  /// Embedded and the contact fields when the term is on: stages finished before they existed keep
  /// their fingerprints).
  nlohmann::ordered_json to_json() const {
    nlohmann::ordered_json j = {{"profile", profile}, {"epochs", resolved_epochs()}, {"batch_size", batch_size}, {"lr", lr},          {"lr_decay_epochs", lr_decay_epochs},
            {"w_recon", w_recon}, {"w_zreg", w_zreg},            {"w_fn", w_fn},             {"residual", residual}, {"knn", knn},
            {"up_k", up_k},       {"without_fe", without_fe},    {"without_cu", without_cu}, {"seed", seed}, {"displacement_scale", displacement_scale}};
    if (residual_base != "embedded") j["residual_base"] = residual_base;  // absent: the stages of earlier versions keep their fingerprints
    if (w_contact != 0) {
      j["w_contact"] = w_contact;
      j["contact_radius"] = contact_radius;
      j["contact_margin"] = contact_margin;
    }
    return j;
  }
};

}  // namespace simsr::interp
