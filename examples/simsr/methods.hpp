#pragma once
// The interpolation methods the tool knows by name: their command-line options. The library's
// interp::with_method (interp/by_name.hpp) builds the named method, so this file is option parsing only.
#include <simsr/eval/error_statistics.hpp>
#include <simsr/interp/by_name.hpp>
#include <simsr/interp/interp.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace simsr::cli {

/// Method parameters shared by `upsample` and `baselines`: the library's interp::MethodParameters
/// with their command-line options.
struct MethodArgs : interp::MethodParameters {
  void add_options(CLI::App* cmd) {
    cmd->add_option("--k", k, "neighbours per HR vertex (idw, mls; paper: 20)")->check(CLI::PositiveNumber);
    cmd->add_option("--power", power, "idw: power p of 1/d^p");
    cmd->add_option("--sigma", sigma, "rbf/mls: Gaussian width (0: from the data)");
    cmd->add_option("--degree", degree, "rbf: polynomial tail degree (-1 none, 0, 1)");
    cmd->add_option("--mls-basis", mls_basis, "mls: paper (Eq. 12-16, per coordinate, degree 2) or linear (3-D linear)");
    cmd->add_option("--rbf-regularization", rbf_regularization, "rbf: lambda added to the kernel matrix's diagonal (0: exact interpolation)");
    cmd->add_option("--rbf-distance", rbf_distance,
                    "rbf: geodesic (HR-surface distances between mapped vertices, consistent), lr-mesh (the literal, inconsistent reading) or euclidean");
  }
  void add_vae_options(CLI::App* cmd) {
    cmd->add_option("--vae-epochs", vae_epochs, "beta_vae: training epochs (default 4, 25-45 s each on the bunny at 2 threads; Adam lr 1e-4, beta 0.01, batch 8)");
    cmd->add_option("--seed", seed, "beta_vae: seed of the initial weights, the shuffling and the noise (default 0)");
  }
};

using interp::with_method;

/// Table-1 statistics as the tool prints them (the same keys in every command's JSON).
inline nlohmann::ordered_json statistics_json(const eval::ErrorStatistics& s) {
  return {{"mean", s.mean}, {"median", s.median}, {"std", s.std}, {"max", s.max}, {"min", s.min}};
}

}  // namespace simsr::cli
