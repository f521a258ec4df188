#pragma once
/// \file
/// The core paper's upsampling methods (interp/: the super-resolution network, the local-linear
/// map, ridge, MLS, …) as baselines on a cloth dataset, beside the detail-synthesis network
/// (issue #14 item 5: "the face network's upsampling composition"). The coarse cloth is the LR
/// mesh and the fine cloth the HR surface. A cloth's LR mesh is a surface: the problem has no LR
/// tets, and its LR geodesic graph (the network's first EdgeConv) is taken along the coarse
/// triangles' edges; the §3.2 neighbourhoods need only the LR points and the HR surface.
///
///     auto problem = shell::cloth_upsampling_problem(exec::omp, data);
///     const auto train = shell::cloth_paired_frames(data, false);   // built once for every method
///     interp::LocalLinear<> method;
///     const auto e = shell::evaluate_upsampling(exec::omp, data, problem, train, method, "local_linear");
///
/// Trained (a method that learns) on the training sequences' frames as displacements from the
/// rest pair; applied to every held-out coarse frame on its own (these methods are per frame: no
/// temporal window, no fed-back state).

#include <chrono>
#include <string>
#include <vector>

#include "../data/paired_frames.hpp"
#include "../interp/concepts.hpp"
#include "../interp/fit_and_train.hpp"
#include "../neighbors/geodesic_knn.hpp"
#include "cloth_data.hpp"

namespace simsr::shell {

/// The cloth pair as an upsampling problem: LR = the coarse rest cloth (points only; no tets),
/// HR = the fine rest surface, the LR graph = the `graph_k` geodesically nearest coarse vertices
/// along the coarse triangles' edges (self first), the §3.2 neighbourhoods with `k` neighbours.
template <exec::HostPolicy P>
interp::UpsamplingProblem<> cloth_upsampling_problem(P policy, const ClothData& d, Index k = 20, Index graph_k = 5) {
  interp::UpsamplingProblem<> p;
  p.lr.V = d.pair.coarse.V;
  p.lr.T.resize(0, 4);
  p.hr = d.pair.fine;
  p.lr_graph = neighbors::geodesic_knn(policy, d.pair.coarse.V, d.pair.coarse.F, graph_k).indices;
  p.ensure_neighborhoods(policy, k);
  return p;
}

/// The frames of the training (test = false) or held-out (test = true) sequences as paired
/// absolute positions, one sequence index per frame. ArgumentError when there are none.
inline data::PairedFrames<> cloth_paired_frames(const ClothData& d, bool test) {
  Index F = 0;
  for (const auto& s : d.sequences)
    if (s.test == test) F += s.num_frames();
  if (F == 0) throw ArgumentError(std::string("cloth_paired_frames: the dataset has no ") + (test ? "held-out" : "training") + " sequence");
  const Index N = d.num_coarse(), M = d.num_fine();
  data::PairedFrames<> out;
  out.lowres.resize(F, 3 * N);
  out.highres.resize(F, 3 * M);
  Index row = 0;
  for (const auto& s : d.sequences) {
    if (s.test != test) continue;
    out.sequence_names.push_back(s.name);
    for (Index f = 0; f < s.num_frames(); ++f, ++row) {
      out.lr(row) = s.coarse[std::size_t(f)];
      out.hr(row) = s.fine[std::size_t(f)];
      out.ids.push_back(row);
      out.sequence.push_back(std::int32_t(out.sequence_names.size() - 1));
    }
  }
  return out;
}

/// One upsampling method on the held-out sequences: RMS vertex distance (m) to the fine
/// simulation per sequence and overall (the same figure as ClothEvaluation's).
struct ClothUpsamplingEvaluation {
  std::string method;
  struct Sequence {
    std::string name;
    Index frames = 0;
    double rmse = 0;
    std::vector<double> frame_rmse;  ///< per frame: RMS vertex distance (m)
  };
  std::vector<Sequence> sequences;
  double rmse = 0;
  double fit_seconds = 0;       ///< fit + training
  double seconds_per_frame = 0;  ///< apply, per held-out frame
  Index frames = 0;
};

/// Fits `method` on the problem, trains it (when it learns) on `train` (the training sequences'
/// frames: cloth_paired_frames(d, false)) with `options` (its train_options; none: the
/// defaults), and applies it to every held-out coarse frame (see the file comment).
template <exec::HostPolicy P, interp::Interpolator I, class... TrainOptions>
ClothUpsamplingEvaluation evaluate_upsampling(P policy, const ClothData& d, interp::UpsamplingProblem<>& problem, const data::PairedFrames<>& train,
                                              I& method, const std::string& name, const TrainOptions&... options) {
  static_assert(sizeof...(TrainOptions) <= 1, "evaluate_upsampling: at most one train_options");
  static_assert(interp::TrainableInterpolator<I> || sizeof...(TrainOptions) == 0, "evaluate_upsampling: this method does not train; pass no options");
  using clock = std::chrono::steady_clock;
  if (problem.num_lr() != d.num_coarse() || problem.num_hr() != d.num_fine())
    throw ShapeError("evaluate_upsampling: the problem's LR / HR vertices", {d.num_coarse(), d.num_fine()}, {problem.num_lr(), problem.num_hr()});
  ClothUpsamplingEvaluation e;
  e.method = name;
  const auto t0 = clock::now();
  if constexpr (interp::TrainableInterpolator<I>) interp::prepare(policy, method, problem, train, options...);
  else interp::prepare(policy, method, problem);
  e.fit_seconds = std::chrono::duration<double>(clock::now() - t0).count();
  Points<> lr_disp(d.num_coarse(), 3), hr_disp(d.num_fine(), 3);
  double total = 0, apply_seconds = 0;
  for (const auto& s : d.sequences) {
    if (!s.test) continue;
    double sum = 0;
    std::vector<double> per_frame;
    per_frame.reserve(std::size_t(s.num_frames()));
    for (Index f = 0; f < s.num_frames(); ++f) {
      lr_disp = s.coarse[std::size_t(f)] - problem.lr.V;
      const auto t = clock::now();
      method.apply(policy, lr_disp, hr_disp);
      apply_seconds += std::chrono::duration<double>(clock::now() - t).count();
      const double msd = (problem.hr.V + hr_disp - s.fine[std::size_t(f)]).rowwise().squaredNorm().mean();
      per_frame.push_back(std::sqrt(msd));
      sum += msd;
    }
    e.sequences.push_back({s.name, s.num_frames(), std::sqrt(sum / double(s.num_frames())), std::move(per_frame)});
    total += sum;
    e.frames += s.num_frames();
  }
  if (e.frames == 0) throw ArgumentError("evaluate_upsampling: the dataset has no held-out sequence");
  e.rmse = std::sqrt(total / double(e.frames));
  e.seconds_per_frame = apply_seconds / double(e.frames);
  return e;
}

}  // namespace simsr::shell
