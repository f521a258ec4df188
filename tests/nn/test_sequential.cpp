#include <simsr/nn/sequential.hpp>

#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

namespace {
using SeqMlp = nn::Sequential<nn::Linear<double>, nn::LeakyReLU<double>, nn::Linear<double>>;
using SeqMlpF = nn::Sequential<nn::Linear<float>, nn::Sine<float>, nn::Linear<float>>;
}  // namespace

static_assert(nn::Layer<SeqMlp>, "a chain of layers is a layer");
static_assert(nn::Layer<nn::Sequential<SeqMlp, nn::Dropout<double>>>, "chains nest");
static_assert(!nn::Layer<nn::Concat<float>>);

TEST_CASE("nn::Sequential: forward is the layers one after the other, registered in order") {
  std::mt19937_64 rng(301);
  nn::Rng init(302);
  nn::ParameterStore<double> store;
  SeqMlp mlp{nn::Linear<double>(store, "fc.0", 5, 8, init), nn::LeakyReLU<double>(0.2), nn::Linear<double>(store, "fc.2", 8, 3, init)};
  std::vector<std::string> names;
  for (const auto& e : store.entries()) names.push_back(e.name);
  CHECK(names == std::vector<std::string>{"fc.0.weight", "fc.0.bias", "fc.2.weight", "fc.2.bias"});
  CHECK(mlp.out_features(5) == 3);
  const Matrix<double> x = random_matrix(rng, 70, 5);
  Matrix<double> y, a, b, c;
  mlp.forward(exec::seq, nn::Mode::train, x, y);
  mlp.layer<0>().forward(exec::seq, nn::Mode::train, x, a);
  mlp.layer<1>().forward(exec::seq, nn::Mode::train, a, b);
  mlp.layer<2>().forward(exec::seq, nn::Mode::train, b, c);
  CHECK(test::bitwise_equal(y, c));
  CHECK(test::bitwise_equal(mlp.activation(0), a));
}

TEST_CASE("nn::Sequential: gradients match finite differences; seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(303);
  nn::Rng init(304);
  nn::ParameterStore<double> store;
  SeqMlp mlp{nn::Linear<double>(store, "fc.0", 4, 6, init), nn::LeakyReLU<double>(0.2), nn::Linear<double>(store, "fc.2", 6, 2, init)};
  test::check_gradients(test::layer_gradient_check(mlp, &store, test::random_away_from_zero(rng, 9, 4), nn::Mode::train, rng));

  nn::ParameterStore<float> fstore;
  SeqMlpF f{nn::Linear<float>(fstore, "a", 7, 300, init), nn::Sine<float>(30.0f), nn::Linear<float>(fstore, "b", 300, 3, init)};
  const Matrix<float> xf = random_matrix(rng, 500, 7).cast<float>();
  test::check_seq_equals_omp(f, &fstore, xf, nn::Mode::train, rng);
  test::check_warm_no_allocation(exec::omp, f, xf, nn::Mode::train);
  test::check_warm_no_allocation(exec::seq, f, xf, nn::Mode::eval);
}
