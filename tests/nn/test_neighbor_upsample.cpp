#include <simsr/nn/device_neighbor_upsample.hpp>  // the host compiler sees the header, not the class (nvcc only)
#include <simsr/nn/neighbor_upsample.hpp>

#include "gradient_check.hpp"

using namespace simsr;
using nn::GraphIndices;
using nn::Matrix;
using test::random_matrix;

namespace {
GraphIndices random_indices(std::mt19937_64& rng, Index M, Index N, Index K) {
  std::uniform_int_distribution<int> pick(0, int(N) - 1);
  GraphIndices g(M, K);
  for (Index i = 0; i < g.size(); ++i) g.data()[i] = pick(rng);
  return g;
}
}  // namespace

TEST_CASE("nn::NeighborUpsample: softmax weights and the weighted gather against plain loops") {
  std::mt19937_64 rng(91);
  const Index B = 3, N = 8, M = 11, K = 4, C = 5;
  nn::NeighborUpsample<double> up(random_indices(rng, M, N, K), N);
  const Matrix<double> z = random_matrix(rng, B * N, C);
  for (bool shared : {true, false}) {
    const Matrix<double> logits = random_matrix(rng, shared ? M : B * M, K, -3, 3);
    Matrix<double> out, out2;
    up.forward(exec::seq, logits, z, out);
    REQUIRE(out.rows() == B * M);
    for (Index r = 0; r < logits.rows(); ++r) {
      double s = 0;
      for (Index i = 0; i < K; ++i) s += std::exp(logits(r, i));
      for (Index i = 0; i < K; ++i) CHECK(std::abs(up.weights()(r, i) - std::exp(logits(r, i)) / s) < 1e-15);
    }
    for (Index b = 0; b < B; ++b)
      for (Index j = 0; j < M; ++j)
        for (Index c = 0; c < C; ++c) {
          double v = 0;
          for (Index i = 0; i < K; ++i) v += up.weights()(shared ? j : b * M + j, i) * z(b * N + up.indices()(j, i), c);
          CHECK(std::abs(out(b * M + j, c) - v) < 1e-14);
        }
    // inference path with precomputed weights: the same bits
    Matrix<double> w;
    nn::NeighborUpsample<double>::softmax_rows(exec::seq, logits, w);
    up.apply(exec::seq, w, z, out2);
    CHECK(test::bitwise_equal(out, out2));
    // any row range into a wider buffer: apply's rows, bit for bit
    for (int t = 0; t < 20; ++t) {
      const Index b = Index(rng() % std::uint64_t(B * M + 1)), e = b + Index(rng() % std::uint64_t(B * M - b + 1)), ld = C + Index(rng() % 3);
      Matrix<double> part = Matrix<double>::Constant(std::max<Index>(e - b, 1), ld, 7.0);
      up.apply_rows(w, z, b, e, part.data(), ld);
      for (Index r = b; r < e; ++r) {
        CHECK(test::bitwise_equal(Matrix<double>(part.row(r - b).head(C)), Matrix<double>(out2.row(r))));
        CHECK((part.row(r - b).tail(ld - C).array() == 7.0).all());  // the padding untouched
      }
    }
    Matrix<double> part(B * M, C);
    CHECK_THROWS_AS(up.apply_rows(w, z, 2, 1, part.data(), C), ArgumentError);          // end before begin
    CHECK_THROWS_AS(up.apply_rows(w, z, 0, B * M + 1, part.data(), C), ArgumentError);  // past the last row
    CHECK_THROWS_AS(up.apply_rows(w, z, 0, 1, part.data(), C - 1), ArgumentError);      // a row does not fit
    CHECK_THROWS_AS(up.apply_rows(w, Matrix<double>(N + 1, C), 0, 1, part.data(), C), ShapeError);
  }
  // large logits do not overflow
  Matrix<double> big = Matrix<double>::Constant(M, K, 1000.0), w;
  nn::NeighborUpsample<double>::softmax_rows(exec::seq, big, w);
  CHECK((w.array() - 0.25).abs().maxCoeff() < 1e-15);
  GraphIndices bad = GraphIndices::Constant(M, K, VIndex(N));
  CHECK_THROWS_AS(nn::NeighborUpsample<double>(bad, N), ArgumentError);
  Matrix<double> out;
  CHECK_THROWS_AS(up.forward(exec::seq, Matrix<double>(M + 1, K), z, out), ShapeError);
  CHECK_THROWS_AS(up.forward(exec::seq, Matrix<double>(M, K), Matrix<double>(N + 1, C), out), ShapeError);
}

TEST_CASE("nn::NeighborUpsample: gradients to logits and LR codes match finite differences") {
  std::mt19937_64 rng(92);
  const Index B = 2, N = 6, M = 9, K = 3, C = 4;
  nn::NeighborUpsample<double> up(random_indices(rng, M, N, K), N);
  for (bool shared : {true, false}) {
    INFO("shared logits " << shared);
    const Matrix<double> logits = random_matrix(rng, shared ? M : B * M, K, -2, 2);
    const Matrix<double> z = random_matrix(rng, B * N, C);
    // w.r.t. z (logits fixed)
    test::check_gradients(test::gradient_check(
        z, (nn::ParameterStore<double>*)nullptr, [&](const Matrix<double>& x, Matrix<double>& o) { up.forward(exec::seq, logits, x, o); },
        [&](const Matrix<double>& x, const Matrix<double>&, const Matrix<double>& d, Matrix<double>* dx) {
          up.backward(exec::seq, x, d, nullptr, dx);
        },
        rng));
    // w.r.t. the logits (z fixed)
    test::check_gradients(test::gradient_check(
        logits, (nn::ParameterStore<double>*)nullptr, [&](const Matrix<double>& l, Matrix<double>& o) { up.forward(exec::seq, l, z, o); },
        [&](const Matrix<double>&, const Matrix<double>&, const Matrix<double>& d, Matrix<double>* dl) { up.backward(exec::seq, z, d, dl, nullptr); },
        rng));
  }
}

TEST_CASE("nn::NeighborUpsample: seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(93);
  const Index B = 4, N = 300, M = 1200, K = 10, C = 64;
  nn::NeighborUpsample<float> up(random_indices(rng, M, N, K), N);
  const Matrix<float> z = random_matrix(rng, B * N, C).cast<float>();
  const Matrix<float> logits = random_matrix(rng, M, K, -2, 2).cast<float>();
  Matrix<float> o1, o2, dl1, dl2, dz1, dz2;
  up.forward(exec::seq, logits, z, o1);
  const Matrix<float> r = random_matrix(rng, o1.rows(), o1.cols()).cast<float>();
  up.backward(exec::seq, z, r, &dl1, &dz1);
  up.forward(exec::omp, logits, z, o2);
  up.backward(exec::omp, z, r, &dl2, &dz2);
  CHECK(test::bitwise_equal(o1, o2));
  CHECK(test::bitwise_equal(dl1, dl2));
  CHECK(test::bitwise_equal(dz1, dz2));
  const float* p = o1.data();
  const long before = simsr_test_malloc_count();
  up.forward(exec::omp, logits, z, o1);
  up.backward(exec::omp, z, r, &dl1, &dz1);
  up.apply(exec::seq, up.weights(), z, o1);
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before);
  CHECK(o1.data() == p);
}

TEST_CASE("nn::NeighborUpsample: the gather's body over MatrixSpan (DeviceNeighborUpsample's accessor), row by row and entry by entry, equals apply, bitwise, under seq and omp") {
  std::mt19937_64 rng(94);
  for (int t = 0; t < 24; ++t) {
    const Index B = 1 + Index(rng() % 4), N = 1 + Index(rng() % 40), M = 1 + Index(rng() % 90), K = 1 + Index(rng() % 24),
                C = 1 + Index(rng() % 70), pad = Index(rng() % 3);
    const bool shared = t % 2 == 0;
    INFO("B " << B << ", N " << N << ", M " << M << ", upK " << K << ", C " << C << ", shared " << shared << ", padding " << pad);
    nn::NeighborUpsample<float> up(random_indices(rng, M, N, K), N);
    // z and the weights as column blocks of wider matrices: row strides beyond their columns
    const Matrix<float> z_wide = random_matrix(rng, B * N, C + pad).cast<float>();
    const Matrix<float> logits = random_matrix(rng, shared ? M : B * M, K + pad, -3, 3).cast<float>();
    Matrix<float> w_wide;
    nn::NeighborUpsample<float>::softmax_rows(exec::seq, logits, w_wide);
    const nn::ConstView<float> z = z_wide.leftCols(C), w = w_wide.leftCols(K);
    Matrix<float> ref;
    up.apply(exec::seq, w, z, ref);
    const MatrixSpan<const float> zs{z.data(), z.rows(), z.cols(), z.outerStride()}, ws{w.data(), w.rows(), w.cols(), w.outerStride()};
    for (bool omp : {false, true}) {
      Matrix<float> out = Matrix<float>::Constant(B * M, C + pad, 7.0f);
      const nn::detail::UpsampleGather<float> body{up.indices().data(), M, N, ws, zs, MatrixSpan<float>{out.data(), out.rows(), C, out.cols()}};
      if (omp)
        exec::parallel_for(exec::omp, B * M, body);
      else
        exec::parallel_for(exec::seq, B * M, body);
      CHECK(test::bitwise_equal(Matrix<float>(out.leftCols(C)), ref));
      CHECK((out.rightCols(pad).array() == 7.0f).all());  // the padding untouched
      // entry by entry (the device's launch: one index an entry), the same sums
      out.setConstant(7.0f);
      const nn::detail::UpsampleGatherEntries<float> entries{body};
      if (omp)
        exec::parallel_for(exec::omp, B * M * C, entries);
      else
        exec::parallel_for(exec::seq, B * M * C, entries);
      CHECK(test::bitwise_equal(Matrix<float>(out.leftCols(C)), ref));
      CHECK((out.rightCols(pad).array() == 7.0f).all());
    }
  }
}
