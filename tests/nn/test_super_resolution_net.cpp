#include "gradient_check.hpp"
#include "network_fixture.hpp"

#include <simsr/nn/super_resolution_net.hpp>

#include <map>
#include <set>

using namespace simsr;
using nn::Matrix;

namespace {

/// Parameters the forward never reads (official fc_initial and the dead SIREN layer).
bool unused_parameter(const nn::NetworkConfig& cfg, const std::string& name) {
  const std::string dead = "net_decoder.decoder.layers." + std::to_string(cfg.decoder_dims.size() - 2) + ".fc.";
  return name.find("fc_initial") != std::string::npos || (cfg.decoder_dead_layer && name.rfind(dead, 0) == 0);
}

/// The bias of f_θ's last layer shifts every logit of a row alike: the softmax ignores it, so its
/// exact gradient is 0 (FD and backward both give rounding noise).
bool softmax_invariant(const nn::NetworkConfig& cfg, const std::string& name) {
  const std::size_t stages = cfg.up_hidden.size() * (cfg.up_batch_norm ? 3 : 2);
  return cfg.upsampling == nn::UpsamplingKind::mlp && name == "net_upscale.conv_weights." + std::to_string(stages) + ".bias";
}

/// FD check of every trainable tensor of `net` under a random linear functional of the output,
/// plus an extra code gradient (exercises backward's d_code path).
void check_net_gradients(const nn::NetworkConfig& cfg, Index B, double tol, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const auto geo = test::small_network_geometry(rng, 24, 30, cfg);
  nn::Rng init(seed + 1);
  nn::SuperResolutionNet<double> net(cfg, geo, init);
  const Matrix<double> ldx = test::random_matrix(rng, B * net.lr_points(), 3, -0.5, 0.5);
  if (cfg.residual) {
    // A fresh residual network is exactly the embedding (zero output layer)...
    Matrix<double> pred;
    net.forward(exec::seq, nn::Mode::eval, ldx, pred);
    for (Index b = 0; b < B; ++b) {
      const Matrix<double> e = geo.embedding * ldx.middleRows(b * net.lr_points(), net.lr_points());
      CHECK((pred.middleRows(b * net.hr_points(), net.hr_points()) - e).cwiseAbs().maxCoeff() < 1e-15);
    }
    // ...whose hidden layers get no gradient yet: randomize the output layer for a meaningful check.
    for (const char* n : {"net_decoder.decoder.last_layer.fc.weight", "net_decoder.decoder.last_layer.fc.bias"})
      for (double& v : net.store().values(net.store().at(n))) v = std::uniform_real_distribution<double>(-0.5, 0.5)(rng);
  }
  const Matrix<double> zw = test::random_matrix(rng, B * net.lr_points(), net.latent_dim());
  auto& store = net.store();
  // loss = Σ r⊙pred + Σ zw⊙z: d_pred = r, d_code = zw.
  auto errors = test::gradient_check(
      ldx, &store, [&](const Matrix<double>& x, Matrix<double>& out) {
        net.forward(exec::seq, nn::Mode::train, x, out);
        // append the code term as extra columns of the "output": out' = [pred | z] flattened
        Matrix<double> both(out.size() + net.code().size(), 1);
        both.topRows(out.size()) = Eigen::Map<const Eigen::VectorXd>(out.data(), out.size());
        both.bottomRows(net.code().size()) = Eigen::Map<const Eigen::VectorXd>(net.code().data(), net.code().size());
        out = both;
      },
      [&](const Matrix<double>&, const Matrix<double>& out, const Matrix<double>& r, Matrix<double>*) {
        const Index P = out.size() - net.code().size();
        const Matrix<double> d_pred = Eigen::Map<const Matrix<double>>(r.data(), P / 3, 3);
        const Matrix<double> d_code = Eigen::Map<const Matrix<double>>(r.data() + P, net.code().rows(), net.code().cols());
        net.backward(exec::seq, d_pred, &d_code);
      },
      rng, false);
  REQUIRE(errors.size() > 5);
  for (const auto& e : errors) {
    INFO(cfg.profile << ": " << e.what << " relative error " << e.rel_error << ", scale " << e.scale);
    if (softmax_invariant(cfg, e.what)) {
      CHECK(e.scale < 1e-12);
      continue;
    }
    CHECK(e.rel_error < tol);
    if (unused_parameter(cfg, e.what))
      CHECK(e.scale == 0);
    else
      CHECK(e.scale > 0);
  }
}

}  // namespace

TEST_CASE("nn::SuperResolutionNet official: 706,871 parameters under the official state-dict names, in PyTorch's order") {
  std::mt19937_64 rng(3);
  const auto cfg = nn::NetworkConfig::official();
  const auto geo = test::small_network_geometry(rng, 40, 50, cfg);
  nn::Rng init(1);
  nn::SuperResolutionNet<float> net(cfg, geo, init);
  CHECK(net.store().num_parameters() == 706871);
  const auto& e = net.store().entries();
  REQUIRE(e.size() > 10);
  CHECK(e.front().name == "net_feat_emb.blocks.0.edge_conv.0.weight");
  CHECK(e.front().shape == std::vector<Index>{128, 70, 1, 1});
  CHECK(net.store().at("net_feat_emb.blocks.1.fc_out.0.weight").shape == std::vector<Index>{384, 448, 1});
  CHECK(net.store().at("net_feat_emb.blocks.1.fc_out.9.weight").shape == std::vector<Index>{128, 128, 1});
  CHECK(net.store().at("net_feat_emb.fc_initial.2.bias").shape == std::vector<Index>{32});
  CHECK(net.store().at("net_upscale.conv_weights.0.weight").shape == std::vector<Index>{128, 7, 1, 1});
  CHECK(net.store().at("net_upscale.conv_weights.22.num_batches_tracked").shape.empty());
  CHECK(net.store().at("net_upscale.conv_weights.24.bias").shape == std::vector<Index>{1});
  CHECK(net.store().at("net_decoder.decoder.layers.0.fc.weight").shape == std::vector<Index>{256, 227});
  CHECK(net.store().at("net_decoder.decoder.layers.5.fc.weight").shape == std::vector<Index>{3, 16});
  CHECK(e.back().name == "net_decoder.decoder.last_layer.fc.bias");
  // module order: every net_feat_emb entry before net_upscale before net_decoder
  int phase = 0;
  for (const auto& x : e) {
    const int p = x.name.rfind("net_feat_emb", 0) == 0 ? 0 : x.name.rfind("net_upscale", 0) == 0 ? 1 : 2;
    CHECK(p >= phase);
    phase = p;
  }
  // SIREN init bounds (first layer U(±1/227), later U(±√(6/fan_in)))
  const auto& s = net.store();
  auto maxabs = [&](const std::string& n) {
    const auto v = s.values(s.at(n));
    double m = 0;
    for (float x : v) m = std::max(m, double(std::abs(x)));
    return m;
  };
  CHECK(maxabs("net_decoder.decoder.layers.0.fc.weight") <= 1.0 / 227);
  CHECK(maxabs("net_decoder.decoder.layers.0.fc.weight") > 0.9 / 227);
  CHECK(maxabs("net_decoder.decoder.layers.1.fc.weight") <= std::sqrt(6.0 / 256));
  CHECK(maxabs("net_decoder.decoder.layers.1.fc.weight") > 0.9 * std::sqrt(6.0 / 256));
}

// exec::seq throughout: the TSan build leaves it out (tests/CMakeLists.txt, "single-threaded");
// the next case checks omp against seq bitwise.
TEST_CASE("nn::SuperResolutionNet: whole-network gradients match finite differences (official, paper, ablations)" *
          doctest::test_suite("single-threaded")) {
  nn::NetworkConfig cfg = test::tiny_config(nn::NetworkConfig::official());
  SUBCASE("official, B = 2") { check_net_gradients(cfg, 2, 2e-5, 11); }
  SUBCASE("paper, B = 1") { check_net_gradients(test::tiny_config(nn::NetworkConfig::paper()), 1, 2e-5, 12); }
  SUBCASE("w/o FE") {
    cfg.disable_feature_embedding();
    check_net_gradients(cfg, 2, 2e-5, 13);
  }
  SUBCASE("w/o CU (table of logits)") {
    cfg.upsampling = nn::UpsamplingKind::table;
    check_net_gradients(cfg, 2, 2e-5, 14);
  }
  SUBCASE("residual over the embedding") {
    cfg.residual = true;
    check_net_gradients(cfg, 2, 2e-5, 15);
  }
}

TEST_CASE("nn::SuperResolutionNet: seq == omp bitwise; infer (precomputed sparse upsampling) == eval forward") {
  std::mt19937_64 rng(5);
  const nn::NetworkConfig cfg = test::tiny_config(nn::NetworkConfig::official());
  const auto geo = test::small_network_geometry(rng, 60, 70, cfg);
  nn::Rng init(2);
  nn::SuperResolutionNet<float> net(cfg, geo, init);
  const Matrix<float> ldx = test::random_matrix(rng, 3 * 60, 3, -0.5, 0.5).cast<float>();
  const Matrix<float> r = test::random_matrix(rng, 3 * 70, 3).cast<float>();
  const nn::Vector<float> buffers0 = net.store().buffers();
  Matrix<float> p1, p2;
  net.store().zero_grad();
  net.forward(exec::seq, nn::Mode::train, ldx, p1);
  net.backward(exec::seq, r, nullptr);
  const nn::Vector<float> g1 = net.store().gradients(), b1 = net.store().buffers();
  net.store().zero_grad();
  net.store().buffers() = buffers0;
  net.forward(exec::omp, nn::Mode::train, ldx, p2);
  net.backward(exec::omp, r, nullptr);
  CHECK(test::bitwise_equal(p1, p2));
  CHECK(test::bitwise_equal(g1, nn::Vector<float>(net.store().gradients())));
  CHECK(test::bitwise_equal(b1, nn::Vector<float>(net.store().buffers())));

  Matrix<float> pe, pi, pi2;
  net.forward(exec::seq, nn::Mode::eval, ldx, pe);
  net.prepare_inference(exec::omp);
  net.set_decoder_first_layer_on_lr(false);  // the unsplit decoder: the eval forward's very sums (the next case splits it)
  net.infer(exec::omp, ldx, pi);
  CHECK(test::bitwise_equal(pe, pi));
  // the sparse M×N matrix is the same operator
  const auto W = net.upsampling().sparse_matrix();
  CHECK(W.rows() == 70);
  CHECK(W.cols() == 60);
  const Matrix<float> zH = W * net.code().topRows(60);
  CHECK((zH - net.hr_code().topRows(70)).cwiseAbs().maxCoeff() < 1e-5f);
  // warm inference allocates nothing
  net.infer(exec::omp, ldx, pi2);
  const long before = simsr_test_malloc_count();
  net.infer(exec::omp, ldx, pi2);
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before);
  // the residual path (a sparse embedding product per item) allocates nothing either
  nn::NetworkConfig rcfg = cfg;
  rcfg.residual = true;
  nn::Rng init2(4);
  nn::SuperResolutionNet<float> rnet(rcfg, geo, init2);
  Matrix<float> pr;
  rnet.infer(exec::omp, ldx, pr);
  rnet.infer(exec::omp, ldx, pr);
  const long before_r = simsr_test_malloc_count();
  rnet.infer(exec::omp, ldx, pr);
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before_r);
  // bad input
  CHECK_THROWS_AS(net.infer(exec::seq, Matrix<float>::Zero(59, 3), pi), ShapeError);
  CHECK_THROWS_AS(net.infer(exec::seq, Matrix<float>::Zero(60, 2), pi), ShapeError);
}

/// infer with the decoder's first Linear before the upsampling (Σ_i w_ji·W₁z_i instead of
/// W₁·Σ_i w_ji z_i) against the eval forward that forms z^H, on random networks: the profiles and
/// ablations, B = 1…3, random weights and BatchNorm statistics.
template <class S>
void check_first_layer_on_lr(const nn::NetworkConfig& cfg, Index N, Index M, Index B, std::uint64_t seed, double tol) {
  CAPTURE(seed);
  CAPTURE(B);
  std::mt19937_64 rng(seed);
  const auto geo = test::small_network_geometry(rng, N, M, cfg);
  nn::Rng init(seed + 100);
  nn::SuperResolutionNet<S> net(cfg, geo, init);
  if (cfg.residual) {  // a fresh residual network predicts the base alone: give the decoder's output layer weights
    for (const char* n : {"net_decoder.decoder.last_layer.fc.weight", "net_decoder.decoder.last_layer.fc.bias"})
      for (S& v : net.store().values(net.store().at(n))) v = static_cast<S>(std::uniform_real_distribution<double>(-0.5, 0.5)(rng));
  }
  for (S& v : net.store().buffers()) v = static_cast<S>(std::uniform_real_distribution<double>(0.5, 1.5)(rng));  // running means and variances
  const Matrix<S> ldx = test::random_matrix(rng, B * N, 3, -0.5, 0.5).template cast<S>();
  REQUIRE(net.infer_moves_decoder_first_layer());
  Matrix<S> pe, ps, po, po2;
  net.forward(exec::seq, nn::Mode::eval, ldx, pe);
  net.prepare_inference(exec::omp);
  net.infer(exec::seq, ldx, ps);
  net.infer(exec::omp, ldx, po);
  CHECK(test::bitwise_equal(ps, po));
  REQUIRE(ps.rows() == pe.rows());
  const double scale = std::max(1.0, double(pe.cwiseAbs().maxCoeff()));
  CHECK(double((ps - pe).cwiseAbs().maxCoeff()) <= tol * scale);
  // not the same sums: the split is real (rounding differs somewhere in float)
  if constexpr (std::is_same_v<S, float>) CHECK_FALSE(test::bitwise_equal(ps, pe));
  // what the split did not form, it does not hand out; no backward after an inference
  CHECK_THROWS_AS((void)net.hr_code(), ArgumentError);
  CHECK_THROWS_AS(net.backward(exec::seq, pe, nullptr), ArgumentError);
  // warm calls allocate nothing
  net.infer(exec::omp, ldx, po2);
  const long before = simsr_test_malloc_count();
  net.infer(exec::omp, ldx, po2);
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before);
  CHECK(test::bitwise_equal(po, po2));
  // switched off: the unsplit decoder, bitwise the eval forward; hr_code back
  net.set_decoder_first_layer_on_lr(false);
  Matrix<S> pu;
  net.infer(exec::omp, ldx, pu);
  CHECK(test::bitwise_equal(pu, pe));
  CHECK(net.hr_code().rows() == B * M);
}

TEST_CASE("nn::SuperResolutionNet: infer with the decoder's first layer on the LR rows == the eval forward up to rounding") {
  std::mt19937_64 pick(77);
  for (int trial = 0; trial < 24; ++trial) {
    nn::NetworkConfig cfg = test::tiny_config(trial % 2 ? nn::NetworkConfig::paper() : nn::NetworkConfig::official());
    switch (trial % 6) {
      case 2: cfg.disable_feature_embedding(); break;
      case 3: cfg.upsampling = nn::UpsamplingKind::table; break;
      case 4: cfg.residual = true; break;  // over the embedding
      default: break;
    }
    const Index N = 20 + Index(pick() % 30), M = N + 30 + Index(pick() % 60), B = 1 + Index(pick() % 3);
    const std::uint64_t seed = pick();
    check_first_layer_on_lr<double>(cfg, N, M, B, seed, 1e-12);
    check_first_layer_on_lr<float>(cfg, N, M, B, seed, 2e-4);
  }
}

TEST_CASE("nn::SuperResolutionNet: the decoder's first layer stays on the HR rows when moving it costs more") {
  std::mt19937_64 rng(3);
  const nn::NetworkConfig cfg = test::tiny_config(nn::NetworkConfig::official());
  // 162·N + 36·M < 234·M is false for N = 80, M = 50: infer keeps the unsplit decoder (bitwise the eval forward)
  const auto geo = test::small_network_geometry(rng, 80, 50, cfg);
  nn::Rng init(9);
  nn::SuperResolutionNet<float> net(cfg, geo, init);
  CHECK_FALSE(net.infer_moves_decoder_first_layer());
  const Matrix<float> ldx = test::random_matrix(rng, 80, 3, -0.5, 0.5).cast<float>();
  Matrix<float> pe, pi;
  net.forward(exec::seq, nn::Mode::eval, ldx, pe);
  net.infer(exec::omp, ldx, pi);
  CHECK(test::bitwise_equal(pe, pi));
  CHECK(net.hr_code().rows() == 50);
}

TEST_CASE("nn::NetworkConfig: JSON round trip, presets, the converter's official keys, and errors") {
  for (const auto& c : {nn::NetworkConfig::official(), nn::NetworkConfig::paper()}) {
    const auto back = nn::NetworkConfig::from_json(c.to_json());
    CHECK(back.to_json() == c.to_json());
  }
  // the keys scripts/torch_to_simsr.py writes
  const auto j = nlohmann::json::parse(R"({"profile": "official", "pos_feat_dim": 32, "emb_feat_dims": [35, 64, 128], "knn": 5,
      "upK": 20, "w_up_feat_dim": 64, "n_upscale_layers": 3, "decoder_dim": 256, "w0_initial": 30.0, "w0": 1.0,
      "leaky_relu_slope": 0.2, "batchnorm_eps": 1e-05, "batchnorm_momentum": 0.1, "dropout": 0.0, "n_epochs": 200,
      "norm_mean": -0.00047, "norm_std": 0.05045, "parameter_count": 1, "source": "x.pth"})");
  const auto c = nn::NetworkConfig::from_json(j);
  CHECK(c.up_k == 20);
  CHECK(c.up_hidden == std::vector<Index>{64, 64, 64});
  CHECK(c.decoder_dims == std::vector<Index>{227, 256, 128, 64, 32, 16, 3});
  CHECK(c.norm_std == doctest::Approx(0.05045));
  CHECK_THROWS_AS(nn::NetworkConfig::from_json(nlohmann::json::parse(R"({"knn": "five"})")), ArgumentError);
  CHECK_THROWS_AS(nn::NetworkConfig::from_json(nlohmann::json::parse(R"({"knn": 0})")), ArgumentError);
  CHECK_THROWS_AS(nn::NetworkConfig::from_json(nlohmann::json::parse(R"({"profile": "nope"})")), ArgumentError);
  CHECK_THROWS_AS(nn::NetworkConfig::from_json(nlohmann::json::parse(R"({"decoder_dims": [10, 3]})")), ArgumentError);
  CHECK_THROWS_AS(nn::NetworkConfig::from_json(nlohmann::json::parse("[1, 2]")), ArgumentError);
}
