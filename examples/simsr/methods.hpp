#pragma once
// The interpolation methods the tool knows, behind one variant: each command builds one by name
// and calls fit / train / apply through std::visit.
#include <simsr/eval/error_statistics.hpp>
#include <simsr/interp/interp.hpp>
#include <simsr/io/npz.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <variant>
#include <vector>

namespace simsr::cli {

using AnyMethod = std::variant<interp::Embedded<double>, interp::IDW<double>, interp::RBF<double>, interp::MLS<double>,
                               interp::Ridge<double>>;

/// Method parameters shared by `upsample` and `baselines`.
struct MethodArgs {
  Index k = 20;
  double power = 2, sigma = 0;
  int degree = -1;
  std::string mls_basis = "paper", rbf_distance = "geodesic";

  void add_options(CLI::App* cmd) {
    cmd->add_option("--k", k, "neighbours per HR vertex (idw, mls; paper: 20)")->check(CLI::PositiveNumber);
    cmd->add_option("--power", power, "idw: power p of 1/d^p");
    cmd->add_option("--sigma", sigma, "rbf/mls: Gaussian width (0: from the data)");
    cmd->add_option("--degree", degree, "rbf: polynomial tail degree (-1 none, 0, 1)");
    cmd->add_option("--mls-basis", mls_basis, "mls: paper (Eq. 12-16, per coordinate, degree 2) or linear (3-D linear)");
    cmd->add_option("--rbf-distance", rbf_distance, "rbf: geodesic (HR-surface distances between mapped vertices, consistent), lr-mesh (the literal, inconsistent reading) or euclidean");
  }
};

inline const std::vector<std::string>& method_names() {
  static const std::vector<std::string> names{"embedded", "idw", "rbf", "mls", "ridge"};
  return names;
}

inline AnyMethod make_method(const std::string& name, const MethodArgs& a) {
  if (name == "embedded") return interp::Embedded<double>{};
  if (name == "idw") {
    interp::IDWOptions o;
    o.k = a.k;
    o.power = a.power;
    return interp::IDW<double>(o);
  }
  if (name == "rbf") {
    interp::RBFOptions o;
    o.sigma = a.sigma;
    o.degree = a.degree;
    if (a.rbf_distance == "euclidean")
      o.distance = interp::RbfDistance::euclidean;
    else if (a.rbf_distance == "lr-mesh")
      o.distance = interp::RbfDistance::lr_mesh_geodesic;
    else if (a.rbf_distance != "geodesic")
      throw ArgumentError("--rbf-distance: expected geodesic, lr-mesh or euclidean, got '" + a.rbf_distance + "'");
    return interp::RBF<double>(o);
  }
  if (name == "mls") {
    interp::MLSOptions o;
    o.k = a.k;
    o.sigma = a.sigma;
    if (a.mls_basis == "linear")
      o.basis = interp::MlsBasis::linear_3d;
    else if (a.mls_basis != "paper")
      throw ArgumentError("--mls-basis: expected paper or linear, got '" + a.mls_basis + "'");
    return interp::MLS<double>(o);
  }
  if (name == "ridge") return interp::Ridge<double>{};
  throw ArgumentError("unknown method '" + name + "' (known: embedded, idw, rbf, mls, ridge)");
}

/// Whether the method reads the §3.2 neighbourhoods.
inline bool needs_neighborhoods(const AnyMethod& m) {
  return std::holds_alternative<interp::IDW<double>>(m) || std::holds_alternative<interp::RBF<double>>(m) ||
         std::holds_alternative<interp::MLS<double>>(m);
}

/// Fits a method on the rest shapes; ridge also trains on `train_lr`/`train_hr` (F×N×3, F×M×3
/// displacements flattened), which other methods ignore.
inline void fit_method(AnyMethod& method, interp::UpsamplingProblem<double>& problem, const std::vector<double>& train_lr,
                       const std::vector<double>& train_hr, Index train_frames) {
  std::visit(
      [&](auto& m) {
        if constexpr (requires { m.fit(exec::omp, problem); })
          m.fit(exec::omp, problem);
        else
          m.fit(problem);
        if constexpr (requires { m.train(exec::omp, train_lr, train_hr, train_frames); }) {
          if (train_frames == 0) throw ArgumentError("ridge needs training frames (--train)");
          m.train(exec::omp, train_lr, train_hr, train_frames);
        }
      },
      method);
}

inline void apply_method(const AnyMethod& method, const Points<double>& lr, Points<double>& hr) {
  std::visit([&](const auto& m) { m.apply(exec::omp, lr, hr); }, method);
}

/// Frames array `name` of an .npz as F×V×3; ShapeError naming file and array otherwise.
inline io::NpyArray read_frames(io::NpzReader& z, const std::string& file, const std::string& name, Index vertices) {
  if (!z.contains(name)) throw ArgumentError(file + ": no array '" + name + "'");
  io::NpyArray a = z.read(name);
  if (a.ndim() != 3 || a.shape[1] != vertices || a.shape[2] != 3) throw ShapeError(file + ": " + name, {-1, vertices, 3}, a.shape);
  return a;
}

/// Displacements of the selected frames from a rest shape, flattened (frame, vertex, xyz).
inline std::vector<double> frame_displacements(const io::NpyArray& frames, const std::vector<Index>& selected, const Points<double>& rest) {
  std::vector<double> out;
  out.reserve(selected.size() * std::size_t(rest.size()));
  for (Index f : selected) {
    const Points<double> d = frames.frame_points<double>(f) - rest;
    out.insert(out.end(), d.data(), d.data() + d.size());
  }
  return out;
}

/// Table-1 statistics as the tool prints them (the same keys in every command's JSON).
inline nlohmann::ordered_json statistics_json(const eval::ErrorStatistics& s) {
  return {{"mean", s.mean}, {"median", s.median}, {"std", s.std}, {"max", s.max}, {"min", s.min}};
}

}  // namespace simsr::cli
