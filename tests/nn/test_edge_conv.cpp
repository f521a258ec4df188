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

namespace {
/// The edge MLP of `ec` run per edge on the gathered rows cat(h_j − h_i, h_i) (Mlp's eval path,
/// its first Linear per edge), then the max over each point's k edges: EdgeConv's eval forward
/// before the point-wise first layer.
template <class S>
Matrix<S> per_edge_eval(nn::EdgeConv<S>& ec, const Matrix<S>& h, Index N) {
  nn::GraphFeatures<S> gf(ec.graph(), N);
  Matrix<S> edges, values;
  gf.forward(exec::seq, nn::Mode::eval, h, edges);
  ec.edge_function().forward(exec::seq, nn::Mode::eval, edges, values);
  const Index k = ec.k();
  Matrix<S> y(h.rows(), values.cols());
  for (Index r = 0; r < h.rows(); ++r) y.row(r) = values.middleRows(r * k, k).colwise().maxCoeff();
  return y;
}
}  // namespace

TEST_CASE("nn::EdgeConv: the eval path's point-wise first layer gives the per-edge edge MLP's values (random shapes, both edge functions)") {
  std::mt19937_64 rng(78);
  std::uniform_int_distribution<int> dim(1, 9), kk(1, 6), items(1, 3);
  for (int trial = 0; trial < 40; ++trial) {
    const Index B = items(rng), N = 8 + dim(rng), C = dim(rng), O = dim(rng), k = kk(rng);
    const bool official = trial % 2 == 0, shared = trial % 3 != 0;
    INFO("trial " << trial << ": B " << B << " N " << N << " C " << C << " O " << O << " k " << k << " official " << official);
    typename nn::EdgeConv<double>::Options opt;
    opt.edge_mlp = official ? nn::EdgeConv<double>::EdgeMlp::official : nn::EdgeConv<double>::EdgeMlp::single_linear;
    nn::ParameterStore<double> sd;
    nn::ParameterStore<float> sf;
    nn::Rng id(trial), iff(trial);
    nn::EdgeConv<double> ecd(sd, "ec", C, O, k, id, opt);
    typename nn::EdgeConv<float>::Options optf;
    optf.edge_mlp = official ? nn::EdgeConv<float>::EdgeMlp::official : nn::EdgeConv<float>::EdgeMlp::single_linear;
    nn::EdgeConv<float> ecf(sf, "ec", C, O, k, iff, optf);
    if (official) {  // running statistics and affine parameters away from the identity
      ecd.batch_norm().running_mean() = random_matrix(rng, 2 * O, 1);
      ecd.batch_norm().running_var() = random_matrix(rng, 2 * O, 1, 0.3, 2.0);
      ecd.batch_norm().weight() = random_matrix(rng, 2 * O, 1, 0.5, 1.5);
      ecd.batch_norm().bias() = random_matrix(rng, 2 * O, 1);
    }
    sf.values() = sd.values().cast<float>();
    sf.buffers() = sd.buffers().cast<float>();
    const GraphIndices g = random_graph(rng, shared ? N : B * N, N, k);
    ecd.set_graph(g, N);
    ecf.set_graph(g, N);
    // features far from the origin beside their differences: the point-wise form's cancellation
    Matrix<double> h = random_matrix(rng, B * N, C, -1.0, 1.0);
    h.rowwise() += random_matrix(rng, 1, C, -20.0, 20.0).row(0);
    const Matrix<float> hf = h.cast<float>();
    Matrix<double> yd;
    Matrix<float> yf, yf_omp;
    ecd.forward(exec::seq, nn::Mode::eval, h, yd);
    ecf.forward(exec::seq, nn::Mode::eval, hf, yf);
    ecf.forward(exec::omp, nn::Mode::eval, hf, yf_omp);
    CHECK(test::bitwise_equal(yf, yf_omp));
    const Matrix<double> refd = per_edge_eval(ecd, h, N);
    const Matrix<float> reff = per_edge_eval(ecf, hf, N);
    const double scale = 1.0 + refd.cwiseAbs().maxCoeff();
    CHECK((yd - refd).cwiseAbs().maxCoeff() <= 1e-12 * scale * 20);
    CHECK((yf - reff).cwiseAbs().maxCoeff() <= 2e-5 * scale * 20);
  }
}
