#include <simsr/eval/evaluate.hpp>
#include <simsr/interp/embedded.hpp>
#include <simsr/interp/ridge.hpp>
#include <simsr/mesh/generators.hpp>

#include <doctest/doctest.h>

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
