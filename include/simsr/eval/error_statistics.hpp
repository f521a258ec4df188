#pragma once
/// \file
/// Reconstruction error of predicted HR surfaces against the HR simulation (SPEC §8, the paper's
/// §5.2 and Tables 1–2): per-vertex Euclidean distance, and its mean / median / std / max / min
/// over every vertex of every evaluated frame — raw, relative to the rest shape's bounding-box
/// diagonal, and normalized to the largest value across methods as the paper's tables print them.
///
///     eval::ErrorAccumulator acc(rest_hr.V);                 // bbox diagonal from the rest shape
///     for (f ...) acc.add_frame(predicted_f, truth_f);        // M×3 each
///     eval::ErrorStatistics s = acc.statistics();             // s.mean, s.median, ...
///     eval::ErrorStatistics r = acc.relative_statistics();    // divided by the diagonal

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/types.hpp"

namespace simsr::eval {

/// Summary of a set of per-vertex errors. `std` is the population standard deviation (numpy's
/// default, ddof = 0); `median` of an even count is the mean of the two middle values.
struct ErrorStatistics {
  double mean = 0, median = 0, std = 0, max = 0, min = 0;
  Index count = 0;

  /// Every statistic divided by `scale` (e.g. the bounding-box diagonal).
  ErrorStatistics scaled(double scale) const {
    if (!(scale > 0) || !std::isfinite(scale)) throw ArgumentError("error statistics: scale must be positive and finite");
    return {mean / scale, median / scale, std / scale, max / scale, min / scale, count};
  }
};

/// Statistics of `errors` (any order; the vector is copied for the median). Empty input → ArgumentError.
inline ErrorStatistics statistics(std::vector<double> errors) {
  if (errors.empty()) throw ArgumentError("error statistics of an empty set");
  ErrorStatistics s;
  s.count = static_cast<Index>(errors.size());
  long double sum = 0, sq = 0;
  s.min = errors.front();
  s.max = errors.front();
  for (double e : errors) {
    if (!std::isfinite(e)) throw ArgumentError("error statistics: non-finite error value");
    sum += e;
    s.min = std::min(s.min, e);
    s.max = std::max(s.max, e);
  }
  s.mean = double(sum / s.count);
  for (double e : errors) sq += (e - s.mean) * (long double)(e - s.mean);
  s.std = std::sqrt(double(sq / s.count));
  const std::size_t mid = errors.size() / 2;
  std::nth_element(errors.begin(), errors.begin() + mid, errors.end());
  s.median = errors[mid];
  if (errors.size() % 2 == 0) s.median = 0.5 * (s.median + *std::max_element(errors.begin(), errors.begin() + mid));
  return s;
}

/// Per-vertex Euclidean distances between two M×3 position (or displacement) sets.
template <class DA, class DB>
VecX<double> vertex_errors(const Eigen::MatrixBase<DA>& predicted, const Eigen::MatrixBase<DB>& truth) {
  if (predicted.rows() != truth.rows() || predicted.cols() != 3 || truth.cols() != 3)
    throw ShapeError("vertex_errors: predicted vs truth", {truth.rows(), 3}, {predicted.rows(), predicted.cols()});
  return (predicted.template cast<double>() - truth.template cast<double>()).rowwise().norm();
}

/// Length of the bounding-box diagonal of #V×3 points (the paper's relative-error unit).
template <class D>
double bbox_diagonal(const Eigen::MatrixBase<D>& V) {
  if (V.rows() == 0) throw ArgumentError("bbox_diagonal of an empty point set");
  return (V.colwise().maxCoeff() - V.colwise().minCoeff()).template cast<double>().norm();
}

/// For each statistic, the values of all methods divided by the largest of them (Tables 1–2:
/// the worst method reads 1.0 in every column).
inline std::vector<ErrorStatistics> normalized_to_largest(const std::vector<ErrorStatistics>& methods) {
  ErrorStatistics top;
  for (const auto& m : methods) {
    top.mean = std::max(top.mean, m.mean);
    top.median = std::max(top.median, m.median);
    top.std = std::max(top.std, m.std);
    top.max = std::max(top.max, m.max);
    top.min = std::max(top.min, m.min);
  }
  auto div = [](double a, double b) { return b > 0 ? a / b : 0.0; };
  std::vector<ErrorStatistics> out;
  for (const auto& m : methods)
    out.push_back({div(m.mean, top.mean), div(m.median, top.median), div(m.std, top.std), div(m.max, top.max),
                   div(m.min, top.min), m.count});
  return out;
}

/// Collects per-vertex errors frame by frame: the per-frame mean (Fig. 5), the last frame's
/// per-vertex errors (for a heatmap), and the pooled statistics.
class ErrorAccumulator {
 public:
  /// `rest` is the HR rest shape; its bounding-box diagonal is the relative-error unit.
  template <class D>
  explicit ErrorAccumulator(const Eigen::MatrixBase<D>& rest) : diagonal_(bbox_diagonal(rest)), vertices_(rest.rows()) {}

  /// Adds one frame (M×3 predicted and true positions); returns that frame's mean error.
  template <class DA, class DB>
  double add_frame(const Eigen::MatrixBase<DA>& predicted, const Eigen::MatrixBase<DB>& truth) {
    if (truth.rows() != vertices_) throw ShapeError("error accumulator: frame", {vertices_, 3}, {truth.rows(), truth.cols()});
    last_ = vertex_errors(predicted, truth);
    if (!last_.allFinite()) throw ArgumentError("error accumulator: frame " + std::to_string(frame_means_.size()) + " has non-finite positions");
    errors_.insert(errors_.end(), last_.data(), last_.data() + last_.size());
    frame_means_.push_back(last_.mean());
    frame_maxes_.push_back(last_.maxCoeff());
    return frame_means_.back();
  }

  Index num_frames() const { return static_cast<Index>(frame_means_.size()); }
  double diagonal() const { return diagonal_; }
  const std::vector<double>& frame_means() const { return frame_means_; }
  const std::vector<double>& frame_maxes() const { return frame_maxes_; }
  const VecX<double>& last_frame_errors() const { return last_; }
  ErrorStatistics statistics() const { return eval::statistics(errors_); }
  ErrorStatistics relative_statistics() const { return statistics().scaled(diagonal_); }

 private:
  double diagonal_;
  Index vertices_;
  std::vector<double> errors_, frame_means_, frame_maxes_;
  VecX<double> last_;
};

}  // namespace simsr::eval
