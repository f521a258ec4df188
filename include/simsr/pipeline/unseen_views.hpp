#pragma once
/// \file
/// Fig. 7 of the core paper (§5.3, "unseen forces"): methods applied to LR-only frames of forces
/// the training performances never had (scenario/face/unseen_forces.hpp: a lip corner pulled by a
/// spring, a sphere pushed into the cheek), shown beside each method's prediction of the rest
/// pose. There is no HR truth for these frames; what can be seen and measured is whether a method
/// follows the LR deformation (Embedded is the LR surface itself) and what it adds to it.
///
///     std::vector<pipeline::NamedApply> methods{{"embedded", embedded_apply}, {"network", network_apply}};
///     auto j = pipeline::write_unseen_force_views(data_dir / "unseen", out / "results" / "unseen", problem, methods);
///
/// For each DIR/<sequence>.npz (`lowres` F×N×3), at its rest frame (0: the settled neutral) and its
/// peak frame (the LR mesh farthest from the rest frame on average), OUT/<sequence>/ gets
/// lr_input.vtu (the LR mesh at the peak), <method>.vtu (the method's HR surface at the peak, its
/// per-vertex `change` from the method's own rest-pose prediction) and rest_<method>.vtu (that
/// rest-pose prediction), for ParaView and scripts/render_comparison.py (--reference rest_network
/// --field change). Returns per sequence and method the change (mean, max) and the mean distance
/// to the first method's prediction at rest and at the peak.

#include <algorithm>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../data/frame_set.hpp"
#include "../interp/problem.hpp"
#include "../io/vtu.hpp"

namespace simsr::pipeline {

/// A method by name: apply(lr_displacement N×3, hr_displacement M×3).
struct NamedApply {
  std::string name;
  std::function<void(const Points<Scalar>&, Points<Scalar>&)> apply;
};

/// Writes Fig. 7's views and returns their figures (see the file comment). ArgumentError when
/// `methods` is empty or a name repeats; ShapeError for a sequence of another LR mesh.
inline nlohmann::ordered_json write_unseen_force_views(const std::filesystem::path& unseen_dir, const std::filesystem::path& out_dir,
                                                       const interp::UpsamplingProblem<>& problem, const std::vector<NamedApply>& methods) {
  if (methods.empty()) throw ArgumentError("write_unseen_force_views: no method");
  for (std::size_t i = 0; i < methods.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (methods[i].name == methods[j].name) throw ArgumentError("write_unseen_force_views: method '" + methods[i].name + "' given twice");
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(unseen_dir))
    if (e.path().extension() == ".npz") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  const Index n = problem.num_lr(), m = problem.num_hr();
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const auto& file : files) {
    const data::FrameSet frames = data::read_frame_set(file, "lowres", n);
    if (frames.num_frames() < 2) throw ArgumentError(file.string() + ": an unseen-force sequence needs at least 2 frames (rest and forced)");
    const Points<Scalar> rest_lr = frames.frame(0);
    Index peak = 1;
    double farthest = -1;
    for (Index f = 1; f < frames.num_frames(); ++f) {
      const double d = (frames.frame(f) - rest_lr).rowwise().norm().mean();
      if (d > farthest) farthest = d, peak = f;
    }
    const Points<Scalar> peak_lr = frames.frame(peak);
    const std::string name = file.stem().string();
    const auto dir = out_dir / name;
    std::filesystem::create_directories(dir);
    io::VtuGrid lr;
    lr.set_points(peak_lr).set_tets(problem.lr.T);
    io::write_vtu(dir / "lr_input.vtu", lr);

    nlohmann::ordered_json seq;
    seq["name"] = name;
    seq["frames"] = frames.num_frames();
    seq["peak_frame"] = frames.ids[std::size_t(peak)];
    seq["lr_mean_motion_at_peak"] = farthest;
    Points<Scalar> disp(m, 3), first_rest, first_peak;
    const Points<Scalar> rest_in = rest_lr - problem.lr.V, peak_in = peak_lr - problem.lr.V;
    for (std::size_t k = 0; k < methods.size(); ++k) {
      methods[k].apply(rest_in, disp);
      const Points<Scalar> at_rest = problem.hr.V + disp;
      methods[k].apply(peak_in, disp);
      const Points<Scalar> at_peak = problem.hr.V + disp;
      if (!at_rest.allFinite() || !at_peak.allFinite())
        throw NumericalError("write_unseen_force_views", methods[k].name + "'s prediction of " + name, -1, at_peak.sum() + at_rest.sum());
      const VecX<double> change = (at_peak - at_rest).rowwise().norm();
      io::VtuGrid g;
      g.set_points(at_peak).set_triangles(problem.hr.F);
      g.add_point_data("change", change);
      io::write_vtu(dir / (methods[k].name + ".vtu"), g);
      io::VtuGrid r;
      r.set_points(at_rest).set_triangles(problem.hr.F);
      r.add_point_data("change", VecX<double>(VecX<double>::Zero(m)));
      io::write_vtu(dir / ("rest_" + methods[k].name + ".vtu"), r);
      nlohmann::ordered_json mj;
      mj["change_mean"] = change.mean();
      mj["change_max"] = change.maxCoeff();
      if (k == 0) {
        first_rest = at_rest;
        first_peak = at_peak;
      } else {
        mj["distance_to_" + methods[0].name + "_at_rest_mean"] = (at_rest - first_rest).rowwise().norm().mean();
        mj["distance_to_" + methods[0].name + "_at_peak_mean"] = (at_peak - first_peak).rowwise().norm().mean();
      }
      seq["methods"][methods[k].name] = mj;
    }
    seq["views"] = dir.string();
    out.push_back(seq);
  }
  return out;
}

}  // namespace simsr::pipeline
