#include <simsr/nn/nn.hpp>

#include <doctest/doctest.h>

#include <string>

using namespace simsr;
using nn::Matrix;

static_assert(nn::assert_layer<nn::Linear<float>>());
static_assert(nn::assert_layer<nn::BatchNorm1d<float>>());
static_assert(nn::assert_layer<nn::LeakyReLU<double>>());
static_assert(nn::assert_layer<nn::Sine<float>>());
static_assert(nn::assert_layer<nn::PositionalEncoding<float>>());
static_assert(nn::assert_layer<nn::GroupPool<float>>());
static_assert(!nn::Layer<int>);
static_assert(!nn::Layer<nn::Concat<float>>, "several inputs: not a unary layer");
static_assert(!nn::Layer<nn::ParameterStore<float>>);

TEST_CASE("nn::ParameterStore: PyTorch state-dict names, shapes, order and counts") {
  nn::ParameterStore<float> store;
  nn::Rng rng(3);
  nn::Linear<float> conv(store, "fc_out.0", 7, 5, rng, {.bias = false, .kernel_dims = 1});
  nn::BatchNorm1d<float> bn(store, "fc_out.1", 5);
  nn::Linear<float> lin(store, "fc.0", 5, 3, rng);
  nn::Linear<float> conv2d(store, "edge_conv.0", 4, 2, rng, {.bias = false, .kernel_dims = 2});

  const auto& e = store.entries();
  REQUIRE(e.size() == 9);
  const char* names[] = {"fc_out.0.weight",       "fc_out.1.weight",          "fc_out.1.bias",
                         "fc_out.1.running_mean", "fc_out.1.running_var",     "fc_out.1.num_batches_tracked",
                         "fc.0.weight",           "fc.0.bias",                "edge_conv.0.weight"};
  for (int i = 0; i < 9; ++i) CHECK(e[std::size_t(i)].name == names[i]);
  CHECK(e[0].shape == std::vector<Index>{5, 7, 1});
  CHECK(e[5].shape.empty());
  CHECK(e[5].size == 1);
  CHECK(e[6].shape == std::vector<Index>{3, 5});
  CHECK(e[8].shape == std::vector<Index>{2, 4, 1, 1});
  CHECK(e[3].kind == nn::TensorEntry::Kind::buffer);
  // trainable count = Σ numel of parameters (PyTorch's count): 35 + 5 + 5 + 15 + 3 + 8
  CHECK(store.num_parameters() == 71);
  CHECK(store.num_buffer_values() == 11);
  // offsets are contiguous per kind, in registration order
  CHECK(store.at("fc_out.1.weight").offset == 35);
  CHECK(store.at("fc.0.weight").offset == 45);
  CHECK(store.at("fc_out.1.running_var").offset == 5);

  // views alias the flat buffers
  auto rv = store.values(store.at("fc_out.1.running_var"));
  CHECK(rv.size() == 5);
  CHECK(rv[0] == 1.0f);
  CHECK(store.values(store.at("fc_out.1.weight"))[2] == 1.0f);
  lin.weight()(1, 2) = 42.0f;
  CHECK(store.values(store.at("fc.0.weight"))[1 * 5 + 2] == 42.0f);
  store.gradients().setConstant(2.0f);
  CHECK(lin.bias_grad()[1] == 2.0f);
  store.zero_grad();
  CHECK(store.gradients().cwiseAbs().maxCoeff() == 0.0f);

  CHECK(store.find("nope") == nullptr);
  CHECK_THROWS_AS(store.at("nope"), ArgumentError);
  CHECK_THROWS_AS(store.gradient(store.at("fc_out.1.running_mean")), ArgumentError);
  CHECK_THROWS_AS(nn::Linear<float>(store, "fc.0", 5, 3, rng), ArgumentError);  // duplicate name
  CHECK_THROWS_AS(store.add_parameter("neg", {-1, 2}), ArgumentError);
  CHECK_THROWS_AS(conv.bias(), ArgumentError);
}

TEST_CASE("nn::ParameterStore: registering more tensors later keeps earlier layers valid") {
  nn::ParameterStore<double> store;
  nn::Rng rng(1);
  nn::Linear<double> a(store, "a", 3, 4, rng);
  const Matrix<double> Wa = a.weight();
  for (int i = 0; i < 50; ++i) nn::Linear<double>(store, std::string("b").append(std::to_string(i)), 30, 30, rng);  // (GCC 12 false -Wrestrict on "b" + string)
  CHECK(Matrix<double>(a.weight()) == Wa);
  Matrix<double> x = Matrix<double>::Ones(2, 3), y;
  a.forward(exec::seq, nn::Mode::eval, x, y);
  CHECK(y.rows() == 2);
}
