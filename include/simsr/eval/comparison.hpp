#pragma once
/// \file
/// Several methods evaluated on the same test frames, and the files people open (the paper's
/// Table 1 and Fig. 5): statistics.csv (raw, relative to the bounding-box diagonal, normalized to
/// the largest), frame_errors.csv + frame_errors.svg (per-frame mean error of every method) and
/// heatmaps.pvd (ParaView: the true HR surface of every test frame with one error array per method);
/// and write_evaluation, the same files for one set of predictions (`simsr eval --out`).
///
///     eval::MethodComparison table(hr.V, hr.F, test);
///     table.add("embedded", eval::run_method(exec::omp, embedded, problem, train, test));
///     table.add("mls", eval::run_method(exec::omp, mls, problem, train, test));
///     table.write("out/bunny_baselines");   // every file above, atomically

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/parallel.hpp"
#include "../data/paired_frames.hpp"
#include "../io/vtu.hpp"
#include "error_statistics.hpp"
#include "evaluate.hpp"
#include "report.hpp"

namespace simsr::eval {

class MethodComparison {
 public:
  /// The HR rest surface (its bounding-box diagonal is the relative unit) and the test frames
  /// every method is evaluated on (absolute positions).
  MethodComparison(Points<Scalar> hr_rest, Tris hr_faces, const data::PairedFrames<Scalar>& test)
      : hr_rest_(std::move(hr_rest)), hr_faces_(std::move(hr_faces)), test_(&test), diagonal_(bbox_diagonal(hr_rest_)) {
    if (test.num_hr() != hr_rest_.rows()) throw ShapeError("eval::MethodComparison: test frames' HR vertices", {hr_rest_.rows()}, {test.num_hr()});
  }

  /// Records `name`'s evaluation on the test frames. ArgumentError for a repeated name,
  /// ShapeError for an evaluation of other frames.
  const Evaluation& add(std::string name, Evaluation evaluation) {
    for (const auto& n : names_)
      if (n == name) throw ArgumentError("eval::MethodComparison: method '" + name + "' added twice");
    if (evaluation.errors.num_frames() != test_->num_frames() || evaluation.vertex_errors.cols() != hr_rest_.rows())
      throw ShapeError("eval::MethodComparison: evaluation of '" + name + "' (frames, HR vertices)", {test_->num_frames(), hr_rest_.rows()},
                       {evaluation.errors.num_frames(), evaluation.vertex_errors.cols()});
    names_.push_back(std::move(name));
    evaluations_.push_back(std::move(evaluation));
    return evaluations_.back();
  }

  const std::vector<std::string>& names() const { return names_; }
  const std::vector<Evaluation>& evaluations() const { return evaluations_; }
  double diagonal() const { return diagonal_; }
  /// Raw Table-1 statistics per method, in the order added.
  std::vector<ErrorStatistics> statistics() const {
    std::vector<ErrorStatistics> s;
    for (const auto& e : evaluations_) s.push_back(e.errors.statistics());
    return s;
  }

  /// Writes statistics.csv, frame_errors.csv, frame_errors.svg and heatmaps.pvd (+ one .vtu per
  /// test frame in heatmaps/) into `dir` (created if needed).
  void write(const std::filesystem::path& dir) const {
    if (names_.empty()) throw ArgumentError("eval::MethodComparison::write: no method was added");
    std::filesystem::create_directories(dir);
    write_statistics_csv(dir / "statistics.csv", names_, statistics(), diagonal_);
    std::vector<Series> series;
    for (std::size_t k = 0; k < names_.size(); ++k) {
      Series s{names_[k], evaluations_[k].errors.frame_means()};
      for (double& v : s.values) v /= diagonal_;
      series.push_back(std::move(s));
    }
    const std::vector<long long> ids(test_->ids.begin(), test_->ids.end());
    write_frame_csv(dir / "frame_errors.csv", series, ids);
    write_svg_plot(dir / "frame_errors.svg", series, "Mean per-vertex error on held-out frames (log scale)", "mean error / bbox diagonal", true,
                   "held-out frame (index)");
    io::PvdWriter heatmaps(dir / "heatmaps.pvd");
    for (Index f = 0; f < test_->num_frames(); ++f) {
      io::VtuGrid grid;
      grid.set_points(Points<Scalar>(test_->hr(f))).set_triangles(hr_faces_);
      for (std::size_t k = 0; k < names_.size(); ++k)
        grid.add_point_data("error_" + names_[k], VecX<double>(evaluations_[k].vertex_errors.row(f).transpose().template cast<double>()));
      heatmaps.add(double(test_->ids[std::size_t(f)]), grid);
    }
  }

 private:
  Points<Scalar> hr_rest_;
  Tris hr_faces_;
  const data::PairedFrames<Scalar>* test_;
  double diagonal_;
  std::vector<std::string> names_;
  std::vector<Evaluation> evaluations_;
};

/// The files of one evaluated prediction set (`simsr eval --out`): frame_errors.csv (per frame:
/// mean, max, and both relative to the diagonal, by frame id), frame_errors.svg, error_heatmap.vtu
/// (the HR rest surface with each vertex's mean, max and relative mean error over the frames:
/// ParaView) and statistics.csv (one row, `name`).
inline void write_evaluation(const std::filesystem::path& dir, const std::string& name, const Evaluation& r, const TriMesh<Scalar>& hr_rest,
                             const std::vector<std::int64_t>& frame_ids) {
  if (Index(frame_ids.size()) != r.errors.num_frames())
    throw ShapeError("eval::write_evaluation: frame ids", {r.errors.num_frames()}, {Index(frame_ids.size())});
  std::filesystem::create_directories(dir);
  const double diagonal = r.errors.diagonal();
  std::vector<double> rel_means = r.errors.frame_means(), rel_maxes = r.errors.frame_maxes();
  for (double& v : rel_means) v /= diagonal;
  for (double& v : rel_maxes) v /= diagonal;
  const std::vector<long long> ids(frame_ids.begin(), frame_ids.end());
  write_frame_csv(dir / "frame_errors.csv",
                  {{"mean", r.errors.frame_means()}, {"max", r.errors.frame_maxes()}, {"relative_mean", rel_means}, {"relative_max", rel_maxes}}, ids);
  write_svg_plot(dir / "frame_errors.svg", {{"mean", rel_means}, {"max", rel_maxes}}, "Per-vertex error of " + name + " per frame",
                 "error / bbox diagonal", false, "frame (index)");
  io::VtuGrid grid(hr_rest);
  grid.add_point_data("mean_error", r.vertex_mean_error).add_point_data("max_error", r.vertex_max_error);
  grid.add_point_data("relative_mean_error", VecX<double>(r.vertex_mean_error / diagonal));
  io::write_vtu(dir / "error_heatmap.vtu", grid);
  write_statistics_csv(dir / "statistics.csv", {name}, {r.errors.statistics()}, diagonal);
}

}  // namespace simsr::eval
