#include "gradient_check.hpp"
#include "network_fixture.hpp"

#include <simsr/nn/inference_net.hpp>

#include <algorithm>
#include <numeric>

using namespace simsr;
using nn::ConstView;
using nn::Matrix;

namespace {

/// A random network of `cfg` with random weights where a fresh one has zeros (a residual
/// network's output layer) and random BatchNorm running statistics.
template <class S>
std::unique_ptr<nn::SuperResolutionNet<S>> random_network(const nn::NetworkConfig& cfg, const nn::NetworkGeometry& geo, std::mt19937_64& rng,
                                                          std::uint64_t seed) {
  nn::Rng init(seed);
  auto net = std::make_unique<nn::SuperResolutionNet<S>>(cfg, geo, init);
  if (cfg.residual) {
    for (const char* n : {"net_decoder.decoder.last_layer.fc.weight", "net_decoder.decoder.last_layer.fc.bias"})
      for (S& v : net->store().values(net->store().at(n))) v = static_cast<S>(std::uniform_real_distribution<double>(-0.5, 0.5)(rng));
  }
  for (S& v : net->store().buffers()) v = static_cast<S>(std::uniform_real_distribution<double>(0.5, 1.5)(rng));  // running means and variances
  if (cfg.residual && cfg.residual_base == nn::ResidualBase::local_linear) {
    // a random 3M×3N map, 5 entries per row
    const Index M = geo.hr_rest.rows(), N = geo.lr_rest.rows();
    std::vector<Eigen::Triplet<double>> t;
    std::uniform_int_distribution<Index> col(0, 3 * N - 1);
    std::uniform_real_distribution<double> val(-0.4, 0.4);
    for (Index r = 0; r < 3 * M; ++r)
      for (int e = 0; e < 5; ++e) t.emplace_back(r, col(rng), val(rng));
    Eigen::SparseMatrix<double, Eigen::RowMajor> map(3 * M, 3 * N);
    map.setFromTriplets(t.begin(), t.end());
    net->set_residual_map(map);
  }
  return net;
}

/// The kernels' ranking key: S(√Σ_c (h_r,c − h_q,c)²), the sum in double over c ascending.
template <class S>
S feature_distance(const Matrix<S>& h, Index r, Index q) {
  double acc = 0;
  for (Index c = 0; c < h.cols(); ++c) acc += (double(h(r, c)) - double(h(q, c))) * (double(h(r, c)) - double(h(q, c)));
  return static_cast<S>(std::sqrt(acc));
}

/// Each row's k nearest other rows of its item by that key, ties by ascending index: a full sort.
template <class S>
nn::GraphIndices exact_feature_graph(const Matrix<S>& h, Index N, Index k) {
  nn::GraphIndices g(h.rows(), k);
  for (Index r = 0; r < h.rows(); ++r) {
    const Index item = r / N;
    std::vector<Index> order;
    for (Index n = 0; n < N; ++n)
      if (n != r % N) order.push_back(n);
    std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return feature_distance(h, r, item * N + a) < feature_distance(h, r, item * N + b); });
    for (Index j = 0; j < k; ++j) g(r, j) = VIndex(order[std::size_t(j)]);
  }
  return g;
}

/// InferenceNet<S, HostBuffer> (the device path's launches on host memory) against the network's
/// own infer with the unsplit decoder (= its eval forward), seq == omp bitwise, the dynamic graphs
/// the exact ones.
template <class S>
void check_inference_net(const nn::NetworkConfig& cfg, Index N, Index M, Index B, std::uint64_t seed, double tol) {
  CAPTURE(seed);
  CAPTURE(sizeof(S));
  CAPTURE(N);
  CAPTURE(B);
  std::mt19937_64 rng(seed);
  const auto geo = test::small_network_geometry(rng, N, M, cfg);
  auto net = random_network<S>(cfg, geo, rng, seed + 100);
  const Matrix<S> ldx = test::random_matrix(rng, B * N, 3, -0.5, 0.5).template cast<S>();
  net->set_decoder_first_layer_on_lr(false);
  Matrix<S> expected, got_seq, got_omp;
  net->infer(exec::omp, ldx, expected);

  nn::HostInferenceNet<S> plan(exec::omp, *net);
  CHECK(plan.lr_points() == N);
  CHECK(plan.hr_points() == M);
  plan.infer(exec::seq, ldx, got_seq);
  const std::vector<nn::GraphIndices> graphs_seq = [&] {
    std::vector<nn::GraphIndices> g;
    if (net->has_feature_embedding())
      for (Index b = 1; b < net->feature_embedding().blocks(); ++b) g.push_back(plan.dynamic_graph(b));
    return g;
  }();
  plan.infer(exec::omp, ldx, got_omp);
  CHECK(test::bitwise_equal(got_seq, got_omp));
  REQUIRE(got_seq.rows() == expected.rows());
  REQUIRE(got_seq.cols() == 3);
  const double scale = std::max(1.0, double(expected.cwiseAbs().maxCoeff()));
  CHECK(double((got_seq - expected).cwiseAbs().maxCoeff()) <= tol * scale);
  // the code z = [h⁰, h¹, …] is the network's up to rounding
  const Matrix<S> z = plan.code();
  REQUIRE(z.rows() == net->code().rows());
  CHECK(double((z - net->code()).cwiseAbs().maxCoeff()) <= tol * std::max(1.0, double(net->code().cwiseAbs().maxCoeff())));
  // the dynamic graphs: the exact k nearest of the plan's own features by the kernel's key, under
  // either policy (not compared with the network's: its features differ by rounding, and random
  // BatchNorm statistics collapse some blocks' rows to ~1e-6 relative differences, where rounding
  // reorders neighbours; there BruteForceKnn's candidate pass, ‖a‖² + ‖b‖² − 2a·b in S, cannot
  // resolve them either)
  if (net->has_feature_embedding()) {
    CHECK_THROWS_AS((void)plan.dynamic_graph(0), ArgumentError);  // block 0's graph is fixed
    Index col = cfg.emb_feat_dims[0];
    for (Index b = 1; b < net->feature_embedding().blocks(); ++b) {
      CAPTURE(b);
      const Index width = cfg.emb_feat_dims[std::size_t(b)];
      const Matrix<S> h = z.middleCols(col, width);  // block b's input h^b (dropout is the identity in eval)
      col += width;
      const nn::GraphIndices ours = plan.dynamic_graph(b);
      CHECK(graphs_seq[std::size_t(b - 1)] == ours);
      CHECK(ours == exact_feature_graph(h, N, cfg.knn));
    }
  }
}

}  // namespace

TEST_CASE("nn::InferenceNet (host memory): the device path's launches give SuperResolutionNet::infer's prediction, profiles and ablations") {
  std::mt19937_64 pick(31);
  for (int trial = 0; trial < 28; ++trial) {
    nn::NetworkConfig cfg = test::tiny_config(trial % 2 ? nn::NetworkConfig::paper() : nn::NetworkConfig::official());
    switch (trial % 7) {
      case 2: cfg.disable_feature_embedding(); break;
      case 3: cfg.upsampling = nn::UpsamplingKind::table; break;
      case 4: cfg.residual = true; break;  // over the embedding
      case 5:
        cfg.residual = true;
        cfg.residual_base = nn::ResidualBase::local_linear;
        break;
      case 6:  // two dynamic blocks
        cfg.emb_feat_dims = {7, 5, 6, 4};
        cfg.decoder_dims.front() = 7 + 5 + 6 + 4;
        cfg.validate();
        break;
      default: break;
    }
    const Index N = 20 + Index(pick() % 30), M = N + 10 + Index(pick() % 60), B = 1 + Index(pick() % 3);
    const std::uint64_t seed = pick();
    check_inference_net<double>(cfg, N, M, B, seed, 1e-12);
    check_inference_net<float>(cfg, N, M, B, seed, 2e-5);
  }
}

TEST_CASE("nn::detail::FeatureKnnRows: the k nearest other rows of each item, ties by ascending index, against a brute-force sort") {
  std::mt19937_64 rng(8);
  for (int trial = 0; trial < 40; ++trial) {
    const Index N = 6 + Index(rng() % 20), B = 1 + Index(rng() % 3), C = 1 + Index(rng() % 5), k = 1 + Index(rng() % (N - 1));
    CAPTURE(trial);
    // small integer features: many exact ties and duplicate rows
    Matrix<float> h(B * N, C);
    for (Index i = 0; i < h.size(); ++i) h.data()[i] = float(Index(rng() % 3));
    nn::GraphIndices graph(B * N, k);
    Matrix<float> dist(B * N, k);
    exec::parallel_for(exec::omp, B * N, nn::detail::FeatureKnnRows<float>{{h.data(), B * N, C, C}, N, k, graph.data(), dist.data()});
    for (Index r = 0; r < B * N; ++r) {
      const Index item = r / N, self = r % N;
      std::vector<Index> order;
      for (Index n = 0; n < N; ++n)
        if (n != self) order.push_back(n);
      auto d = [&](Index n) { return (h.row(r) - h.row(item * N + n)).cast<double>().norm(); };
      std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return d(a) < d(b); });
      for (Index j = 0; j < k; ++j) {
        CHECK(graph(r, j) == order[std::size_t(j)]);
        CHECK(dist(r, j) == float(d(order[std::size_t(j)])));
      }
    }
  }
}

TEST_CASE("nn::InferenceNet: bad shapes and strides are refused; a warm infer allocates nothing") {
  std::mt19937_64 rng(4);
  const nn::NetworkConfig cfg = test::tiny_config(nn::NetworkConfig::official());
  const auto geo = test::small_network_geometry(rng, 30, 40, cfg);
  auto net = random_network<float>(cfg, geo, rng, 5);
  nn::HostInferenceNet<float> plan(exec::seq, *net);
  Matrix<float> ldx = test::random_matrix(rng, 60, 3).cast<float>(), pred(80, 3);
  CHECK_THROWS_AS(plan.infer(exec::seq, Matrix<float>::Zero(59, 3), pred), ShapeError);
  CHECK_THROWS_AS(plan.infer(exec::seq, Matrix<float>::Zero(60, 2), pred), ShapeError);
  const MatrixSpan<const float> in{ldx.data(), 60, 3, 3};
  CHECK_THROWS_AS(plan.infer(exec::seq, in, MatrixSpan<float>{pred.data(), 40, 3, 3}), ShapeError);  // B·M rows are 80
  CHECK_THROWS_AS(plan.infer(exec::seq, MatrixSpan<const float>{ldx.data(), 60, 3, 2}, MatrixSpan<float>{pred.data(), 80, 3, 3}), ArgumentError);
  CHECK_THROWS_AS((void)plan.dynamic_graph(1), ArgumentError);  // no infer yet
  plan.infer(exec::omp, in, MatrixSpan<float>{pred.data(), 80, 3, 3});
  const long before = simsr_test_malloc_count();
  plan.infer(exec::omp, in, MatrixSpan<float>{pred.data(), 80, 3, 3});
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before);
  // the host-array call: warm, it allocates nothing either; a column block (row stride 5) is packed
  Matrix<float> host_pred;
  plan.infer(exec::omp, ldx, host_pred);
  const long before_host = simsr_test_malloc_count();
  plan.infer(exec::omp, ldx, host_pred);
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, simsr_test_malloc_count() - before_host);
  CHECK(host_pred == pred);
  Matrix<float> wide(60, 5), strided_pred;
  wide.leftCols(3) = ldx;
  plan.infer(exec::seq, ConstView<float>(wide.leftCols(3)), strided_pred);
  CHECK(strided_pred == pred);
  Matrix<float> expected;
  net->set_decoder_first_layer_on_lr(false);
  net->infer(exec::seq, ldx, expected);
  CHECK((pred - expected).cwiseAbs().maxCoeff() <= 2e-5f * std::max(1.0f, expected.cwiseAbs().maxCoeff()));
}
