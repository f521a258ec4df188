#pragma once
/// \file
/// The baselines by name, for tools and pipelines that take the method as a string: `with_method`
/// builds the named method with its parameters and hands it (with its training options, for a
/// method that learns from frames) to a generic visitor, so fit / train / evaluate run unchanged
/// for every method — the string is resolved once, the work stays typed.
///
///     interp::MethodParameters p;  p.k = 20;
///     interp::with_method("mls", p, [&](auto& method, const auto&... train_options) {
///       interp::prepare(exec::omp, method, problem, train, train_options...);   // or without frames
///     });

#include <cstdint>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "beta_vae.hpp"
#include "embedded.hpp"
#include "idw.hpp"
#include "local_linear.hpp"
#include "mls.hpp"
#include "rbf.hpp"
#include "ridge.hpp"

namespace simsr::interp {

/// Every parameter a baseline takes by name (defaults: the paper's).
struct MethodParameters {
  Index k = 20;                           ///< idw, mls, local_linear: neighbours per HR vertex (paper 20)
  double power = 2;                       ///< idw: p of 1/d^p
  double sigma = 0;                       ///< rbf, mls: Gaussian width (0: from the data)
  int degree = -1;                        ///< rbf: polynomial tail degree (-1 none, 0, 1)
  std::string mls_basis = "paper";        ///< mls: paper (Eq. 12–16) or linear (3-D linear)
  std::string rbf_distance = "geodesic";  ///< rbf: geodesic, lr-mesh or euclidean
  double rbf_regularization = 0;          ///< rbf: λ added to Φ_LL's diagonal (coincident LR vertices need some)
  Index vae_epochs = 4;                   ///< beta_vae: training epochs
  std::uint64_t seed = 0;                 ///< beta_vae: initial weights, shuffling and noise
  bool progress = true;                   ///< beta_vae: progress line on stderr
};

/// The names `with_method` knows, the cheap ones first (beta_vae trains for minutes).
inline const std::vector<std::string>& method_names() {
  static const std::vector<std::string> names{"embedded", "idw", "rbf", "mls", "ridge", "local_linear", "beta_vae"};
  return names;
}

/// Builds the method named `name` and calls `visit(method)`, or `visit(method, train_options)`
/// for a method that learns from paired frames. ArgumentError for an unknown name or parameter.
template <class Visit>
void with_method(const std::string& name, const MethodParameters& a, Visit&& visit) {
  if (name == "embedded") {
    Embedded<> m;
    visit(m);
  } else if (name == "idw") {
    IDW<> m(IDWOptions{.k = a.k, .power = a.power});
    visit(m);
  } else if (name == "rbf") {
    RBFOptions o;
    o.sigma = a.sigma;
    o.degree = a.degree;
    o.regularization = a.rbf_regularization;
    if (a.rbf_distance == "euclidean")
      o.distance = RbfDistance::euclidean;
    else if (a.rbf_distance == "lr-mesh")
      o.distance = RbfDistance::lr_mesh_geodesic;
    else if (a.rbf_distance != "geodesic")
      throw ArgumentError("rbf distance: expected geodesic, lr-mesh or euclidean, got '" + a.rbf_distance + "'");
    RBF<> m(o);
    visit(m);
  } else if (name == "mls") {
    MLSOptions o;
    o.k = a.k;
    o.sigma = a.sigma;
    if (a.mls_basis == "linear")
      o.basis = MlsBasis::linear_3d;
    else if (a.mls_basis != "paper")
      throw ArgumentError("mls basis: expected paper or linear, got '" + a.mls_basis + "'");
    MLS<> m(o);
    visit(m);
  } else if (name == "ridge") {
    Ridge<> m;
    visit(m, RidgeTrainOptions{});
  } else if (name == "local_linear") {
    LocalLinear<> m(LocalLinearOptions{.k = a.k});
    visit(m, LocalLinearTrainOptions{});
  } else if (name == "beta_vae") {
    if (a.vae_epochs < 0) throw ArgumentError("beta_vae epochs must be >= 0 (got " + std::to_string(a.vae_epochs) + ")");
    BetaVaeBaseline<> m;
    visit(m, BetaVaeTrainOptions{.epochs = a.vae_epochs, .seed = a.seed, .progress = a.progress, .on_epoch = {}});
  } else {
    std::string known;
    for (const auto& n : method_names()) known += (known.empty() ? "" : ", ") + n;
    throw ArgumentError("unknown method '" + name + "' (known: " + known + ")");
  }
}

}  // namespace simsr::interp
