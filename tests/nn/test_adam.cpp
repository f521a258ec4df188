#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

namespace {
/// Textbook Adam (Kingma & Ba, Algorithm 1, with PyTorch's eps placement and L2 decay), in long double.
struct ReferenceAdam {
  double lr, b1, b2, eps, wd;
  std::vector<long double> m, v;
  int t = 0;
  void step(std::vector<long double>& p, const std::vector<long double>& grad) {
    if (m.empty()) m.assign(p.size(), 0), v.assign(p.size(), 0);
    ++t;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const long double g = grad[i] + wd * p[i];
      m[i] = b1 * m[i] + (1 - b1) * g;
      v[i] = b2 * v[i] + (1 - b2) * g * g;
      const long double mhat = m[i] / (1 - std::pow((long double)b1, t)), vhat = v[i] / (1 - std::pow((long double)b2, t));
      p[i] -= lr * mhat / (std::sqrt(vhat) + eps);
    }
  }
};
}  // namespace

TEST_CASE("nn::Adam: a few steps against a hand-written reference (with and without weight decay)") {
  for (double wd : {0.0, 0.01}) {
    std::mt19937_64 rng(81);
    nn::Rng init(82);
    nn::ParameterStore<double> store;
    nn::Linear<double> l(store, "l", 4, 3, init);
    nn::Adam<double> opt(store, {.lr = 2e-2, .weight_decay = wd});
    ReferenceAdam ref{2e-2, 0.9, 0.999, 1e-8, wd, {}, {}};
    std::vector<long double> p(store.values().data(), store.values().data() + store.num_parameters());
    for (int step = 0; step < 6; ++step) {
      const Matrix<double> g = random_matrix(rng, store.num_parameters(), 1, -step - 1.0, step + 1.0);
      store.gradients() = g;
      opt.step(exec::seq);
      ref.step(p, std::vector<long double>(g.data(), g.data() + g.size()));
      double err = 0;
      for (Index i = 0; i < store.num_parameters(); ++i) err = std::max(err, double(std::abs(store.values()[i] - p[std::size_t(i)])));
      INFO("step " << step + 1 << " weight decay " << wd);
      CHECK(err < 1e-14);
    }
    CHECK(opt.steps() == 6);
  }
  // the first step moves every parameter by lr·|g|/(|g| + eps) ≈ lr, whatever the gradient scale
  nn::ParameterStore<double> store;
  store.add_parameter("p", {2});
  store.values() << 1, -1;
  store.gradients() << 1e-3, -50;
  nn::Adam<double> opt(store, {.lr = 0.1});
  opt.step(exec::seq);
  CHECK(store.values()[0] == doctest::Approx(1 - 0.1 * 1e-3 / (1e-3 + 1e-8)).epsilon(1e-12));
  CHECK(store.values()[1] == doctest::Approx(-1 + 0.1 * 50 / (50 + 1e-8)).epsilon(1e-12));
}

TEST_CASE("nn::Adam: saved state restores the trajectory exactly; seq == omp bitwise") {
  std::mt19937_64 rng(83);
  nn::Rng init(84);
  nn::ParameterStore<float> store;
  nn::Linear<float> l(store, "l", 40, 50, init);
  const nn::Vector<float> p0 = store.values();
  std::vector<Matrix<float>> grads;
  for (int i = 0; i < 5; ++i) grads.push_back(random_matrix(rng, store.num_parameters(), 1).cast<float>());

  nn::Adam<float> a(store, {.lr = 1e-3});
  for (int i = 0; i < 5; ++i) store.gradients() = grads[std::size_t(i)], a.step(exec::seq);
  const nn::Vector<float> straight = store.values();

  store.values() = p0;
  nn::Adam<float> b(store, {.lr = 1e-3});
  for (int i = 0; i < 2; ++i) store.gradients() = grads[std::size_t(i)], b.step(exec::omp);
  const auto saved = b.state();
  nn::Adam<float> c(store, {.lr = 1e-3});
  c.load_state(saved);
  CHECK(c.steps() == 2);
  for (int i = 2; i < 5; ++i) store.gradients() = grads[std::size_t(i)], c.step(exec::omp);
  CHECK(test::bitwise_equal(straight, nn::Vector<float>(store.values())));
  CHECK(!test::bitwise_equal(p0, straight));

  nn::Adam<float>::State bad;
  bad.exp_avg.setZero(3);
  bad.exp_avg_sq.setZero(3);
  CHECK_THROWS_AS(c.load_state(bad), ShapeError);
  CHECK_THROWS_AS(nn::Adam<float>(store, {.beta1 = 1.0}), ArgumentError);
}
