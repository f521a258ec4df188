#pragma once
// The interpolation methods the tool knows by name. `with_method` builds the named method with
// the command line's parameters and hands it (with its training options, for methods that learn
// from frames) to a generic visitor: the library's fit / train / evaluate code runs unchanged for
// every method, so this file is option parsing only.
#include <simsr/eval/error_statistics.hpp>
#include <simsr/interp/interp.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace simsr::cli {

/// Method parameters shared by `upsample` and `baselines`.
struct MethodArgs {
  Index k = 20;
  double power = 2, sigma = 0;
  int degree = -1;
  std::string mls_basis = "paper", rbf_distance = "geodesic";
  Index vae_epochs = 4;
  std::uint64_t seed = 0;

  void add_options(CLI::App* cmd) {
    cmd->add_option("--k", k, "neighbours per HR vertex (idw, mls; paper: 20)")->check(CLI::PositiveNumber);
    cmd->add_option("--power", power, "idw: power p of 1/d^p");
    cmd->add_option("--sigma", sigma, "rbf/mls: Gaussian width (0: from the data)");
    cmd->add_option("--degree", degree, "rbf: polynomial tail degree (-1 none, 0, 1)");
    cmd->add_option("--mls-basis", mls_basis, "mls: paper (Eq. 12-16, per coordinate, degree 2) or linear (3-D linear)");
    cmd->add_option("--rbf-distance", rbf_distance,
                    "rbf: geodesic (HR-surface distances between mapped vertices, consistent), lr-mesh (the literal, inconsistent reading) or euclidean");
  }
  void add_vae_options(CLI::App* cmd) {
    cmd->add_option("--vae-epochs", vae_epochs, "beta_vae: training epochs (default 4, 25-45 s each on the bunny at 2 threads; Adam lr 1e-4, beta 0.01, batch 8)");
    cmd->add_option("--seed", seed, "beta_vae: seed of the initial weights, the shuffling and the noise (default 0)");
  }
};

/// Builds the method named `name` and calls `visit(method)`, or `visit(method, train_options)`
/// for a method that learns from paired frames. ArgumentError for an unknown name or parameter.
template <class Visit>
void with_method(const std::string& name, const MethodArgs& a, Visit&& visit) {
  if (name == "embedded") {
    interp::Embedded<> m;
    visit(m);
  } else if (name == "idw") {
    interp::IDW<> m(interp::IDWOptions{.k = a.k, .power = a.power});
    visit(m);
  } else if (name == "rbf") {
    interp::RBFOptions o;
    o.sigma = a.sigma;
    o.degree = a.degree;
    if (a.rbf_distance == "euclidean")
      o.distance = interp::RbfDistance::euclidean;
    else if (a.rbf_distance == "lr-mesh")
      o.distance = interp::RbfDistance::lr_mesh_geodesic;
    else if (a.rbf_distance != "geodesic")
      throw ArgumentError("--rbf-distance: expected geodesic, lr-mesh or euclidean, got '" + a.rbf_distance + "'");
    interp::RBF<> m(o);
    visit(m);
  } else if (name == "mls") {
    interp::MLSOptions o;
    o.k = a.k;
    o.sigma = a.sigma;
    if (a.mls_basis == "linear")
      o.basis = interp::MlsBasis::linear_3d;
    else if (a.mls_basis != "paper")
      throw ArgumentError("--mls-basis: expected paper or linear, got '" + a.mls_basis + "'");
    interp::MLS<> m(o);
    visit(m);
  } else if (name == "ridge") {
    interp::Ridge<> m;
    visit(m, interp::RidgeTrainOptions{});
  } else if (name == "beta_vae") {
    if (a.vae_epochs < 0) throw ArgumentError("--vae-epochs must be >= 0 (got " + std::to_string(a.vae_epochs) + ")");
    interp::BetaVaeBaseline<> m;
    visit(m, interp::BetaVaeTrainOptions{.epochs = a.vae_epochs, .seed = a.seed, .progress = true, .on_epoch = {}});
  } else {
    throw ArgumentError("unknown method '" + name + "' (known: embedded, idw, rbf, mls, ridge, beta_vae)");
  }
}

/// Table-1 statistics as the tool prints them (the same keys in every command's JSON).
inline nlohmann::ordered_json statistics_json(const eval::ErrorStatistics& s) {
  return {{"mean", s.mean}, {"median", s.median}, {"std", s.std}, {"max", s.max}, {"min", s.min}};
}

}  // namespace simsr::cli
