#include "gradient_check.hpp"
#include "network_fixture.hpp"

#include <simsr/nn/trainer.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

using namespace simsr;
using nn::Matrix;

namespace {

/// A learnable toy problem: HR displacements are a fixed smooth function of the LR ones
/// (each HR vertex follows the mean of its upsampling neighbours, scaled), F frames.
struct Toy {
  nn::NetworkConfig cfg;
  nn::NetworkGeometry geo;
  Tris faces;
  nn::TrainingFrames<double> frames;
};

Toy make_toy(std::uint64_t seed, Index F = 10) {
  Toy t;
  t.cfg = test::tiny_config(nn::NetworkConfig::official());
  t.cfg.batch_size = 4;
  t.cfg.lr = 3e-3;
  std::mt19937_64 rng(seed);
  t.geo = test::small_network_geometry(rng, 20, 24, t.cfg);
  t.faces.resize(16, 3);
  std::uniform_int_distribution<int> pick(0, 23);
  for (Index f = 0; f < t.faces.rows(); ++f) {
    t.faces(f, 0) = pick(rng);
    do t.faces(f, 1) = pick(rng);
    while (t.faces(f, 1) == t.faces(f, 0));
    do t.faces(f, 2) = pick(rng);
    while (t.faces(f, 2) == t.faces(f, 0) || t.faces(f, 2) == t.faces(f, 1));
  }
  auto& d = t.frames;
  d.n = 20;
  d.m = 24;
  d.frames = F;
  d.ldx = test::random_matrix(rng, F * d.n, 3, -0.3, 0.3);
  d.hdx.resize(F * d.m, 3);
  for (Index f = 0; f < F; ++f)
    for (Index j = 0; j < d.m; ++j) {
      Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
      for (Index i = 0; i < 3; ++i) s += d.ldx.row(f * d.n + t.geo.up_indices(j, i));
      d.hdx.row(f * d.m + j) = 0.5 * s;
    }
  for (Index f = 0; f < F; ++f) d.ids.push_back(f);
  return t;
}

/// Every weight and buffer of `net`, flat.
std::vector<double> trainer_state(const nn::SuperResolutionNet<double>& net) {
  const auto v = net.store().values();
  const auto b = net.store().buffers();
  std::vector<double> out(v.data(), v.data() + v.size());
  out.insert(out.end(), b.data(), b.data() + b.size());
  return out;
}

std::vector<double> train_values(const Toy& toy, Index epochs, std::uint64_t seed, bool omp) {
  nn::Rng init(7);
  nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
  nn::Trainer<double> tr(net, toy.faces, toy.frames, {.epochs = epochs, .seed = seed, .progress = false, .on_epoch = {}});
  if (omp)
    tr.run(exec::omp);
  else
    tr.run(exec::seq);
  return trainer_state(net);
}

}  // namespace

TEST_CASE("nn::Trainer: the loss falls on a learnable toy problem; held-out error is reported in raw units") {
  const Toy toy = make_toy(1);
  nn::Rng init(3);
  nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
  nn::Trainer<double> tr(net, toy.faces, toy.frames, {.epochs = 60, .seed = 5, .progress = false, .on_epoch = {}});
  tr.set_holdout(toy.frames);
  const double before = tr.holdout_error(exec::seq);
  tr.run(exec::omp);
  REQUIRE(tr.history().size() == 60);
  CHECK(tr.steps() == 60 * 3);  // 10 frames, batches of 4: 4 + 4 + 2
  CHECK(tr.history().back().recon < 0.5 * tr.history().front().recon);
  CHECK(tr.history().back().holdout_mean_error < 0.7 * before);
  CHECK(tr.history().back().holdout_mean_error == doctest::Approx(tr.holdout_error(exec::seq)).epsilon(1e-12));
}

TEST_CASE("nn::Trainer: a seed fixes the run, seq == omp bitwise, and a checkpoint resumes to the identical continuation") {
  const Toy toy = make_toy(2);
  const auto a = train_values(toy, 4, 11, false);
  CHECK(a == train_values(toy, 4, 11, true));
  CHECK(a != train_values(toy, 4, 12, false));

  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "trainer";
  std::filesystem::create_directories(dir);
  nn::ModelData md;
  md.config = toy.cfg;
  md.geometry = toy.geo;
  md.lr_tets = Tets::Zero(1, 4);
  md.lr_tets.row(0) << 0, 1, 2, 3;
  md.hr_faces = toy.faces;
  {
    nn::Rng init(7);
    nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
    nn::Trainer<double> tr(net, toy.faces, toy.frames, {.epochs = 4, .seed = 11, .progress = false, .on_epoch = {}});
    tr.run_epoch(exec::seq);
    tr.run_epoch(exec::seq);
    tr.save_checkpoint(dir / "ckpt.npz", md);
  }
  nn::Rng other(99);  // different initial weights: the checkpoint must overwrite them all
  nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, other);
  nn::Trainer<double> tr(net, toy.faces, toy.frames, {.epochs = 4, .seed = 11, .progress = false, .on_epoch = {}});
  tr.load_checkpoint(dir / "ckpt.npz");
  CHECK(tr.epoch() == 2);
  CHECK(tr.steps() == 6);
  tr.run(exec::omp);
  CHECK(trainer_state(net) == a);
  // the checkpoint is also a model file
  const auto data = nn::read_model_data(dir / "ckpt.npz");
  CHECK(data.geometry.up_indices == toy.geo.up_indices);
  nn::Rng r3(1);
  nn::SuperResolutionNet<double> net3(data.config, data.geometry, r3);
  nn::load_state(net3.store(), nn::read_model_arrays(dir / "ckpt.npz"));
}

TEST_CASE("nn::Trainer and the model file: bad input is rejected with what and where") {
  const Toy toy = make_toy(3);
  nn::Rng init(7);
  nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
  nn::TrainingFrames<double> empty = toy.frames;
  empty.frames = 0;
  CHECK_THROWS_AS(nn::Trainer<double>(net, toy.faces, empty, {}), ArgumentError);
  nn::TrainingFrames<double> wrong = toy.frames;
  wrong.n = 19;
  CHECK_THROWS_AS(nn::Trainer<double>(net, toy.faces, wrong, {}), ShapeError);
  // load_state: a missing tensor, a wrong shape, a stray tensor, a NaN
  io::NpzArrays a;
  nn::add_state(a, net.store());
  {
    io::NpzArrays b = a;
    b.at("net_upscale.conv_weights.0.weight").shape = {1, 2};
    CHECK_THROWS_WITH_AS(nn::load_state(net.store(), b), doctest::Contains("net_upscale.conv_weights.0.weight"), ArgumentError);
  }
  {
    io::NpzArrays b = a;
    const float x = 1;
    b["net_decoder.extra.weight"] = io::make_npy<float>({1}, &x);
    CHECK_THROWS_WITH_AS(nn::load_state(net.store(), b), doctest::Contains("net_decoder.extra.weight"), ArgumentError);
  }
  {
    io::NpzArrays b;
    for (const auto& [name, arr] : a)
      if (name != "net_decoder.decoder.last_layer.fc.bias") b[name] = arr;
    CHECK_THROWS_WITH_AS(nn::load_state(net.store(), b), doctest::Contains("last_layer.fc.bias"), ArgumentError);
  }
  {
    io::NpzArrays b = a;
    auto& arr = b.at("net_decoder.decoder.last_layer.fc.bias");
    const double nan = std::numeric_limits<double>::quiet_NaN();  // a double network stores float64
    REQUIRE(arr.dtype.itemsize == 8);
    std::memcpy(arr.bytes.data(), &nan, sizeof(double));
    CHECK_THROWS_WITH_AS(nn::load_state(net.store(), b), doctest::Contains("not finite"), ArgumentError);
  }
}

namespace {

nn::ModelData toy_model_data(const Toy& toy) {
  nn::ModelData md;
  md.config = toy.cfg;
  md.geometry = toy.geo;
  md.lr_tets = Tets::Zero(1, 4);
  md.lr_tets.row(0) << 0, 1, 2, 3;
  md.hr_faces = toy.faces;
  return md;
}

}  // namespace

TEST_CASE("nn::Trainer: a non-finite loss stops training before the optimizer moves anything, naming the step") {
  Toy toy = make_toy(4);
  toy.frames.hdx(5 * toy.frames.m + 3, 1) = std::numeric_limits<double>::quiet_NaN();  // frame 5
  nn::Rng init(7);
  nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
  nn::Trainer<double> tr(net, toy.faces, toy.frames, {.epochs = 2, .seed = 1, .progress = false, .on_epoch = {}});
  const auto before = trainer_state(net);
  try {
    tr.run(exec::seq);
    FAIL("a NaN target trained without error");
  } catch (const NumericalError& e) {
    CHECK(e.tensor() == "the loss");
    CHECK(e.step() >= 1);
    CHECK(e.step() == tr.steps() + 1);  // the step that was refused
    CHECK(std::string(e.what()).find("step " + std::to_string(e.step())) != std::string::npos);
  }
  if (tr.steps() == 0) CHECK(trainer_state(net) == before);  // NaN in the first batch: nothing moved
}

TEST_CASE("nn::Trainer: weights the optimizer makes non-finite stop training at that step, and no model file holds them") {
  // float network, lr beyond float's range: Adam's first step sends every weight to ±inf
  Toy toy = make_toy(5);
  nn::Rng init(7);
  nn::NetworkGeometry geo = toy.geo;
  nn::SuperResolutionNet<float> net(toy.cfg, geo, init);
  nn::TrainingFrames<float> frames;
  frames.n = toy.frames.n, frames.m = toy.frames.m, frames.frames = toy.frames.frames, frames.ids = toy.frames.ids;
  frames.ldx = toy.frames.ldx.cast<float>();
  frames.hdx = toy.frames.hdx.cast<float>();
  nn::Trainer<float> tr(net, toy.faces, frames, {.epochs = 1, .lr = 1e39, .seed = 1, .progress = false, .on_epoch = {}});
  try {
    tr.run(exec::seq);
    FAIL("training with lr = 1e39 in float gave finite weights");
  } catch (const NumericalError& e) {
    CHECK(e.step() == 1);
    CHECK(std::string(e.tensor()).find("the weight of '") == 0);
  }
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "trainer_nonfinite";
  std::filesystem::create_directories(dir);
  std::filesystem::remove(dir / "model.npz");
  const Toy& t = toy;
  CHECK_THROWS_AS(nn::save_model(dir / "model.npz", net, toy_model_data(t)), NumericalError);
  CHECK(!std::filesystem::exists(dir / "model.npz"));
  CHECK_THROWS_AS(tr.save_checkpoint(dir / "model.npz", toy_model_data(t)), NumericalError);
  CHECK(!std::filesystem::exists(dir / "model.npz"));
}

TEST_CASE("nn: the finite guards name the tensor, the entry and the step") {
  nn::ParameterStore<double> store;
  const Index w = store.add_parameter("block.weight", {2, 3});
  store.add_buffer("block.running_var", {3}, 1.0);
  CHECK_NOTHROW(nn::require_finite_state("here", store, 4));
  store.gradient(w, 2, 3)(1, 2) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH_AS(nn::require_finite_gradients("here", store, 4), "here: the gradient of 'block.weight' (entry 5) is not finite (inf) at step 4",
                       NumericalError);
  store.buffers()[1] = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH_AS(nn::require_finite_buffers("here", store, 9), doctest::Contains("the buffer of 'block.running_var' (entry 1)"), NumericalError);
  CHECK_THROWS_AS(nn::require_finite_loss("here", std::nan(""), 2), NumericalError);
}

TEST_CASE("nn::Trainer: a non-finite held-out error is an error, not a number in the history") {
  Toy toy = make_toy(6);
  nn::Rng init(7);
  nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
  nn::Trainer<double> tr(net, toy.faces, toy.frames, {.epochs = 1, .seed = 1, .progress = false, .on_epoch = {}});
  nn::TrainingFrames<double> held = toy.frames;
  held.hdx(2, 0) = std::numeric_limits<double>::infinity();
  tr.set_holdout(held);
  CHECK_THROWS_WITH_AS(tr.run(exec::seq), doctest::Contains("the held-out mean error"), NumericalError);
}

TEST_CASE("nn::Trainer: a checkpoint written before the first step resumes to the same run; another run's checkpoint is refused, naming what differs") {
  const Toy toy = make_toy(7);
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "trainer_resume";
  std::filesystem::create_directories(dir);
  const nn::TrainerOptions opts{.epochs = 3, .seed = 21, .progress = false, .on_epoch = {}};
  std::vector<double> straight;
  {
    nn::Rng init(7);
    nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
    nn::Trainer<double> tr(net, toy.faces, toy.frames, opts);
    tr.save_checkpoint(dir / "step0.npz", toy_model_data(toy));  // before any step
    tr.run(exec::seq);
    straight = trainer_state(net);
  }
  {
    nn::Rng other(1234);
    nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, other);
    nn::Trainer<double> tr(net, toy.faces, toy.frames, opts);
    tr.load_checkpoint(dir / "step0.npz");
    CHECK(tr.epoch() == 0);
    CHECK(tr.steps() == 0);
    tr.run(exec::seq);
    CHECK(trainer_state(net) == straight);
  }
  auto refused = [&](const Toy& t, const nn::TrainerOptions& o, const std::string& what) {
    nn::Rng init(7);
    nn::SuperResolutionNet<double> net(t.cfg, t.geo, init);
    nn::Trainer<double> tr(net, t.faces, t.frames, o);
    const auto before = trainer_state(net);
    CHECK_THROWS_WITH_AS(tr.load_checkpoint(dir / "step0.npz"), doctest::Contains(what.c_str()), ArgumentError);
    CHECK(trainer_state(net) == before);  // nothing loaded
    CHECK(tr.epoch() == 0);
  };
  nn::TrainerOptions o = opts;
  o.batch_size = 3;
  refused(toy, o, "options differ: batch_size (checkpoint 4, this run 3)");
  o = opts;
  o.seed = 22;
  refused(toy, o, "seed (checkpoint 21, this run 22)");
  o = opts;
  o.epochs = 5;  // the official loss has no run-length schedule: training longer is a continuation
  {
    nn::Rng init(7);
    nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
    nn::Trainer<double> tr(net, toy.faces, toy.frames, o);
    CHECK_NOTHROW(tr.load_checkpoint(dir / "step0.npz"));
  }
  {  // the paper's ramped latent norm spans the whole run: there the epochs must match
    Toy ramped = toy;
    ramped.cfg.zreg = nn::LatentRegularizer::ramped_norm;
    nn::Rng init(7);
    nn::SuperResolutionNet<double> net(ramped.cfg, ramped.geo, init);
    nn::Trainer<double> tr(net, ramped.faces, ramped.frames, opts);
    tr.save_checkpoint(dir / "ramped.npz", toy_model_data(ramped));
    nn::Trainer<double> longer(net, ramped.faces, ramped.frames, o);
    CHECK_THROWS_WITH_AS(longer.load_checkpoint(dir / "ramped.npz"), doctest::Contains("epochs (checkpoint 3, this run 5)"), ArgumentError);
  }
  Toy other_data = toy;
  other_data.frames.hdx(0, 0) += 1e-9;
  refused(other_data, opts, "data differ: training_fingerprint");
  Toy fewer = make_toy(7, 9);
  refused(fewer, opts, "training_frames (checkpoint 10, this run 9)");
  Toy other_cfg = toy;
  other_cfg.cfg.dropout = 0.25;
  refused(other_cfg, opts, "config differ: dropout");
  {  // held-out frames are part of the data too
    nn::Rng init(7);
    nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
    nn::Trainer<double> tr(net, toy.faces, toy.frames, opts);
    tr.set_holdout(toy.frames);
    CHECK_THROWS_WITH_AS(tr.load_checkpoint(dir / "step0.npz"), doctest::Contains("holdout_frames (checkpoint 0, this run 10)"), ArgumentError);
  }
  {  // a model file is not a checkpoint
    nn::Rng init(7);
    nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
    nn::save_model(dir / "model.npz", net, toy_model_data(toy));
    nn::Trainer<double> tr(net, toy.faces, toy.frames, opts);
    CHECK_THROWS_WITH_AS(tr.load_checkpoint(dir / "model.npz"), doctest::Contains("not a training checkpoint"), ArgumentError);
  }
}
