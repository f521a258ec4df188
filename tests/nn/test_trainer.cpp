#include "gradient_check.hpp"
#include "network_fixture.hpp"

#include <simsr/nn/trainer.hpp>

#include <filesystem>

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

std::vector<double> train_values(const Toy& toy, Index epochs, std::uint64_t seed, bool omp) {
  nn::Rng init(7);
  nn::SuperResolutionNet<double> net(toy.cfg, toy.geo, init);
  nn::Trainer<double> tr(net, toy.faces, toy.frames, {.epochs = epochs, .seed = seed, .progress = false, .on_epoch = {}});
  if (omp)
    tr.run(exec::omp);
  else
    tr.run(exec::seq);
  const auto v = net.store().values();
  const auto b = net.store().buffers();
  std::vector<double> out(v.data(), v.data() + v.size());
  out.insert(out.end(), b.data(), b.data() + b.size());
  return out;
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
  nn::Trainer<double> tr(net, toy.faces, toy.frames, {.epochs = 4, .seed = 0, .progress = false, .on_epoch = {}});
  tr.load_checkpoint(dir / "ckpt.npz");
  CHECK(tr.epoch() == 2);
  CHECK(tr.steps() == 6);
  tr.run(exec::omp);
  const auto v = net.store().values();
  const auto b = net.store().buffers();
  std::vector<double> resumed(v.data(), v.data() + v.size());
  resumed.insert(resumed.end(), b.data(), b.data() + b.size());
  CHECK(resumed == a);
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
