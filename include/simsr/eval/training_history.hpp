#pragma once
/// \file
/// The files of a training run people open: training_history.csv (one row per epoch: loss terms,
/// learning rate, seconds, held-out error raw and relative, and the baseline's relative error on
/// the same held-out frames), training_loss.svg and holdout_error.svg (network vs baseline).
///
///     eval::write_training_history("out/bunny_network", net.history(), hr_diagonal, embedded_mean_error);

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../nn/trainer.hpp"
#include "report.hpp"

namespace simsr::eval {

/// Writes the three files into `dir` (created if needed). `diagonal` is the HR rest shape's
/// bounding-box diagonal; `baseline_error` the baseline's mean held-out error in mesh units (< 0:
/// none, the column is left empty). Nothing is written for an empty history.
inline void write_training_history(const std::filesystem::path& dir, const std::vector<nn::EpochReport>& history, double diagonal,
                                   double baseline_error = -1, const std::string& baseline_name = "Embedded") {
  if (!(diagonal > 0)) throw ArgumentError("write_training_history: the bounding-box diagonal must be > 0");
  if (history.empty()) return;
  std::filesystem::create_directories(dir);
  std::ostringstream csv;
  csv.imbue(std::locale::classic());
  csv << std::setprecision(10);
  csv << "epoch,steps,loss,recon,z_reg,face_normals,contact,penetrating_pairs,lr,seconds,holdout_mean_error,holdout_relative_error,baseline_relative_error\n";
  Series loss{"training loss", {}}, err{"network, held-out mean error / bbox diagonal", {}}, base{baseline_name + " on the same frames", {}};
  for (const auto& r : history) {
    csv << r.epoch << ',' << r.steps << ',' << r.loss << ',' << r.recon << ',' << r.z_reg << ',' << r.face_normals << ',' << r.contact << ',' << r.penetrating << ',' << r.lr << ','
        << r.seconds << ',';
    if (r.holdout_mean_error >= 0) csv << r.holdout_mean_error << ',' << r.holdout_mean_error / diagonal;
    else csv << ',';
    csv << ',';
    if (baseline_error >= 0) csv << baseline_error / diagonal;
    csv << '\n';
    loss.values.push_back(r.loss);
    if (r.holdout_mean_error >= 0) {
      err.values.push_back(r.holdout_mean_error / diagonal);
      if (baseline_error >= 0) base.values.push_back(baseline_error / diagonal);
    }
  }
  detail::write_file(dir / "training_history.csv", csv.str());
  write_svg_plot(dir / "training_loss.svg", {loss}, "training loss per epoch", "loss", true, "epoch");
  if (!err.values.empty()) {
    std::vector<Series> s{err};
    if (!base.values.empty()) s.push_back(base);
    write_svg_plot(dir / "holdout_error.svg", s, "held-out mean HR vertex error", "error / bbox diagonal", true, "epoch");
  }
}

}  // namespace simsr::eval
