#include <doctest/doctest.h>
#include "../support/require.hpp"
#include "bunny_fixture.hpp"
#include "random_points.hpp"

#include <simsr/interp/local_linear.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace simsr;

namespace {

using simsr::test::random_points;

interp::UpsamplingProblem<> make_problem(Index n, Index m, Index k, std::mt19937& rng) {
  interp::UpsamplingProblem<> p;
  p.lr.V = random_points(n, 0, 1, rng);
  p.hr.V = random_points(m, 0, 1, rng);
  p.neighborhoods = simsr::test::brute_neighborhoods(p.lr.V, p.hr.V, k);
  return p;
}

/// F frames of random LR displacements; the HR ones from `truth` (M×(3k·3), LocalLinear's layout)
/// plus Gaussian noise of `noise`. Sequence s of frame f: f·sequences/F.
data::PairedFrames<> make_frames(const interp::UpsamplingProblem<>& p, Index k, const Eigen::MatrixXd& truth, Index F, double noise, int sequences,
                                 std::mt19937& rng) {
  std::normal_distribution<double> g;
  const Index n = p.num_lr(), m = p.num_hr();
  data::PairedFrames<> fr;
  fr.lowres.resize(F, 3 * n);
  fr.highres.resize(F, 3 * m);
  for (Index i = 0; i < fr.lowres.size(); ++i) fr.lowres.data()[i] = g(rng);
  const auto& idx = p.neighborhoods->indices;
  for (Index f = 0; f < F; ++f)
    for (Index v = 0; v < m; ++v)
      for (Index c = 0; c < 3; ++c) {
        double y = noise * g(rng);
        for (Index j = 0; j < k; ++j)
          for (Index a = 0; a < 3; ++a) y += truth(v, 3 * (3 * j + a) + c) * fr.lowres(f, 3 * idx(v, j) + a);
        fr.highres(f, 3 * v + c) = y;
      }
  for (Index f = 0; f < F; ++f) fr.ids.push_back(f);
  fr.controls.resize(F, 0);
  if (sequences > 0) {
    for (int s = 0; s < sequences; ++s) fr.sequence_names.push_back("s" + std::to_string(s));
    for (Index f = 0; f < F; ++f) fr.sequence.push_back(std::int32_t(f * sequences / F));
  }
  return fr;
}

/// The ridge problem of one vertex solved from scratch: rows of A are the frames, λ relative to
/// tr(AᵀA)/3k, no fold machinery.
Eigen::MatrixXd brute_vertex(const data::PairedFrames<>& fr, const std::vector<Index>& rows, const interp::UpsamplingProblem<>& p, Index v, Index k,
                             double lambda) {
  const Index D = 3 * k;
  Eigen::MatrixXd A(Index(rows.size()), D), Y(Index(rows.size()), 3);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (Index j = 0; j < k; ++j)
      for (Index a = 0; a < 3; ++a) A(Index(r), 3 * j + a) = fr.lowres(rows[r], 3 * p.neighborhoods->indices(v, j) + a);
    for (Index c = 0; c < 3; ++c) Y(Index(r), c) = fr.highres(rows[r], 3 * v + c);
  }
  Eigen::MatrixXd G = A.transpose() * A;
  const double t = G.trace() / double(D);
  if (!(t > 0)) return Eigen::MatrixXd::Zero(D, 3);
  G.diagonal().array() += lambda * t;
  return G.colPivHouseholderQr().solve(A.transpose() * Y);
}

/// Predictions of the brute-force maps for frame f (M×3).
Points<> brute_apply(const std::vector<Eigen::MatrixXd>& W, const data::PairedFrames<>& fr, Index f, const interp::UpsamplingProblem<>& p, Index k) {
  Points<> out = Points<>::Zero(p.num_hr(), 3);
  for (Index v = 0; v < p.num_hr(); ++v)
    for (Index j = 0; j < k; ++j)
      for (Index a = 0; a < 3; ++a)
        for (Index c = 0; c < 3; ++c) out(v, c) += W[std::size_t(v)](3 * j + a, c) * fr.lowres(f, 3 * p.neighborhoods->indices(v, j) + a);
  return out;
}

Eigen::MatrixXd random_truth(Index m, Index k, std::mt19937& rng) {
  std::normal_distribution<double> g;
  Eigen::MatrixXd t(m, 9 * k);
  for (Index i = 0; i < t.size(); ++i) t.data()[i] = g(rng);
  return t;
}

}  // namespace

TEST_CASE("LocalLinear recovers an exactly local-linear map, and linear_map is apply as a matrix") {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 6; ++trial) {
    const Index n = 15 + 3 * trial, m = 10 + trial, k = 2 + trial % 3;
    auto p = make_problem(n, m, k, rng);
    const Eigen::MatrixXd truth = random_truth(m, k, rng);
    const auto train = make_frames(p, k, truth, 12 * k, 0.0, 0, rng);
    interp::LocalLinear<> ll(interp::LocalLinearOptions{.k = k});
    ll.fit(exec::omp, p);
    ll.train(exec::omp, train, {.lambda = 1e-13});
    const auto test = make_frames(p, k, truth, 4, 0.0, 0, rng);
    const auto map = ll.linear_map();
    Points<> out(m, 3);
    for (Index f = 0; f < test.num_frames(); ++f) {
      const Points<> x = test.lr(f);
      ll.apply(exec::omp, x, out);
      CHECK((out - test.hr(f)).cwiseAbs().maxCoeff() < 1e-8 * (1 + test.hr(f).cwiseAbs().maxCoeff()));
      const Eigen::VectorXd flat = Eigen::Map<const Eigen::VectorXd>(test.lowres.row(f).eval().data(), 3 * n);
      const Eigen::VectorXd y = map * flat;
      CHECK((Eigen::Map<const Eigen::VectorXd>(out.data(), 3 * m) - y).cwiseAbs().maxCoeff() < 1e-10 * (1 + y.cwiseAbs().maxCoeff()));
    }
  }
}

TEST_CASE("LocalLinear at a given λ equals each vertex's ridge problem solved from scratch; seq == omp bitwise") {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 8; ++trial) {
    const Index n = 12 + trial, m = 9, k = 1 + trial % 4, F = 6 + 3 * trial;  // F < 3k too: underdetermined vertices
    auto p = make_problem(n, m, k, rng);
    const auto train = make_frames(p, k, random_truth(m, k, rng), F, 0.3, 0, rng);
    const double lambda = std::pow(10.0, -4 + trial % 5);
    interp::LocalLinear<> a(interp::LocalLinearOptions{.k = k}), b(interp::LocalLinearOptions{.k = k});
    a.fit(exec::seq, p);
    b.fit(exec::omp, p);
    a.train(exec::seq, train, {.lambda = lambda});
    b.train(exec::omp, train, {.lambda = lambda});
    std::vector<Index> all(static_cast<std::size_t>(F), 0);
    for (Index f = 0; f < F; ++f) all[std::size_t(f)] = f;
    std::vector<Eigen::MatrixXd> W;
    for (Index v = 0; v < m; ++v) W.push_back(brute_vertex(train, all, p, v, k, lambda));
    const auto test = make_frames(p, k, random_truth(m, k, rng), 3, 0.0, 0, rng);
    Points<> oa(m, 3), ob(m, 3);
    for (Index f = 0; f < 3; ++f) {
      const Points<> x = test.lr(f);
      a.apply(exec::seq, x, oa);
      b.apply(exec::omp, x, ob);
      const Points<> want = brute_apply(W, test, f, p, k);
      CHECK((oa - want).cwiseAbs().maxCoeff() < 1e-9 * (1 + want.cwiseAbs().maxCoeff()));
      CHECK(oa == ob);
    }
    CHECK(a.info().lambda_relative == lambda);
    CHECK(a.info().folds == 0);
  }
}

TEST_CASE("LocalLinear's cross-validation: the grid λ whose held-out error, refitted from scratch fold by fold, is least") {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 6; ++trial) {
    const Index n = 14, m = 8, k = 2 + trial % 2, F = 30;
    const int sequences = trial % 2 == 0 ? 3 : 0;  // leave one sequence out, or 5 contiguous blocks
    auto p = make_problem(n, m, k, rng);
    const auto train = make_frames(p, k, random_truth(m, k, rng), F, 0.5 + trial, sequences, rng);
    interp::LocalLinearTrainOptions o;
    o.log10_lo = -4;
    o.log10_hi = 1;
    o.steps = 6;
    interp::LocalLinear<> ll(interp::LocalLinearOptions{.k = k});
    ll.fit(exec::omp, p);
    ll.train(exec::omp, train, o);
    const auto& info = ll.info();
    CHECK(info.by_sequence == (sequences > 0));
    CHECK(info.folds == (sequences > 0 ? sequences : 5));
    REQUIRE(info.grid_lambda.size() == 6);
    // brute force: every fold refitted with LocalLinear at a given λ on the other frames
    std::vector<double> rmse;
    for (double lambda : info.grid_lambda) {
      double sq = 0;
      for (Index fold = 0; fold < info.folds; ++fold) {
        std::vector<Index> in, out;
        for (Index f = 0; f < F; ++f) {
          const Index of = sequences > 0 ? Index(train.sequence[std::size_t(f)]) : f * 5 / F;
          (of == fold ? out : in).push_back(f);
        }
        std::vector<Eigen::MatrixXd> W;
        for (Index v = 0; v < m; ++v) W.push_back(brute_vertex(train, in, p, v, k, lambda));
        for (Index f : out) sq += (brute_apply(W, train, f, p, k) - train.hr(f)).squaredNorm();
      }
      rmse.push_back(std::sqrt(sq / double(3 * m * F)));
    }
    std::size_t best = 0;
    for (std::size_t i = 0; i < rmse.size(); ++i) {
      CHECK(info.grid_rmse[i] == doctest::Approx(rmse[i]).epsilon(1e-8));
      if (rmse[i] < rmse[best]) best = i;
    }
    CHECK(info.lambda_relative == info.grid_lambda[best]);
  }
}

TEST_CASE("LocalLinear: vertices whose neighbours never move get a zero map; bad input is refused") {
  std::mt19937 rng(3);
  const Index n = 12, m = 7, k = 3;
  auto p = make_problem(n, m, k, rng);
  auto train = make_frames(p, k, random_truth(m, k, rng), 20, 0.1, 0, rng);
  for (Index j = 0; j < k; ++j)  // vertex 0's neighbours held still
    for (Index a = 0; a < 3; ++a) train.lowres.col(3 * p.neighborhoods->indices(0, j) + a).setZero();
  interp::LocalLinear<> ll(interp::LocalLinearOptions{.k = k});
  Points<> x = Points<>::Random(n, 3), out(m, 3);
  CHECK_THROWS_AS(ll.train(exec::seq, train, {}), ArgumentError);  // before fit
  ll.fit(exec::seq, p);
  CHECK_THROWS_AS(ll.apply(exec::seq, x, out), ArgumentError);  // before train
  ll.train(exec::seq, train, {});
  CHECK(ll.info().still_vertices >= 1);
  ll.apply(exec::seq, x, out);
  CHECK(out.row(0).isZero());
  Points<> wrong(n + 1, 3);
  CHECK_THROWS_AS(ll.apply(exec::seq, wrong, out), ShapeError);
  auto nan = train;
  nan.highres(3, 4) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(ll.train(exec::seq, nan, {}), ArgumentError);
  CHECK_THROWS_AS(ll.train(exec::seq, train, {.lambda = -1, .log10_lo = -9, .log10_hi = -1, .steps = 9, .folds = 21}), ArgumentError);  // folds > frames
  CHECK_THROWS_AS(ll.train(exec::seq, train, {.lambda = -1, .log10_lo = 0, .log10_hi = -1, .steps = 9, .folds = 5}), ArgumentError);  // empty grid
  interp::LocalLinear<> wide(interp::LocalLinearOptions{.k = k + 1});
  CHECK_THROWS_AS(wide.fit(exec::seq, p), ArgumentError);  // neighbourhoods have only k columns
  CHECK_THROWS_AS(interp::LocalLinear<>(interp::LocalLinearOptions{.k = 0}), ArgumentError);
}

TEST_CASE("LocalLinear::apply's body over strided MatrixSpans (DeviceLocalLinear's accessor) equals apply, bitwise, seq and omp") {
  std::mt19937 rng(21);
  const Index n = 30, m = 25, k = 4;
  auto p = make_problem(n, m, k, rng);
  const Eigen::MatrixXd truth = random_truth(m, k, rng);
  const auto train = make_frames(p, k, truth, 60, 0.01, 0, rng);
  interp::LocalLinear<> ll(interp::LocalLinearOptions{.k = k});
  ll.fit(exec::omp, p);
  CHECK_FALSE(ll.trained());
  ll.train(exec::omp, train, {.lambda = 1e-6});
  REQUIRE(ll.trained());
  const Points<> x = train.lr(3);
  Points<> ref(m, 3);
  ll.apply(exec::seq, x, ref);
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> wide_lr(n, 4), wide_hr(m, 4);
  wide_lr.leftCols(3) = x;
  for (const bool omp : {false, true}) {
    wide_hr.setConstant(5.0);
    const interp::detail::LocalLinearRow<double> body{ll.neighbor_indices().data(), ll.vertex_maps().data(), k, {wide_lr.data(), n, 3, 4},
                                                      {wide_hr.data(), m, 3, 4}};
    if (omp)
      exec::parallel_for(exec::omp, m, body);
    else
      exec::parallel_for(exec::seq, m, body);
    CHECK(Points<>(wide_hr.leftCols(3)) == ref);
    CHECK((wide_hr.col(3).array() == 5.0).all());
  }
}
