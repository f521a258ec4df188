#pragma once
// `simsr upsample --method embedded|idw|rbf|mls --lr-rest L --hr-rest H --frames IN.npz --out OUT.npz`
// IN holds `lowres` (F×N×3 absolute LR positions); OUT gets `highres` (F×M×3 absolute HR
// positions, the HR rest plus the interpolated displacement). stdout: one JSON line with the
// timings and, when IN also holds `highres` of the right shape (as the bunny's train_frames.npz
// does), the error statistics of the prediction against it.
#include <simsr/eval/error_statistics.hpp>
#include <simsr/interp/interp.hpp>
#include <simsr/io/npz.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cmd_neighbors.hpp"

namespace simsr::cli {

struct UpsampleArgs {
  std::string method, lr, hr, frames, out, neighbors;
  Index k = 20;
  double power = 2, sigma = 0;
  int degree = -1;
  std::string mls_basis = "paper", rbf_distance = "geodesic";
};

/// Frames array `name` of an .npz as F×V×3; ShapeError naming file and array otherwise.
inline io::NpyArray read_frames(io::NpzReader& z, const std::string& file, const std::string& name, Index vertices) {
  if (!z.contains(name)) throw ArgumentError(file + ": no array '" + name + "'");
  io::NpyArray a = z.read(name);
  if (a.ndim() != 3 || a.shape[1] != vertices || a.shape[2] != 3)
    throw ShapeError(file + ": " + name, {-1, vertices, 3}, a.shape);
  return a;
}

template <class Method>
int upsample_with(Method method, const UpsampleArgs& a) {
  using clock = std::chrono::steady_clock;
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  interp::UpsamplingProblem<double> problem{read_lr_rest(a.lr), read_hr_rest(a.hr), std::nullopt};
  if (!a.neighbors.empty()) problem.neighborhoods = neighbors::load_upsampling_neighborhoods(a.neighbors);
  io::NpzReader z(a.frames);
  const io::NpyArray lowres = read_frames(z, a.frames, "lowres", problem.num_lr());
  const Index frames = lowres.num_frames(), m = problem.num_hr();

  const auto t0 = clock::now();
  if constexpr (!std::is_same_v<Method, interp::Embedded<double>>) problem.ensure_neighborhoods(a.k, exec::omp);
  const auto t1 = clock::now();
  if constexpr (requires { method.fit(exec::omp, problem); })
    method.fit(exec::omp, problem);
  else
    method.fit(problem);
  const auto t2 = clock::now();

  std::vector<double> out(static_cast<std::size_t>(frames * m * 3));
  Points<double> lr_disp(problem.num_lr(), 3), hr_disp(m, 3);
  double apply_ms = 0;
  for (Index f = 0; f < frames; ++f) {
    lr_disp = lowres.frame_points<double>(f) - problem.lr.V;
    const auto s = clock::now();
    method.apply(exec::omp, lr_disp, hr_disp);
    apply_ms += ms(clock::now() - s);
    Eigen::Map<Points<double>>(out.data() + f * m * 3, m, 3) = problem.hr.V + hr_disp;
  }
  io::NpzArrays result;
  result["highres"] = io::make_npy<double>({frames, m, 3}, out.data());
  io::write_npz(a.out, result, io::NpzCompression::Deflate);

  nlohmann::ordered_json j;
  j["method"] = a.method;
  j["frames"] = frames;
  j["lr_vertices"] = problem.num_lr();
  j["hr_vertices"] = m;
  j["neighborhoods_ms"] = ms(t1 - t0);
  j["fit_ms"] = ms(t2 - t1);
  j["apply_ms_per_frame"] = frames ? apply_ms / double(frames) : 0.0;
  if (z.contains("highres")) {
    const io::NpyArray truth = read_frames(z, a.frames, "highres", m);
    if (truth.num_frames() != frames) throw ShapeError(a.frames + ": highres frames", {frames, m, 3}, truth.shape);
    eval::ErrorAccumulator acc(problem.hr.V);
    for (Index f = 0; f < frames; ++f)
      acc.add_frame(Eigen::Map<const Points<double>>(out.data() + f * m * 3, m, 3), truth.frame_points<double>(f));
    const auto s = acc.statistics(), r = acc.relative_statistics();
    j["error"] = {{"mean", s.mean}, {"median", s.median}, {"std", s.std}, {"max", s.max}, {"min", s.min}};
    j["relative_error"] = {{"mean", r.mean}, {"median", r.median}, {"std", r.std}, {"max", r.max}, {"min", r.min}};
  }
  std::cout << j.dump() << '\n';
  return 0;
}

inline int upsample(const UpsampleArgs& a) {
  if (a.method == "embedded") return upsample_with(interp::Embedded<double>{}, a);
  if (a.method == "idw") {
    interp::IDWOptions o;
    o.k = a.k;
    o.power = a.power;
    return upsample_with(interp::IDW<double>(o), a);
  }
  if (a.method == "rbf") {
    interp::RBFOptions o;
    o.sigma = a.sigma;
    o.degree = a.degree;
    if (a.rbf_distance == "euclidean")
      o.distance = interp::RbfDistance::euclidean;
    else if (a.rbf_distance != "geodesic")
      throw ArgumentError("--rbf-distance: expected geodesic or euclidean, got '" + a.rbf_distance + "'");
    return upsample_with(interp::RBF<double>(o), a);
  }
  if (a.method == "mls") {
    interp::MLSOptions o;
    o.k = a.k;
    o.sigma = a.sigma;
    if (a.mls_basis == "linear")
      o.basis = interp::MlsBasis::linear_3d;
    else if (a.mls_basis != "paper")
      throw ArgumentError("--mls-basis: expected paper or linear, got '" + a.mls_basis + "'");
    return upsample_with(interp::MLS<double>(o), a);
  }
  throw ArgumentError("--method: expected embedded, idw, rbf or mls, got '" + a.method + "'");
}

inline void add_upsample(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("upsample", "Interpolate LR frames to the HR surface with a baseline (embedded, idw, rbf, mls)");
  auto a = std::make_shared<UpsampleArgs>();
  cmd->add_option("--method", a->method, "embedded | idw | rbf | mls")->required();
  cmd->add_option("--lr-rest", a->lr, "LR rest tet mesh (.msh .node/.ele .mesh, or OBJ with 4 triangles per tet)")->required();
  cmd->add_option("--hr-rest", a->hr, "HR rest surface")->required();
  cmd->add_option("--frames", a->frames, ".npz with lowres (F×N×3 absolute); an optional highres is used for errors")->required();
  cmd->add_option("--out", a->out, "output .npz with highres (F×M×3 absolute)")->required();
  cmd->add_option("--neighbors", a->neighbors, "precomputed neighbourhoods (simsr neighbors); computed when absent");
  cmd->add_option("--k", a->k, "neighbours per HR vertex (idw, mls; paper: 20)")->check(CLI::PositiveNumber);
  cmd->add_option("--power", a->power, "idw: power p of 1/d^p");
  cmd->add_option("--sigma", a->sigma, "rbf/mls: Gaussian width (0: from the data)");
  cmd->add_option("--degree", a->degree, "rbf: polynomial tail degree (-1 none, 0, 1)");
  cmd->add_option("--mls-basis", a->mls_basis, "mls: paper (Eq. 12-16, per coordinate, degree 2) or linear (3-D linear)");
  cmd->add_option("--rbf-distance", a->rbf_distance, "rbf: geodesic (paper) or euclidean");
  cmd->callback([&action, a] { action = [a] { return upsample(*a); }; });
}

}  // namespace simsr::cli
