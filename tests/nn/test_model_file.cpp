#include <doctest/doctest.h>

#include "network_fixture.hpp"

#include <simsr/nn/model_file.hpp>

#include <random>
#include <string>

using namespace simsr;

namespace {

/// A model file's arrays for a small network of `cfg` (residual embedding included when asked).
io::NpzArrays small_model_arrays(const nn::NetworkConfig& cfg, std::uint64_t seed, nn::ModelData* data_out = nullptr) {
  std::mt19937_64 rng(seed);
  nn::ModelData md;
  md.config = cfg;
  md.geometry = test::small_network_geometry(rng, 12, 15, cfg);
  if (cfg.residual) {
    std::vector<Eigen::Triplet<double>> t;
    for (int r = 0; r < 15; ++r) t.emplace_back(r, r % 12, 1.0);
    md.geometry.embedding.resize(15, 12);
    md.geometry.embedding.setFromTriplets(t.begin(), t.end());
  }
  md.lr_tets = Tets::Zero(1, 4);
  md.lr_tets.row(0) << 0, 1, 2, 3;
  md.hr_faces = Tris::Zero(1, 3);
  md.hr_faces.row(0) << 0, 1, 2;
  nn::Rng init(seed);
  nn::SuperResolutionNet<float> net(cfg, md.geometry, init);
  if (data_out) *data_out = md;
  return nn::model_arrays(net, md);
}

std::string config_text(const io::NpzArrays& a) { return a.at("config").to_strings().at(0); }
void set_config(io::NpzArrays& a, const nlohmann::json& j) {
  a["config"] = io::make_npy(std::vector<std::string>{j.dump()});
  a["config"].shape.clear();
}

}  // namespace

TEST_CASE("nn::SuperResolutionNet::state_shapes lists exactly what the network registers, for random configs") {
  std::mt19937_64 rng(2024);
  std::uniform_int_distribution<int> coin(0, 1), width(1, 9), count(1, 3);
  for (int trial = 0; trial < 60; ++trial) {
    nn::NetworkConfig c = coin(rng) ? nn::NetworkConfig::official() : nn::NetworkConfig::paper();
    c.pos_feat_dim = 2 * width(rng);
    c.emb_feat_dims = {3 + c.pos_feat_dim};
    for (int b = 0, n = count(rng); b < n; ++b) c.emb_feat_dims.push_back(width(rng));
    c.feature_embedding = coin(rng);
    c.edge_batch_norm = coin(rng);
    c.fc_out_batch_norm = coin(rng);
    c.up_batch_norm = coin(rng);
    c.upsampling = coin(rng) ? nn::UpsamplingKind::mlp : nn::UpsamplingKind::table;
    c.decoder_dead_layer = coin(rng);
    c.knn = 3;
    c.up_k = 1 + width(rng) % 4;
    c.up_hidden.clear();
    for (int l = 0, n = count(rng) - 1; l < n; ++l) c.up_hidden.push_back(width(rng));
    c.decoder_dims = {c.latent_dim()};
    for (int l = 0, n = count(rng); l < n; ++l) c.decoder_dims.push_back(width(rng));
    c.decoder_dims.push_back(3);
    c.validate();
    std::mt19937_64 g(trial);
    const nn::NetworkGeometry geo = test::small_network_geometry(g, 10, 13, c);
    nn::Rng init(trial);
    nn::SuperResolutionNet<float> net(c, geo, init);
    const auto expected = nn::SuperResolutionNet<float>::state_shapes(c, 13);
    const auto& built = net.store().entries();
    REQUIRE(expected.size() == built.size());
    for (std::size_t i = 0; i < built.size(); ++i) {
      CHECK(expected[i].name == built[i].name);
      CHECK(expected[i].shape == built[i].shape);
      CHECK(expected[i].kind == built[i].kind);
      CHECK(expected[i].size == built[i].size);
    }
  }
}

TEST_CASE("nn::model_data: a config beyond its bounds or one its tensors do not match is refused before any network is built") {
  const nn::NetworkConfig cfg = test::tiny_config(nn::NetworkConfig::official());
  const io::NpzArrays good = small_model_arrays(cfg, 3);
  CHECK_NOTHROW(nn::model_data(good, "m.npz"));
  const nlohmann::json j = nlohmann::json::parse(config_text(good));

  SUBCASE("widths that would ask for hundreds of GB") {
    io::NpzArrays a = good;
    nlohmann::json k = j;
    k["decoder_dims"] = {18, 200000, 200000, 3};  // 4e10 weights: 160 GB in float
    set_config(a, k);
    CHECK_THROWS_WITH_AS(nn::model_data(a, "m.npz"), doctest::Contains("decoder_dims = 200000 exceeds the sane bound 8192"), ArgumentError);
  }
  SUBCASE("too many layers, too many neighbours, absurd counts") {
    for (const auto& [key_, value, text] :
         std::vector<std::tuple<std::string, nlohmann::json, std::string>>{{"knn", 100000, "knn = 100000"},
                                                                          {"upK", 5000, "upK = 5000"},
                                                                          {"batch_size", 1LL << 40, "batch_size"},
                                                                          {"n_epochs", 1LL << 40, "n_epochs"},
                                                                          {"up_hidden", std::vector<int>(100, 4), "up_hidden (number of entries) = 100"},
                                                                          {"dropout", 1.5, "dropout must be in [0, 1)"},
                                                                          {"decoder_dims", "wide", "decoder_dims"}}) {
      io::NpzArrays a = good;
      nlohmann::json k = j;
      const std::string key = key_;
      k[key] = value;
      set_config(a, k);
      CAPTURE(key);
      CHECK_THROWS_WITH_AS(nn::model_data(a, "m.npz"), doctest::Contains(text.c_str()), simsr::Error);
    }
  }
  SUBCASE("a width the weights do not have: named with both shapes") {
    io::NpzArrays a = good;
    nlohmann::json k = j;
    k["decoder_dims"] = {18, 4000, 6, 4, 3};  // within bounds, but the file's decoder is 18→9→6→4→3
    set_config(a, k);
    CHECK_THROWS_WITH_AS(nn::model_data(a, "m.npz"),
                         doctest::Contains("m.npz: tensor 'net_decoder.decoder.layers.0.fc.weight' has shape (9, 18), the config implies (4000, 18)"),
                         ArgumentError);
  }
  SUBCASE("a tensor missing, or one the config does not describe") {
    io::NpzArrays a;
    for (const auto& [name, arr] : good)
      if (name != "net_decoder.decoder.last_layer.fc.bias") a[name] = arr;
    CHECK_THROWS_WITH_AS(nn::model_data(a, "m.npz"), doctest::Contains("implies tensor 'net_decoder.decoder.last_layer.fc.bias' (3)"), ArgumentError);
    io::NpzArrays b = good;
    const float x = 0;
    b["net_upscale.extra.weight"] = io::make_npy<float>({1}, &x);
    CHECK_THROWS_WITH_AS(nn::model_data(b, "m.npz"), doctest::Contains("'net_upscale.extra.weight' is not part of the network"), ArgumentError);
  }
  SUBCASE("the table upsampling's logits are M×upK: a file's M must match") {
    nn::NetworkConfig t = cfg;
    t.upsampling = nn::UpsamplingKind::table;
    io::NpzArrays a = small_model_arrays(t, 4);
    CHECK_NOTHROW(nn::model_data(a, "t.npz"));
    a.at("net_upscale.logits").shape = {1000000, 4};
    CHECK_THROWS_WITH_AS(nn::model_data(a, "t.npz"), doctest::Contains("the config implies (15, 4)"), ArgumentError);
  }
  SUBCASE("an embedding indptr that runs past the indices and comes back (found by fuzz_model_file)") {
    nn::NetworkConfig r = cfg;
    r.residual = true;
    io::NpzArrays a = small_model_arrays(r, 5);
    CHECK_NOTHROW(nn::model_data(a, "r.npz"));
    std::vector<std::int64_t> ptr(16);  // 15 rows of one entry each: 0, 1, …, 15
    for (std::size_t i = 0; i < ptr.size(); ++i) ptr[i] = std::int64_t(i);
    ptr[1] = 1000;  // row 0 would read indices 0..999 of 15, row 1 then "decreases"
    a["embedding_indptr"] = io::make_npy<std::int64_t>({16}, ptr.data());
    CHECK_THROWS_WITH_AS(nn::model_data(a, "r.npz"), doctest::Contains("r.npz: embedding_indptr decreases at row 1"), ArgumentError);
  }
}

TEST_CASE("nn::save_model writes a model that loads into the same network; a non-finite weight is never written") {
  nn::ModelData md;
  const nn::NetworkConfig cfg = test::tiny_config(nn::NetworkConfig::paper());
  const io::NpzArrays a = small_model_arrays(cfg, 9, &md);
  const nn::ModelData back = nn::model_data(a, "m.npz");
  CHECK(back.config.to_json() == cfg.to_json());
  nn::Rng init(1);
  nn::SuperResolutionNet<float> net(back.config, back.geometry, init);
  nn::load_state(net.store(), a);
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "model_file";
  std::filesystem::create_directories(dir);
  nn::save_model(dir / "m.npz", net, md);
  CHECK(nn::read_model_data(dir / "m.npz").config.to_json() == cfg.to_json());
  net.store().values()[3] = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH_AS(nn::save_model(dir / "m.npz", net, md), doctest::Contains("entry"), NumericalError);
  CHECK(nn::read_model_data(dir / "m.npz").config.to_json() == cfg.to_json());  // the old file is intact
}
