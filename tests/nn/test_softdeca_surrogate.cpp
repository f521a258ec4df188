// SoftDECA's surrogate (nn/softdeca_surrogate.hpp) on a synthetic dataset whose skin
// displacement is a known nonlinear function of the inputs (products and a saturation that no
// linear map reproduces): it learns what ridge cannot, on samples it never saw; a saved model
// predicts the same; shapes and options are checked.
#include <simsr/nn/softdeca_surrogate.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <random>

namespace nn_test_softdeca_surrogate {

using namespace simsr;
using scenario::SoftDecaDataset;
using scenario::SoftDecaParameters;
using scenario::sample_softdeca_parameters;

/// N samples over E = 2 expressions and M skin vertices: parameters drawn by the real sampler,
/// displacement of vertex v = e_v · (w_bulge · tanh(2 g_y) + 0.5 · w_lift · (s_x − 1)(s_y − 1)·4
/// + 0.3 · (v_target − 1)²·4), e_v a fixed direction per vertex (m·1e-2).
SoftDecaDataset synthetic(Index N, Index M, std::uint64_t seed) {
  SoftDecaDataset d;
  d.parameters.resize(N, SoftDecaParameters::size);
  d.expressions.resize(N, 2);
  d.displacements.resize(N, 3 * M);
  d.rest_skin = Points<>::Random(M, 3);
  d.seconds = VecX<>::Constant(N, 1.0);
  d.parameter_names = SoftDecaParameters::names();
  d.expression_names = {"bulge", "lift"};
  d.fingerprint = "synthetic";
  std::mt19937 rng{unsigned(seed)};
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points<> dir(M, 3);
  for (Index v = 0; v < M; ++v) dir.row(v) = Vec3<>(std::cos(0.7 * double(v)), std::sin(0.7 * double(v)), 0.3).normalized().transpose();
  for (Index i = 0; i < N; ++i) {
    const SoftDecaParameters p = sample_softdeca_parameters(seed, std::uint64_t(i));
    d.parameters.row(i) = p.to_vector().transpose();
    d.expressions.row(i) << u(rng), u(rng);
    const double g_y = p.gravity * p.gravity_direction.y();
    const double a = d.expressions(i, 0) * std::tanh(2 * g_y) + 2.0 * d.expressions(i, 1) * (p.cranium_scale.x() - 1) * (p.cranium_scale.y() - 1) +
                     1.2 * (p.volume_target - 1) * (p.volume_target - 1);
    for (Index v = 0; v < M; ++v) d.displacements.row(i).segment<3>(3 * v) = 0.01 * a * (1 + 0.1 * double(v)) * dir.row(v);
  }
  return d;
}

}  // namespace nn_test_softdeca_surrogate

using namespace simsr;
using nn::SoftDecaSurrogate;
using nn::SoftDecaSurrogateReport;
using nn::train_softdeca_surrogate;
using scenario::SoftDecaDataset;

TEST_CASE("SoftDecaSurrogate learns a nonlinear parameter-to-skin map on held-out samples, beyond ridge and the mean") {
  const SoftDecaDataset data = nn_test_softdeca_surrogate::synthetic(300, 12, 3);
  SoftDecaSurrogate net(2, 12, {64, 64}, 5);
  const SoftDecaSurrogateReport r =
      train_softdeca_surrogate(exec::omp, data, {.epochs = 300, .batch = 16, .lr = 3e-3, .held_out = 0.2, .validation = 0.15, .weight_decay = 1e-3}, net);
  MESSAGE("held-out mean error " << r.held_out.mean << " m (relative " << r.held_out.relative << "); ridge " << r.ridge_baseline.mean
                                 << "; mean predictor " << r.mean_baseline.mean << "; final loss " << r.loss.back());
  CHECK(r.train_samples == 204);
  CHECK(r.validation_samples == 36);
  CHECK(r.held_out_samples == 60);
  CHECK(r.loss.size() == 300);
  CHECK(r.validation_loss.size() == 300);
  CHECK(r.loss.back() < 0.2 * r.loss.front());
  // early stopping kept the epoch of least validation loss
  CHECK(r.validation_loss[std::size_t(r.best_epoch)] == *std::min_element(r.validation_loss.begin(), r.validation_loss.end()));
  CHECK(r.mean_baseline.relative == doctest::Approx(1.0));
  CHECK(r.ridge_baseline.mean < r.mean_baseline.mean);
  // with 204 samples of 22 inputs (5 of them relevant) the network goes well beyond the best
  // linear map (this seed: 0.59 of ridge's error; 0.35 with 680 samples)
  CHECK(r.held_out.mean < 0.75 * r.ridge_baseline.mean);
  CHECK(r.held_out.relative < 0.45);
  CHECK(r.inference_seconds > 0);
  CHECK(r.solver_seconds == 1.0);
  // the validation figures are the kept weights' errors on samples 204..239, in metres
  {
    const Eigen::MatrixXd Ytr = data.displacements.topRows(240);
    const VecX<> mean = Ytr.colwise().mean().transpose();
    const auto v = nn::surrogate_errors(net.predict(exec::seq, data.parameters.middleRows(204, 36), data.expressions.middleRows(204, 36)),
                                        data.displacements.middleRows(204, 36), mean);
    CHECK(r.validation.mean == doctest::Approx(v.mean).epsilon(1e-12));
    CHECK(r.validation.max == doctest::Approx(v.max).epsilon(1e-12));
    CHECK(r.validation.relative == doctest::Approx(v.relative).epsilon(1e-12));
    CHECK(r.validation.mean > 0);
    CHECK(r.to_json()["validation_linear_base_alone"].is_null());  // no base
  }

  // the saved model predicts what the trained one does
  const auto file = std::filesystem::temp_directory_path() / "simsr_test_surrogate.npz";
  net.save(file, {{"note", "test"}});
  SoftDecaSurrogate loaded = SoftDecaSurrogate::load(file);
  const Eigen::MatrixXd a = net.predict(exec::seq, data.parameters.bottomRows(7), data.expressions.bottomRows(7));
  const Eigen::MatrixXd b = loaded.predict(exec::omp, data.parameters.bottomRows(7), data.expressions.bottomRows(7));
  CHECK(a == b);
  CHECK(loaded.hidden() == std::vector<Index>{64, 64});
  std::filesystem::remove(file);
}

TEST_CASE("SoftDecaSurrogate with a linear base: an exactly linear map before any training, the nonlinear rest learnt, the base saved" * doctest::test_suite("tsan-repeat")) {
  // exactly linear data: the base alone reproduces it (the untrained network's part is scaled
  // by the spread of what the base leaves, round-off)
  SoftDecaDataset lin = nn_test_softdeca_surrogate::synthetic(60, 5, 7);
  std::mt19937 rng{11};
  std::normal_distribution<double> n01;
  Eigen::MatrixXd W = Eigen::MatrixXd::NullaryExpr(2 + scenario::SoftDecaParameters::size, 15, [&] { return 0.01 * n01(rng); });
  W.topRows(2).setZero();  // the base is a map of the parameters, not of the expression weights
  Eigen::MatrixXd X(60, W.rows());
  X << lin.expressions, lin.parameters;
  lin.displacements = (X * W).rowwise() + Eigen::RowVectorXd::Constant(15, 0.02);
  SoftDecaSurrogate base_only(2, 5, {8}, 3);
  base_only.fit_normalization(X, lin.displacements);
  base_only.fit_linear_base(X, lin.displacements, 1e-12);
  CHECK(base_only.linear_base().rows() == W.rows() + 1);
  CHECK(base_only.linear_base().middleRows(1, 2).isZero(0));
  const Eigen::MatrixXd p = base_only.predict(exec::seq, lin.parameters, lin.expressions);
  CHECK((p - lin.displacements).cwiseAbs().maxCoeff() < 1e-9);
  CHECK_THROWS_AS(base_only.fit_linear_base(X, lin.displacements, 0), ArgumentError);
  CHECK_THROWS_AS(base_only.fit_linear_base(X.leftCols(5), lin.displacements, 1e-3), ShapeError);

  // the nonlinear synthetic data plus a strong linear trend in the skull's scaling: the base
  // takes the trend, the network what no linear map can; better than ridge on unseen samples
  SoftDecaDataset data = nn_test_softdeca_surrogate::synthetic(300, 12, 3);
  for (Index i = 0; i < data.size(); ++i)
    for (Index v = 0; v < 12; ++v) data.displacements(i, 3 * v + 1) += 0.05 * (data.parameters(i, 13) - 1) * (1 + 0.2 * double(v));
  SoftDecaSurrogate net(2, 12, {64, 64}, 5);
  const SoftDecaSurrogateReport r = train_softdeca_surrogate(
      exec::omp, data, {.epochs = 300, .batch = 16, .lr = 3e-3, .held_out = 0.2, .validation = 0.15, .weight_decay = 1e-3, .linear_base = true}, net);
  MESSAGE("with a linear base: held-out mean error " << r.held_out.mean << " m (relative " << r.held_out.relative << "); the base alone "
                                                      << r.base_alone.mean << "; ridge " << r.ridge_baseline.mean << "; mean predictor " << r.mean_baseline.mean);
  CHECK(net.linear_base().cols() == 36);
  CHECK(r.base_lambda > 0);
  CHECK(r.held_out.mean < r.base_alone.mean);  // the network adds what the linear map cannot
  CHECK(r.held_out.mean < 0.85 * r.ridge_baseline.mean);  // this seed: 0.73 of ridge's error
  // on the validation samples too, in metres: the base alone against base + network
  {
    Eigen::MatrixXd Xv(36, W.rows());
    Xv << data.expressions.middleRows(204, 36), data.parameters.middleRows(204, 36);
    const VecX<> mean = data.displacements.topRows(240).colwise().mean().transpose();
    const auto b = nn::surrogate_errors(net.with_intercept(Xv) * net.linear_base(), data.displacements.middleRows(204, 36), mean);
    CHECK(r.validation_base_alone.mean == doctest::Approx(b.mean).epsilon(1e-12));
    CHECK(r.validation.mean < r.validation_base_alone.mean);
    CHECK(r.to_json()["validation_linear_base_alone"]["mean_m"].get<double>() == r.validation_base_alone.mean);
  }
  const auto file = std::filesystem::temp_directory_path() / "simsr_test_surrogate_base.npz";
  net.save(file);
  SoftDecaSurrogate loaded = SoftDecaSurrogate::load(file);
  CHECK(loaded.linear_base() == net.linear_base());
  CHECK(loaded.predict(exec::omp, data.parameters, data.expressions) == net.predict(exec::seq, data.parameters, data.expressions));
  std::filesystem::remove(file);
}

TEST_CASE("SoftDecaSurrogate: shapes, options and files are checked") {
  const SoftDecaDataset data = nn_test_softdeca_surrogate::synthetic(20, 4, 1);
  SoftDecaSurrogate other(3, 4, {8}, 1);  // 3 expressions, the data has 2
  CHECK_THROWS_AS(train_softdeca_surrogate(exec::seq, data, {}, other), ShapeError);
  SoftDecaSurrogate net(2, 4, {8}, 1);
  CHECK_THROWS_AS(train_softdeca_surrogate(exec::seq, data, {.held_out = 0}, net), ArgumentError);
  CHECK_THROWS_AS(train_softdeca_surrogate(exec::seq, data, {.held_out = 0.95}, net), ArgumentError);  // 1 left to train on
  CHECK_THROWS_AS(SoftDecaSurrogate(2, 4, {}, 1), ArgumentError);
  CHECK_THROWS_AS(net.predict(exec::seq, data.parameters.leftCols(19), data.expressions), ShapeError);
  Eigen::MatrixXd bad = data.parameters;
  bad(0, 3) = std::nan("");
  CHECK_THROWS_AS(net.predict(exec::seq, bad, data.expressions), ArgumentError);
  const auto file = std::filesystem::temp_directory_path() / "simsr_test_not_a_surrogate.npz";
  io::NpzArrays z;
  z["x"] = io::make_npy(VecX<>::Zero(3));
  io::write_npz(file, z);
  CHECK_THROWS_AS(SoftDecaSurrogate::load(file), Error);
  std::filesystem::remove(file);
}
