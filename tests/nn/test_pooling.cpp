#include "gradient_check.hpp"

#include <numeric>

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

namespace {
/// rows×cols distinct values (a shuffled 0.1-spaced grid): finite differences never swap a max.
Matrix<double> distinct(std::mt19937_64& rng, Index rows, Index cols) {
  std::vector<double> v(static_cast<std::size_t>(rows * cols));
  std::iota(v.begin(), v.end(), 0.0);
  std::shuffle(v.begin(), v.end(), rng);
  Matrix<double> m(rows, cols);
  for (Index i = 0; i < m.size(); ++i) m.data()[i] = 0.1 * v[std::size_t(i)] - 1;
  return m;
}
}  // namespace

TEST_CASE("nn::GroupPool: global max / mean per batch item, broadcast back") {
  std::mt19937_64 rng(51);
  const Index B = 3, N = 7, C = 4;
  const Matrix<double> x = random_matrix(rng, B * N, C);
  nn::GroupPool<double> gmax(nn::PoolKind::max, N), gmean(nn::PoolKind::mean, N), gmax1(nn::PoolKind::max, N, false);
  Matrix<double> ymax, ymean, y1;
  gmax.forward(exec::seq, nn::Mode::train, x, ymax);
  gmean.forward(exec::seq, nn::Mode::train, x, ymean);
  gmax1.forward(exec::seq, nn::Mode::train, x, y1);
  REQUIRE(ymax.rows() == B * N);
  REQUIRE(y1.rows() == B);
  for (Index b = 0; b < B; ++b) {
    const auto block = x.middleRows(b * N, N);
    for (Index n = 0; n < N; ++n) {
      CHECK(ymax.row(b * N + n) == block.colwise().maxCoeff());
      CHECK((ymean.row(b * N + n) - block.colwise().mean()).cwiseAbs().maxCoeff() < 1e-15);
    }
    CHECK(y1.row(b) == block.colwise().maxCoeff());
  }
}

TEST_CASE("nn::GroupPool: max routes the gradient to the first maximum") {
  nn::GroupPool<double> pool(nn::PoolKind::max, 4, false);
  Matrix<double> x(4, 2), y, d;
  x << 1, 5, 3, 5, 3, 2, 0, 5;
  pool.forward(exec::seq, nn::Mode::train, x, y);
  CHECK(y(0, 0) == 3);
  CHECK(pool.argmax()(0, 0) == 1);
  CHECK(pool.argmax()(0, 1) == 0);
  Matrix<double> g(1, 2);
  g << 2, 7;
  pool.backward(exec::seq, x, y, g, &d);
  Matrix<double> expected(4, 2);
  expected << 0, 7, 2, 0, 0, 0, 0, 0;
  CHECK(d == expected);
}

TEST_CASE("nn::GroupPool: set_argmax routes the next backward through the given rows, broadcast or not") {
  std::mt19937_64 rng(53);
  std::uniform_int_distribution<int> size(1, 6);
  for (int trial = 0; trial < 20; ++trial) {
    const Index groups = size(rng), G = size(rng), C = size(rng);
    for (bool broadcast : {true, false}) {
      INFO("groups " << groups << " size " << G << " C " << C << " broadcast " << broadcast);
      nn::GroupPool<double> pool(nn::PoolKind::max, G, broadcast);
      const Matrix<double> x = random_matrix(rng, groups * G, C);
      Matrix<double> y, d;
      pool.forward(exec::seq, nn::Mode::train, x, y);
      nn::GroupPool<double>::ArgmaxIndices rows(groups, C);
      std::uniform_int_distribution<Index> row(0, G - 1);
      for (Index i = 0; i < rows.size(); ++i) rows.data()[i] = row(rng);
      pool.set_argmax(rows);
      CHECK(pool.argmax() == rows);
      const Matrix<double> g = random_matrix(rng, y.rows(), C);
      pool.backward(exec::seq, x, y, g, &d);
      // brute force: each group's gradient (summed over its rows when broadcast) lands on the chosen row only
      Matrix<double> expected = Matrix<double>::Zero(groups * G, C);
      for (Index q = 0; q < groups; ++q)
        for (Index c = 0; c < C; ++c)
          expected(q * G + rows(q, c), c) = broadcast ? g.middleRows(q * G, G).col(c).sum() : g(q, c);
      CHECK((d - expected).cwiseAbs().maxCoeff() <= 1e-14);
      // the next forward finds its own maxima again
      pool.forward(exec::seq, nn::Mode::train, x, y);
      for (Index q = 0; q < groups; ++q)
        for (Index c = 0; c < C; ++c) CHECK(x(q * G + pool.argmax()(q, c), c) == x.middleRows(q * G, G).col(c).maxCoeff());
    }
  }
  nn::GroupPool<double> pool(nn::PoolKind::max, 3, false), mean(nn::PoolKind::mean, 3, false);
  Matrix<double> y;
  nn::GroupPool<double>::ArgmaxIndices none(1, 2);
  none.setZero();
  CHECK_THROWS_AS(pool.set_argmax(none), ShapeError);  // before a forward
  pool.forward(exec::seq, nn::Mode::train, Matrix<double>::Zero(3, 2), y);
  mean.forward(exec::seq, nn::Mode::train, Matrix<double>::Zero(3, 2), y);
  CHECK_THROWS_AS(mean.set_argmax(none), ArgumentError);
  CHECK_THROWS_AS(pool.set_argmax(nn::GroupPool<double>::ArgmaxIndices::Zero(2, 2)), ShapeError);
  none(0, 1) = 3;
  CHECK_THROWS_WITH_AS(pool.set_argmax(none), doctest::Contains("group 0, channel 1: row 3 outside [0, 3)"), ArgumentError);
  none(0, 1) = 2;
  pool.set_argmax(none);
  CHECK(pool.argmax()(0, 1) == 2);
}

TEST_CASE("nn::GroupPool: gradients match finite differences (distinct values for max)") {
  std::mt19937_64 rng(52);
  std::uniform_int_distribution<int> size(1, 6);
  for (int trial = 0; trial < 8; ++trial) {
    const Index groups = size(rng), g = size(rng), C = size(rng);
    for (auto kind : {nn::PoolKind::max, nn::PoolKind::mean})
      for (bool broadcast : {true, false}) {
        INFO("groups " << groups << " size " << g << " C " << C << " max " << (kind == nn::PoolKind::max) << " broadcast " << broadcast);
        nn::GroupPool<double> pool(kind, g, broadcast);
        test::check_gradients(test::layer_gradient_check(pool, nullptr, distinct(rng, groups * g, C), nn::Mode::train, rng));
      }
  }
  nn::GroupPool<double> pool(nn::PoolKind::max, 3);
  Matrix<double> y;
  CHECK_THROWS_AS(pool.forward(exec::seq, nn::Mode::train, Matrix<double>(4, 2), y), ShapeError);
}

TEST_CASE("nn::GroupPool: seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(53);
  const Matrix<float> x = random_matrix(rng, 4 * 500, 64).cast<float>();
  for (auto kind : {nn::PoolKind::max, nn::PoolKind::mean}) {
    nn::GroupPool<float> global(kind, 500), edges(kind, 5, false);
    test::check_seq_equals_omp(global, (nn::ParameterStore<float>*)nullptr, x, nn::Mode::train, rng);
    test::check_seq_equals_omp(edges, (nn::ParameterStore<float>*)nullptr, x, nn::Mode::train, rng);
    test::check_warm_no_allocation(exec::omp, global, x, nn::Mode::train);
    test::check_warm_no_allocation(exec::seq, edges, x, nn::Mode::train);
  }
}
