#include "gradient_check.hpp"

namespace nn_test_transformer {

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

namespace {
/// Softmax attention of one head, written out independently (no chunking, no Linear layers).
Matrix<double> reference_attention(const Matrix<double>& Q, const Matrix<double>& K, const Matrix<double>& V, bool causal) {
  Matrix<double> S = Q * K.transpose() / std::sqrt(double(Q.cols()));
  for (Index i = 0; i < S.rows(); ++i) {
    for (Index j = 0; j < S.cols(); ++j)
      if (causal && j > i) S(i, j) = -1e300;
    const double mx = S.row(i).maxCoeff();
    S.row(i) = (S.row(i).array() - mx).exp().matrix();
    S.row(i) /= S.row(i).sum();
  }
  return S * V;
}
}  // namespace

TEST_CASE("nn::MultiHeadAttention: per-head softmax attention as written out; causal mask; FD gradients of both inputs") {
  std::mt19937_64 rng(51);
  nn::Rng init(52);
  for (const bool causal : {false, true}) {
    nn::ParameterStore<double> store;
    const Index d = 8, heads = 2, B = 3, tq = 3, tk = causal ? 3 : 4;
    nn::MultiHeadAttention<double> att(store, "att", d, init, {.heads = heads, .causal = causal});
    const Matrix<double> x = random_matrix(rng, B * tq, d), m = random_matrix(rng, B * tk, d);
    Matrix<double> y;
    att.forward(exec::seq, nn::Mode::train, x, tq, m, tk, y);
    // reference: the projections by hand, then each (sequence, head) on its own
    auto lin = [&](const std::string& n, const Matrix<double>& in) {
      const auto& e = store.entries();
      Index w = -1, b = -1;
      for (const auto& t : e) {
        if (t.name == n + ".weight") w = t.offset;
        if (t.name == n + ".bias") b = t.offset;
      }
      Matrix<double> out = in * store.value(w, d, d).transpose();
      out.rowwise() += store.value(b, 1, d).row(0);
      return out;
    };
    const Matrix<double> Q = lin("att.q", x), K = lin("att.k", m), V = lin("att.v", m);
    Matrix<double> O(B * tq, d);
    const Index dh = d / heads;
    for (Index b = 0; b < B; ++b)
      for (Index h = 0; h < heads; ++h)
        O.block(b * tq, h * dh, tq, dh) = reference_attention(Q.block(b * tq, h * dh, tq, dh), K.block(b * tk, h * dh, tk, dh),
                                                              V.block(b * tk, h * dh, tk, dh), causal);
    CHECK((lin("att.out", O) - y).cwiseAbs().maxCoeff() < 1e-12);
    // gradients of queries and memory at once: the two inputs stacked as one matrix
    Matrix<double> xm(B * (tq + tk), d);
    xm << x, m;
    test::check_attention_gradients(test::gradient_check(
        xm, &store,
        [&](const Matrix<double>& in, Matrix<double>& out) {
          att.forward(exec::seq, nn::Mode::train, in.topRows(B * tq), tq, in.bottomRows(B * tk), tk, out);
        },
        [&](const Matrix<double>& in, const Matrix<double>& out, const Matrix<double>& dout, Matrix<double>* din) {
          Matrix<double> dq, dk;
          att.backward(exec::seq, in.topRows(B * tq), in.bottomRows(B * tk), out, dout, &dq, &dk);
          din->resize(in.rows(), in.cols());
          *din << dq, dk;
        },
        rng), 1e-6);
  }
  nn::ParameterStore<double> store;
  CHECK_THROWS_AS(nn::MultiHeadAttention<double>(store, "bad", 6, init, {.heads = 4}), ArgumentError);
  nn::MultiHeadAttention<double> att(store, "a", 4, init, {.heads = 2});
  Matrix<double> y;
  CHECK_THROWS_AS(att.forward(exec::seq, nn::Mode::train, Matrix<double>(random_matrix(rng, 6, 4)), 3,
                              Matrix<double>(random_matrix(rng, 8, 4)), 3, y),
                  ShapeError);
}

TEST_CASE("nn transformer blocks: encoder (a Layer) and decoder (two inputs) match finite differences; seq == omp") {
  std::mt19937_64 rng(53);
  nn::Rng init(54);
  const Index d = 8, ff = 12, T = 3, B = 2;
  {
    nn::ParameterStore<double> store;
    nn::TransformerEncoderBlock<double> enc(store, "enc", d, ff, T, init, 2);
    const Matrix<double> x = random_matrix(rng, B * T, d);
    test::check_attention_gradients(test::layer_gradient_check(enc, &store, x, nn::Mode::train, rng), 1e-5);
    test::check_seq_equals_omp(enc, &store, x, nn::Mode::train, rng);
  }
  nn::ParameterStore<double> store;
  nn::TransformerDecoderBlock<double> dec(store, "dec", d, ff, T, T, init, 2);
  Matrix<double> xm = random_matrix(rng, 2 * B * T, d);
  test::check_attention_gradients(
      test::gradient_check(
          xm, &store,
          [&](const Matrix<double>& in, Matrix<double>& out) {
            dec.forward(exec::seq, nn::Mode::train, in.topRows(B * T), in.bottomRows(B * T), out);
          },
          [&](const Matrix<double>& in, const Matrix<double>& out, const Matrix<double>& dout, Matrix<double>* din) {
            Matrix<double> dx, dm;
            dec.backward(exec::seq, in.topRows(B * T), in.bottomRows(B * T), out, dout, &dx, &dm);
            din->resize(in.rows(), in.cols());
            *din << dx, dm;
          },
          rng),
      1e-5);
  // the decoder's output at token t does not depend on later target tokens (the causal mask)
  Matrix<double> y1, y2;
  Matrix<double> x2 = xm.topRows(B * T);
  dec.forward(exec::seq, nn::Mode::eval, xm.topRows(B * T), xm.bottomRows(B * T), y1);
  x2.row(2) += Eigen::RowVectorXd::Ones(d);  // token 2 of sequence 0
  dec.forward(exec::seq, nn::Mode::eval, x2, xm.bottomRows(B * T), y2);
  CHECK((y1.topRows(2) - y2.topRows(2)).cwiseAbs().maxCoeff() == 0.0);
  CHECK((y1.row(2) - y2.row(2)).cwiseAbs().maxCoeff() > 0.0);
}

}  // namespace nn_test_transformer
