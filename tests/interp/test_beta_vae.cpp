// interp::BetaVaeBaseline: the A.4 β-VAE as a TrainableInterpolator (moved from the tool).
#include <simsr/interp/beta_vae.hpp>
#include <simsr/mesh/generators.hpp>

#include <doctest/doctest.h>

#include <random>

using namespace simsr;

namespace {

/// Small rest shapes and F frames of displacements from a 2-parameter linear family (+ noise).
struct VaeScene {
  interp::UpsamplingProblem<> problem;
  data::PairedFrames<> frames;
};

VaeScene vae_scene(Index f, unsigned seed) {
  VaeScene s;
  s.problem.lr = box_tet_mesh<double>(2, 2, 2);
  s.problem.hr = icosphere<double>(1, 0.4);
  const Index n = s.problem.num_lr(), m = s.problem.num_hr();
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const Eigen::MatrixXd bl = Eigen::MatrixXd::Random(2, 3 * n) * 0.01, bh = Eigen::MatrixXd::Random(2, 3 * m) * 0.01;
  s.frames.lowres.resize(f, 3 * n);
  s.frames.highres.resize(f, 3 * m);
  s.frames.controls.resize(f, 0);
  for (Index i = 0; i < f; ++i) {
    const Eigen::RowVector2d c(g(rng), g(rng));
    s.frames.lowres.row(i) = c * bl;
    s.frames.highres.row(i) = c * bh;
    s.frames.ids.push_back(i);
  }
  return s;
}

/// A.4's layout at a fraction of its widths: the tests train this one (A.4's 1024–4096 widths
/// make each step cost seconds under the sanitizers); misuse below uses the default.
nn::BetaVae<float>::Config small_network() {
  return {.encoder_hidden = {64, 32}, .latent = 8, .decoder_hidden = {16, 64, 128}, .beta = 0.01, .slope = 0.2};
}

}  // namespace

TEST_CASE("β-VAE baseline: seq and omp train the same model; the loss falls; s is the pooled RMS") {
  auto s = vae_scene(24, 1);
  interp::BetaVaeBaseline<> a, b;
  a.fit(exec::seq, s.problem);
  b.fit(exec::omp, s.problem);
  const interp::BetaVaeTrainOptions o{.epochs = 6, .batch_size = 8, .lr = 1e-3, .network = small_network(), .seed = 7, .on_epoch = {}};
  a.train(exec::seq, s.frames, o);
  b.train(exec::omp, s.frames, o);
  const double rms = std::sqrt((s.frames.lowres.squaredNorm() + s.frames.highres.squaredNorm()) /
                               double(s.frames.lowres.size() + s.frames.highres.size()));
  CHECK(a.scale() == doctest::Approx(rms).epsilon(1e-12));
  REQUIRE(a.history().size() == 6);
  CHECK(a.history().back().loss < a.history().front().loss);
  Points<> out_a(s.problem.num_hr(), 3), out_b(s.problem.num_hr(), 3);
  for (Index f = 0; f < 4; ++f) {
    const Points<> in = s.frames.lr(f);
    a.apply(exec::seq, in, out_a);
    b.apply(exec::omp, in, out_b);
    CHECK(out_a == out_b);  // bitwise: the kernels do not depend on the policy
  }
  // the options' network is the one trained
  nn::ParameterStore<float> store;
  nn::Rng rng(0);
  const nn::BetaVae<float> direct(store, s.problem.num_lr(), s.problem.num_hr(), rng, small_network());
  CHECK(a.num_parameters() == direct.num_parameters());
}

TEST_CASE("β-VAE baseline: misuse and bad data are typed errors naming what") {
  auto s = vae_scene(8, 2);
  interp::BetaVaeBaseline<> v;
  Points<> in(s.problem.num_lr(), 3), out(s.problem.num_hr(), 3);
  in.setZero();
  CHECK_THROWS_WITH_AS(v.train(exec::seq, s.frames, {}), doctest::Contains("before fit"), ArgumentError);
  v.fit(exec::seq, s.problem);
  CHECK_THROWS_WITH_AS(v.apply(exec::seq, in, out), doctest::Contains("before train"), ArgumentError);
  auto bad = s.frames;
  bad.lowres(3, 5) = std::nan("");
  CHECK_THROWS_WITH_AS(v.train(exec::seq, bad, {.epochs = 1, .on_epoch = {}}), doctest::Contains("LR displacement of frame 3, vertex 1"), ArgumentError);
  v.train(exec::seq, s.frames, {.epochs = 1, .on_epoch = {}});  // A.4's network
  CHECK(v.num_parameters() > 1000000);
  Points<> wrong(s.problem.num_lr() + 1, 3);
  CHECK_THROWS_AS(v.apply(exec::seq, wrong, out), ShapeError);
  in(4, 2) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH_AS(v.apply(exec::seq, in, out), doctest::Contains("vertex 4"), ArgumentError);
  in(4, 2) = 1e300;  // finite, but beyond float32 after normalization
  CHECK_THROWS_WITH_AS(v.apply(exec::seq, in, out), doctest::Contains("float32"), ArgumentError);
}

TEST_CASE("β-VAE baseline: a diverging run stops at the step and tensor that went non-finite, before Adam moves it") {
  auto s = vae_scene(8, 3);
  interp::BetaVaeBaseline<> v;
  v.fit(exec::seq, s.problem);
  bool named = false;
  try {
    v.train(exec::seq, s.frames, {.epochs = 50, .lr = 1e30, .network = small_network(), .on_epoch = {}});
  } catch (const NumericalError& e) {
    named = e.step() >= 1 && !e.tensor().empty();
    MESSAGE("diverging β-VAE: " << std::string(e.what()));
  }
  CHECK(named);
}
