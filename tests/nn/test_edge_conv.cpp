#include <simsr/neighbors/kd_tree.hpp>
#include <simsr/nn/edge_conv.hpp>

#include <type_traits>

#include "gradient_check.hpp"

using namespace simsr;
using nn::GraphIndices;
using nn::Matrix;
using test::random_matrix;

namespace {
GraphIndices random_graph(std::mt19937_64& rng, Index rows, Index N, Index k) {
  std::uniform_int_distribution<int> pick(0, int(N) - 1);
  GraphIndices g(rows, k);
  for (Index i = 0; i < g.size(); ++i) g.data()[i] = pick(rng);
  return g;
}
}  // namespace

TEST_CASE("nn::GraphFeatures: edge rows cat(h_j - h_i, h_i), shared and per-item graphs") {
  std::mt19937_64 rng(71);
  const Index B = 3, N = 6, k = 4, C = 5;
  const Matrix<double> h = random_matrix(rng, B * N, C);
  for (bool shared : {true, false}) {
    const GraphIndices g = random_graph(rng, shared ? N : B * N, N, k);
    nn::GraphFeatures<double> gf(g, N);
    Matrix<double> e;
    gf.forward(exec::seq, nn::Mode::train, h, e);
    REQUIRE(e.rows() == B * N * k);
    REQUIRE(e.cols() == 2 * C);
    for (Index b = 0; b < B; ++b)
      for (Index n = 0; n < N; ++n)
        for (Index j = 0; j < k; ++j) {
          const Index nb = g(shared ? n : b * N + n, j);
          for (Index c = 0; c < C; ++c) {
            CHECK(e((b * N + n) * k + j, c) == h(b * N + nb, c) - h(b * N + n, c));
            CHECK(e((b * N + n) * k + j, C + c) == h(b * N + n, c));
          }
        }
    test::check_gradients(test::layer_gradient_check(gf, nullptr, h, nn::Mode::train, rng));
  }
  GraphIndices bad(N, k);
  bad.setConstant(VIndex(N));
  CHECK_THROWS_AS(nn::GraphFeatures<double>(bad, N), ArgumentError);
  CHECK_THROWS_AS(nn::GraphFeatures<double>(GraphIndices::Zero(N + 1, k), N), ArgumentError);
  nn::GraphFeatures<double> gf(GraphIndices::Zero(N, k), N);
  Matrix<double> e;
  CHECK_THROWS_AS(gf.forward(exec::seq, nn::Mode::train, Matrix<double>(N + 1, C), e), ShapeError);
}

TEST_CASE("nn::GraphFeatures: seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(72);
  const Index B = 4, N = 300, k = 5;
  const Matrix<float> h = random_matrix(rng, B * N, 16).cast<float>();
  nn::GraphFeatures<float> gf(random_graph(rng, N, N, k), N);
  test::check_seq_equals_omp(gf, (nn::ParameterStore<float>*)nullptr, h, nn::Mode::train, rng);
  test::check_warm_no_allocation(exec::omp, gf, h, nn::Mode::train);
}

TEST_CASE("nn::DynamicKnnGraph: k nearest other points per item, matching a plain-loop reference") {
  std::mt19937_64 rng(73);
  const Index B = 3, N = 40, C = 7, k = 5;
  const Matrix<double> h = random_matrix(rng, B * N, C);
  nn::DynamicKnnGraph<double> dyn;
  GraphIndices g;
  dyn.build(exec::omp, h, N, k, g);
  REQUIRE(g.rows() == B * N);
  REQUIRE(g.cols() == k);
  for (Index b = 0; b < B; ++b)
    for (Index n = 0; n < N; ++n) {
      // reference: official top-(k+1) of -d², first column (self: distinct features) dropped
      std::vector<std::pair<double, Index>> d;
      for (Index m = 0; m < N; ++m) d.push_back({(h.row(b * N + m) - h.row(b * N + n)).squaredNorm(), m});
      std::sort(d.begin(), d.end());
      REQUIRE(d[0].second == n);
      for (Index j = 0; j < k; ++j) CHECK(g(b * N + n, j) == d[std::size_t(j + 1)].second);
    }
  // a column block of a wider matrix gives the same graph
  Matrix<double> wide(B * N, C + 3);
  wide.setZero();
  wide.leftCols(C) = h;
  GraphIndices g2;
  dyn.build(exec::seq, wide.leftCols(C), N, k, g2);
  CHECK(g2 == g);
  CHECK_THROWS_AS(dyn.build(exec::seq, h, N, N, g2), ArgumentError);
  CHECK_THROWS_AS(dyn.build(exec::seq, h, N + 1, k, g2), ShapeError);
}

TEST_CASE("nn::DynamicKnnGraph and EdgeConv: the search is one type (any neighbors::NeighborSearch), same graph") {
  static_assert(neighbors::NeighborSearch<neighbors::KdTree<double>>);
  static_assert(std::is_same_v<nn::EdgeConv<double>::scalar_type, double>);
  std::mt19937_64 rng(75);
  const Index B = 3, N = 40, C = 3, k = 5;
  const Matrix<double> h = random_matrix(rng, B * N, C);  // 3 feature columns: a KdTree applies
  nn::DynamicKnnGraph<double> brute;
  nn::DynamicKnnGraph<double, neighbors::KdTree<double>> tree;
  GraphIndices gb, gt;
  brute.build(exec::seq, h, N, k, gb);
  tree.build(exec::omp, h, N, k, gt);
  CHECK(gt == gb);
  // a search of fixed dimension refuses features of another width
  CHECK_THROWS_AS(tree.build(exec::seq, random_matrix(rng, B * N, C + 1), N, k, gt), ArgumentError);

  // a dynamic-graph EdgeConv with the other search: same weights (same seed), same bits
  nn::ParameterStore<double> s1, s2;
  nn::Rng i1(9), i2(9);
  nn::EdgeConv<double> e1(s1, "ec", C, 4, k, i1);
  nn::EdgeConv<double, neighbors::KdTree<double>> e2(s2, "ec", C, 4, k, i2);
  e1.use_dynamic_graph(N);
  e2.use_dynamic_graph(N);
  Matrix<double> y1, y2;
  e1.forward(exec::seq, nn::Mode::train, h, y1);
  e2.forward(exec::seq, nn::Mode::train, h, y2);
  CHECK(e2.graph() == e1.graph());
  CHECK(test::bitwise_equal(y1, y2));
}

TEST_CASE("nn::EdgeConv: state-dict names and forward against a plain-loop reference") {
  std::mt19937_64 rng(74);
  nn::Rng init(5);
  nn::ParameterStore<double> store;
  const Index B = 2, N = 7, C = 3, O = 4, k = 3;
  nn::EdgeConv<double> ec(store, "net_feat_emb.blocks.0", C, O, k, init);
  std::vector<std::string> names;
  for (const auto& e : store.entries()) names.push_back(e.name);
  const std::vector<std::string> expected{"net_feat_emb.blocks.0.edge_conv.0.weight",      "net_feat_emb.blocks.0.edge_conv.1.weight",
                                          "net_feat_emb.blocks.0.edge_conv.1.bias",        "net_feat_emb.blocks.0.edge_conv.1.running_mean",
                                          "net_feat_emb.blocks.0.edge_conv.1.running_var", "net_feat_emb.blocks.0.edge_conv.1.num_batches_tracked",
                                          "net_feat_emb.blocks.0.edge_conv.3.weight"};
  CHECK(names == expected);
  CHECK(store.entries()[0].shape == std::vector<Index>{2 * O, 2 * C, 1, 1});
  CHECK(store.entries()[6].shape == std::vector<Index>{O, 2 * O, 1, 1});
  ec.batch_norm().weight() = random_matrix(rng, 2 * O, 1);
  ec.batch_norm().bias() = random_matrix(rng, 2 * O, 1);

  const GraphIndices g = random_graph(rng, N, N, k);
  ec.set_graph(g, N);
  const Matrix<double> h = random_matrix(rng, B * N, C);
  Matrix<double> y;
  ec.forward(exec::seq, nn::Mode::eval, h, y);  // eval: running statistics (0, 1)
  const Matrix<double> W0 = ec.conv0().weight(), W3 = ec.conv3().weight();
  const auto gamma = ec.batch_norm().weight(), beta = ec.batch_norm().bias();
  REQUIRE(y.rows() == B * N);
  for (Index b = 0; b < B; ++b)
    for (Index n = 0; n < N; ++n)
      for (Index o = 0; o < O; ++o) {
        double best = -1e300;
        for (Index j = 0; j < k; ++j) {
          Eigen::VectorXd f(2 * C);
          for (Index c = 0; c < C; ++c) f[c] = h(b * N + g(n, j), c) - h(b * N + n, c), f[C + c] = h(b * N + n, c);
          Eigen::VectorXd a = W0 * f;
          for (Index i = 0; i < a.size(); ++i) {
            a[i] = a[i] / std::sqrt(1 + 1e-5) * gamma[i] + beta[i];
            a[i] = a[i] > 0 ? a[i] : 0.2 * a[i];
          }
          best = std::max(best, (W3.row(o) * a)(0, 0));
        }
        CHECK(std::abs(y(b * N + n, o) - best) < 1e-12);
      }
  CHECK_THROWS_AS(ec.set_graph(GraphIndices::Zero(N, k + 1), N), ArgumentError);
}

TEST_CASE("nn::EdgeConv: whole-module gradients match finite differences (fixed graph, train and eval)") {
  std::mt19937_64 rng(75);
  nn::Rng init(6);
  const Index B = 2, N = 6, C = 3, O = 4, k = 3;
  for (auto mode : {nn::Mode::train, nn::Mode::eval}) {
    nn::ParameterStore<double> store;
    nn::EdgeConv<double> ec(store, "blk", C, O, k, init);
    ec.batch_norm().weight() = random_matrix(rng, 2 * O, 1, 0.5, 1.5);
    ec.batch_norm().bias() = random_matrix(rng, 2 * O, 1);
    for (bool shared : {true, false}) {
      INFO("train " << (mode == nn::Mode::train) << " shared graph " << shared);
      ec.set_graph(random_graph(rng, shared ? N : B * N, N, k), N);
      test::check_gradients(test::layer_gradient_check(ec, &store, random_matrix(rng, B * N, C), mode, rng), 1e-5);
    }
  }
}

TEST_CASE("nn::EdgeConv: dynamic graph equals the explicit kNN graph; seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(76);
  nn::Rng init(7);
  const Index B = 3, N = 200, C = 8, O = 16, k = 5;
  nn::ParameterStore<float> store;
  nn::EdgeConv<float> ec(store, "blk", C, O, k, init);
  ec.use_dynamic_graph(N);
  const Matrix<float> h = random_matrix(rng, B * N, C).cast<float>();
  Matrix<float> y1, y2;
  ec.forward(exec::seq, nn::Mode::train, h, y1);
  nn::DynamicKnnGraph<float> dyn;
  GraphIndices g;
  dyn.build(exec::seq, h, N, k, g);
  CHECK(ec.graph() == g);
  nn::ParameterStore<float> store2;
  nn::Rng init2(7);
  nn::EdgeConv<float> fixed(store2, "blk", C, O, k, init2);
  fixed.set_graph(g, N);
  fixed.forward(exec::seq, nn::Mode::train, h, y2);
  CHECK(test::bitwise_equal(y1, y2));

  test::check_seq_equals_omp(ec, &store, h, nn::Mode::train, rng);
  test::check_seq_equals_omp(fixed, &store2, h, nn::Mode::eval, rng);
  test::check_warm_no_allocation(exec::omp, ec, h, nn::Mode::train);
  test::check_warm_no_allocation(exec::seq, fixed, h, nn::Mode::train);
}

TEST_CASE("nn::DynamicKnnGraph: the fused kNN kernel gives the blocked-GEMM kernel's graph; seq == omp") {
  std::mt19937_64 rng(77);
  for (const Index C : {3, 35, 64, 128}) {  // the embedding's feature widths (h⁰ 35, h¹ 64, h² 128) and a narrow one
    const Index B = 2, N = 333, k = 5;
    const Matrix<float> h = random_matrix(rng, B * N, C).cast<float>();
    nn::DynamicKnnGraph<float> fused;
    nn::DynamicKnnGraph<float, neighbors::BruteForceKnn<float, neighbors::SelfKernel::blocked_gemm>> gemm;
    GraphIndices gs, go, gb;
    fused.build(exec::seq, h, N, k, gs);
    fused.build(exec::omp, h, N, k, go);
    gemm.build(exec::omp, h, N, k, gb);
    CHECK(go == gs);
    CHECK(gb == gs);  // random features: no exact ties
  }
}
