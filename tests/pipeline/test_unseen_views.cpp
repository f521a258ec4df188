// pipeline::write_unseen_force_views (Fig. 7) on random LR-only sequences and two linear methods
// with known answers: the peak frame is the LR mesh's farthest from rest, each method's change
// from its own rest-pose prediction and its distance to the first method are the ones computed
// here by hand; every view file is written; bad inputs are named.
#include <simsr/io/npz.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/pipeline/unseen_views.hpp>

#include <doctest/doctest.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

using namespace simsr;

namespace pipeline_unseen {

TEST_CASE("pipeline::write_unseen_force_views: peak frame, changes and distances as computed by hand; every view written") {
  interp::UpsamplingProblem<> problem{box_tet_mesh<double>(2, 2, 2, Vec3<>(-1, -1, -1), Vec3<>(1, 1, 1)), icosphere<double>(1, 0.5), {}, {}};
  const Index n = problem.num_lr(), m = problem.num_hr();
  // method "mean": every HR vertex moves by the LR mean displacement; "scaled": by 2x it plus a
  // constant (so its rest pose differs from the first method's)
  auto mean_of = [](const Points<>& lr) { return Eigen::RowVector3d(lr.colwise().mean()); };
  const std::vector<pipeline::NamedApply> methods{
      {"mean", [&](const Points<>& lr, Points<>& hr) { hr = mean_of(lr).replicate(m, 1); }},
      {"scaled", [&](const Points<>& lr, Points<>& hr) { hr = (2 * mean_of(lr) + Eigen::RowVector3d(0.01, 0, 0)).replicate(m, 1); }}};
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "pipeline_unseen";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "in");
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 0.05);
  std::vector<Index> peaks;
  std::vector<Points<>> rests, peak_frames;
  for (int s = 0; s < 3; ++s) {
    const Index F = 3 + s;
    data::FrameMatrix<double> lowres(F, 3 * n);  // row-major: frame after frame, as the npz holds them
    Index peak = 0;
    double far = -1;
    Points<> rest;
    for (Index f = 0; f < F; ++f) {
      Points<> x = problem.lr.V;
      for (Index i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) x(i, c) += g(rng);
      if (f == 0) rest = x;
      const double d = (x - rest).rowwise().norm().mean();
      if (f > 0 && d > far) far = d, peak = f;
      lowres.row(f) = Eigen::Map<const Eigen::RowVectorXd>(x.data(), 3 * n);
    }
    peaks.push_back(peak);
    rests.push_back(rest);
    peak_frames.push_back(Eigen::Map<const Points<>>(lowres.row(peak).data(), n, 3));
    io::NpzArrays z;
    z["lowres"] = io::make_npy<double>({F, n, 3}, lowres.data());
    std::vector<std::int64_t> ids;
    for (Index f = 0; f < F; ++f) ids.push_back(10 * f);
    z["frame"] = io::make_npy<std::int64_t>({F}, ids.data());
    io::write_npz(dir / "in" / ("seq" + std::to_string(s) + ".npz"), z);
  }
  const auto j = pipeline::write_unseen_force_views(dir / "in", dir / "out", problem, methods);
  REQUIRE(j.size() == 3);
  for (int s = 0; s < 3; ++s) {
    CAPTURE(s);
    const auto& q = j[std::size_t(s)];
    CHECK(q["name"] == "seq" + std::to_string(s));
    CHECK(q["peak_frame"] == 10 * peaks[std::size_t(s)]);
    const Eigen::RowVector3d shift = mean_of(peak_frames[std::size_t(s)] - problem.lr.V) - mean_of(rests[std::size_t(s)] - problem.lr.V);
    CHECK(q["methods"]["mean"]["change_max"].get<double>() == doctest::Approx(shift.norm()).epsilon(1e-12));
    CHECK(q["methods"]["mean"]["change_mean"].get<double>() == doctest::Approx(shift.norm()).epsilon(1e-12));
    CHECK(q["methods"]["scaled"]["change_max"].get<double>() == doctest::Approx(2 * shift.norm()).epsilon(1e-12));
    const Eigen::RowVector3d rest_gap = mean_of(rests[std::size_t(s)] - problem.lr.V) + Eigen::RowVector3d(0.01, 0, 0);
    CHECK(q["methods"]["scaled"]["distance_to_mean_at_rest_mean"].get<double>() == doctest::Approx(rest_gap.norm()).epsilon(1e-12));
    CHECK_FALSE(q["methods"]["mean"].contains("distance_to_mean_at_rest_mean"));
    for (const char* f : {"lr_input.vtu", "mean.vtu", "scaled.vtu", "rest_mean.vtu", "rest_scaled.vtu"})
      CHECK_MESSAGE(std::filesystem::file_size(dir / "out" / ("seq" + std::to_string(s)) / f) > 100, f);
  }

  CHECK_THROWS_AS(pipeline::write_unseen_force_views(dir / "in", dir / "out", problem, {}), ArgumentError);
  CHECK_THROWS_AS(pipeline::write_unseen_force_views(dir / "in", dir / "out", problem, {methods[0], methods[0]}), ArgumentError);
  // a sequence of another LR mesh
  interp::UpsamplingProblem<> other{box_tet_mesh<double>(3, 2, 2, Vec3<>(-1, -1, -1), Vec3<>(1, 1, 1)), icosphere<double>(1, 0.5), {}, {}};
  CHECK_THROWS_AS(pipeline::write_unseen_force_views(dir / "in", dir / "out", other, methods), ShapeError);
  // a method that gives NaN
  const std::vector<pipeline::NamedApply> bad{{"nan", [&](const Points<>&, Points<>& hr) { hr.setConstant(m, 3, std::nan("")); }}};
  CHECK_THROWS_WITH_AS(pipeline::write_unseen_force_views(dir / "in", dir / "out", problem, bad), doctest::Contains("nan's prediction"), NumericalError);
}

}  // namespace pipeline_unseen
