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
