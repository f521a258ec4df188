#include <doctest/doctest.h>

#include <simsr/shell/deform_transformer.hpp>

#include "../nn/gradient_check.hpp"

namespace shell_test_deform_transformer {

using namespace simsr;
using namespace simsr::shell;
using nn::Matrix;

TEST_CASE("shell::DeformTransformer: gradients of both inputs by finite differences, causal in the fine inputs, seq == omp") {
  std::mt19937_64 rng(63);
  nn::Rng init(64);
  const DeformTransformerOptions opt{.latent = 3, .d_model = 8, .feed_forward = 10, .heads = 2, .blocks = 2, .frames = 3};
  nn::ParameterStore<double> store;
  DeformTransformer<double> net(store, "dt", opt, init);
  const Index B = 2, T = 3;
  Matrix<double> both = test::random_matrix(rng, 2 * B * T, 3);
  auto fwd = [&](const Matrix<double>& in, Matrix<double>& out) {
    net.forward(exec::seq, nn::Mode::train, in.topRows(B * T), in.bottomRows(B * T), out);
  };
  std::vector<test::GradientError> errors = test::gradient_check(
      both, &store, fwd,
      [&](const Matrix<double>& in, const Matrix<double>& out, const Matrix<double>& dout, Matrix<double>* din) {
        Matrix<double> dc, df;
        net.backward(exec::seq, in.topRows(B * T), in.bottomRows(B * T), out, dout, &dc, &df);
        din->resize(in.rows(), in.cols());
        *din << dc, df;
      },
      rng);
  test::check_attention_gradients(errors, 1e-5);
  // position t depends on the fine inputs at positions ≤ t only
  Matrix<double> y1, y2, later = both;
  fwd(both, y1);
  later.row(B * T + 2) += Eigen::RowVector3d(1, -1, 0.5);  // fine input, sequence 0, position 2
  fwd(later, y2);
  CHECK((y1.topRows(2) - y2.topRows(2)).cwiseAbs().maxCoeff() == 0.0);
  CHECK((y1.row(2) - y2.row(2)).cwiseAbs().maxCoeff() > 0.0);
  CHECK((y1.bottomRows(3) - y2.bottomRows(3)).cwiseAbs().maxCoeff() == 0.0);  // sequence 1 untouched
  // seq == omp, bitwise
  Matrix<double> ys, yo, dcs, dfs, dco, dfo;
  const Matrix<double> dy = test::random_matrix(rng, B * T, 3);
  store.zero_grad();
  net.forward(exec::seq, nn::Mode::train, both.topRows(B * T), both.bottomRows(B * T), ys);
  net.backward(exec::seq, both.topRows(B * T), both.bottomRows(B * T), ys, dy, &dcs, &dfs);
  const nn::Vector<double> gs = store.gradients();
  store.zero_grad();
  net.forward(exec::omp, nn::Mode::train, both.topRows(B * T), both.bottomRows(B * T), yo);
  net.backward(exec::omp, both.topRows(B * T), both.bottomRows(B * T), yo, dy, &dco, &dfo);
  CHECK(test::bitwise_equal(ys, yo));
  CHECK(test::bitwise_equal(dcs, dco));
  CHECK(test::bitwise_equal(dfs, dfo));
  CHECK(test::bitwise_equal(gs, nn::Vector<double>(store.gradients())));
  CHECK_THROWS_AS(net.forward(exec::seq, nn::Mode::train, both.topRows(4), both.bottomRows(4), ys), ShapeError);
}

}  // namespace shell_test_deform_transformer
