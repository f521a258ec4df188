#include <simsr/eval/comparison.hpp>
#include <simsr/eval/evaluate.hpp>
#include <simsr/eval/training_history.hpp>
#include <simsr/io/npy.hpp>
#include <simsr/interp/embedded.hpp>
#include <simsr/interp/ridge.hpp>
#include <simsr/mesh/generators.hpp>

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

using namespace simsr;

namespace {

/// An LR box, an HR sphere inside it, and F frames of an affine motion per frame (positions):
/// Embedded reproduces affine fields exactly, so its error must be zero.
struct Scene {
  interp::UpsamplingProblem<> problem;
  data::PairedFrames<> frames;
};

Scene affine_scene(Index f, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 0.05);
  Scene s;
  s.problem.lr = box_tet_mesh<double>(3, 3, 3, Vec3<>(-1, -1, -1), Vec3<>(1, 1, 1));
  s.problem.hr = icosphere<double>(2, 0.8);
  const Index n = s.problem.num_lr(), m = s.problem.num_hr();
  s.frames.lowres.resize(f, 3 * n);
  s.frames.highres.resize(f, 3 * m);
  s.frames.controls.resize(f, 0);
  for (Index i = 0; i < f; ++i) {
    Mat3<> A = Mat3<>::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) A(r, c) += g(rng);
    const Eigen::RowVector3d b(g(rng), g(rng), g(rng));
    s.frames.lr(i) = (s.problem.lr.V * A.transpose()).rowwise() + b;
    s.frames.hr(i) = (s.problem.hr.V * A.transpose()).rowwise() + b;
    s.frames.ids.push_back(100 + i);
  }
  return s;
}

/// A method that predicts NaN for one vertex: evaluate must name the frame, not average it away.
struct NanMethod {
  using scalar_type = double;
  Index n = 0, m = 0;
  template <class P>
  void fit(P, interp::UpsamplingProblem<>& p) {
    n = p.num_lr();
    m = p.num_hr();
  }
  template <class P>
  void apply(P, const Points<>&, Points<>& hr) const {
    hr.setZero();
    hr(m / 2, 1) = std::nan("");
  }
  Index num_lr() const { return n; }
  Index num_hr() const { return m; }
};
static_assert(interp::Interpolator<NanMethod>);

}  // namespace

TEST_CASE("evaluate: Embedded on affine frames is exact; the statistics are the per-vertex errors'") {
  for (unsigned seed = 0; seed < 5; ++seed) {
    auto s = affine_scene(6, seed);
    interp::Embedded<> e;
    std::vector<Index> seen;
    const auto r = eval::run_method(exec::omp, e, s.problem, s.frames, s.frames, [&](Index f, const Points<>& pred) {
      seen.push_back(f);
      CHECK((pred - s.frames.hr(f)).cwiseAbs().maxCoeff() < 1e-12);
    });
    CHECK(seen == std::vector<Index>{0, 1, 2, 3, 4, 5});
    CHECK(r.errors.num_frames() == 6);
    CHECK(r.errors.statistics().max < 1e-12);
    CHECK(r.vertex_mean_error.size() == s.problem.num_hr());
    CHECK(r.vertex_mean_error.maxCoeff() < 1e-12);
  }
}

TEST_CASE("evaluate: per-vertex mean and frame means against a brute-force computation") {
  auto s = affine_scene(4, 9);
  // the truth moves the HR surface off the affine field: Embedded now has a known error per vertex
  std::mt19937 rng(1);
  std::normal_distribution<double> g(0.0, 0.01);
  for (Index f = 0; f < 4; ++f)
    for (Index i = 0; i < s.frames.highres.cols(); ++i) s.frames.highres(f, i) += g(rng);
  interp::Embedded<> e;
  e.fit(exec::seq, s.problem);
  const auto r = eval::evaluate(exec::seq, e, s.problem.lr.V, s.problem.hr.V, s.frames);
  const Index m = s.problem.num_hr();
  VecX<> vmean = VecX<>::Zero(m);
  std::vector<double> fmeans;
  Points<> d(m, 3);
  for (Index f = 0; f < 4; ++f) {
    e.apply(exec::seq, Points<>(s.frames.lr(f) - s.problem.lr.V), d);
    const VecX<> err = (s.problem.hr.V + d - s.frames.hr(f)).rowwise().norm();
    vmean += err / 4.0;
    fmeans.push_back(err.mean());
  }
  CHECK((r.vertex_mean_error - vmean).cwiseAbs().maxCoeff() < 1e-14);
  for (Index f = 0; f < 4; ++f) CHECK(r.errors.frame_means()[std::size_t(f)] == doctest::Approx(fmeans[std::size_t(f)]).epsilon(1e-14));
  CHECK(r.errors.statistics().mean == doctest::Approx(vmean.mean()).epsilon(1e-12));
}

TEST_CASE("run_method trains a TrainableInterpolator on the training frames") {
  auto s = affine_scene(12, 4);
  interp::Ridge<> ridge;
  const auto r = eval::run_method(exec::omp, ridge, s.problem, s.frames, s.frames, interp::RidgeTrainOptions{.lambda = 1e-8});
  CHECK(ridge.info().frames == 12);
  CHECK(r.errors.statistics().max < 1e-8);  // affine frames: the residual over Embedded is zero
  interp::Ridge<> untrained;
  data::PairedFrames<> none = s.frames.select(std::vector<Index>{});
  CHECK_THROWS_WITH_AS(eval::run_method(exec::seq, untrained, s.problem, none, s.frames), doctest::Contains("no training frame"), ArgumentError);
}

TEST_CASE("evaluate: a non-finite prediction and mismatched sizes are errors naming what") {
  auto s = affine_scene(3, 2);
  NanMethod nan;
  CHECK_THROWS_WITH_AS(eval::run_method(exec::seq, nan, s.problem, s.frames, s.frames), doctest::Contains("frame 100"), ArgumentError);
  interp::Embedded<> e;
  e.fit(exec::seq, s.problem);
  auto other = affine_scene(2, 3);
  other.frames.highres.conservativeResize(2, other.frames.highres.cols() - 3);
  CHECK_THROWS_AS(eval::evaluate(exec::seq, e, s.problem.lr.V, s.problem.hr.V, other.frames), ShapeError);
  CHECK_THROWS_AS(eval::evaluate(exec::seq, e, s.problem.lr.V, s.problem.hr.V, s.frames.select(std::vector<Index>{})), ArgumentError);
}

TEST_CASE("MethodComparison: Table 1, frame-wise errors and heatmaps for every method added") {
  auto s = affine_scene(5, 6);
  std::mt19937 rng(2);
  std::normal_distribution<double> g(0.0, 0.01);
  for (Index i = 0; i < s.frames.highres.size(); ++i) s.frames.highres.data()[i] += g(rng);
  interp::Embedded<> e;
  interp::Ridge<> r;
  eval::MethodComparison table(s.problem.hr.V, s.problem.hr.F, s.frames);
  const auto& ee = table.add("embedded", eval::run_method(exec::seq, e, s.problem, s.frames, s.frames));
  CHECK(ee.vertex_errors.rows() == 5);
  table.add("ridge", eval::run_method(exec::seq, r, s.problem, s.frames, s.frames));
  CHECK_THROWS_AS(table.add("ridge", eval::evaluate(exec::seq, r, s.problem.lr.V, s.problem.hr.V, s.frames)), ArgumentError);
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "comparison";
  std::filesystem::remove_all(dir);
  table.write(dir);
  for (const char* f : {"statistics.csv", "frame_errors.csv", "frame_errors.svg", "heatmaps.pvd", "heatmaps/heatmaps_000004.vtu"})
    CHECK_MESSAGE(std::filesystem::exists(dir / f), f);
  std::ifstream csv(dir / "frame_errors.csv");
  std::string header, first;
  std::getline(csv, header);
  std::getline(csv, first);
  CHECK(header == "frame,embedded,ridge");
  CHECK(first.rfind("100,", 0) == 0);  // frame ids, not positions
  const auto stats = table.statistics();
  REQUIRE(stats.size() == 2);
  CHECK(stats[1].mean < stats[0].mean);  // ridge learns the noise-free part at least as well
}

TEST_CASE("training history: one CSV row per epoch, relative errors divided by the diagonal, plots") {
  std::vector<nn::EpochReport> h(3);
  for (int i = 0; i < 3; ++i) {
    h[std::size_t(i)].epoch = i + 1;
    h[std::size_t(i)].steps = 10 * (i + 1);
    h[std::size_t(i)].loss = 1.0 / (i + 1);
    h[std::size_t(i)].holdout_mean_error = i == 1 ? -1 : 0.5 / (i + 1);  // epoch 2 not evaluated
  }
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "history";
  std::filesystem::remove_all(dir);
  eval::write_training_history(dir, h, 2.0, 0.4);
  std::ifstream csv(dir / "training_history.csv");
  std::vector<std::string> lines;
  for (std::string l; std::getline(csv, l);) lines.push_back(l);
  REQUIRE(lines.size() == 4);
  CHECK(lines[1].substr(lines[1].size() - 12) == "0.5,0.25,0.2");  // raw 0.5, 0.5 / 2.0, the baseline 0.4 / 2.0
  CHECK(lines[2].find(",,,0.2") != std::string::npos);                  // no held-out error in epoch 2
  CHECK(std::filesystem::exists(dir / "training_loss.svg"));
  CHECK(std::filesystem::exists(dir / "holdout_error.svg"));
  CHECK_THROWS_AS(eval::write_training_history(dir, h, 0.0), ArgumentError);
}
