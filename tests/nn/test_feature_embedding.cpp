#include <simsr/nn/feature_embedding.hpp>

#include "gradient_check.hpp"

using namespace simsr;
using nn::GraphIndices;
using nn::Matrix;
using test::random_matrix;

TEST_CASE("nn::EmbeddingBlock: the eval forward (fc_out on the parts, global features once per item) gives fc_out of the concatenation") {
  std::mt19937_64 rng(95);
  std::uniform_int_distribution<int> dim(2, 9), items(1, 3);
  for (int trial = 0; trial < 16; ++trial) {
    nn::NetworkConfig cfg = nn::NetworkConfig::official();
    cfg.knn = 3;
    cfg.fc_out_batch_norm = trial % 2 == 0;
    cfg.edge_batch_norm = trial % 4 < 2;
    const Index B = items(rng), N = 10 + dim(rng), in = dim(rng), out = dim(rng);
    INFO("trial " << trial << ": B " << B << " N " << N << " in " << in << " out " << out);
    nn::ParameterStore<float> store;
    nn::Rng init(trial);
    std::uniform_int_distribution<int> pick(0, int(N) - 1);
    GraphIndices g(N, cfg.knn);
    for (Index i = 0; i < g.size(); ++i) g.data()[i] = pick(rng);
    const bool dynamic = trial % 3 == 0;
    nn::EmbeddingBlock<float> block(store, "blk", cfg, in, out, N, dynamic ? nullptr : &g, init);
    for (const auto& e : store.entries())  // running statistics away from 0 and 1
      if (e.kind == nn::TensorEntry::Kind::buffer && (e.name.ends_with("running_mean") || e.name.ends_with("running_var")))
        store.buffers().segment(e.offset, e.size) =
            random_matrix(rng, e.size, 1, e.name.ends_with("running_var") ? 0.3 : -1.0, e.name.ends_with("running_var") ? 2.0 : 1.0).cast<float>();
    const Matrix<float> h = random_matrix(rng, B * N, in, -2.0, 2.0).cast<float>();
    Matrix<float> y, y_omp, cat, ref;
    block.forward(exec::seq, nn::Mode::eval, h, y);
    // the reference: fc_out on cat(h, e, max over the item, mean over the item) of the same edge output
    const Matrix<float> e = block.edge_output();
    cat.resize(B * N, in + 3 * out);
    for (Index b = 0; b < B; ++b) {
      const auto eb = e.middleRows(b * N, N);
      const Eigen::RowVectorXf mx = eb.colwise().maxCoeff(), mean = eb.colwise().mean();
      for (Index n = 0; n < N; ++n) cat.row(b * N + n) << h.row(b * N + n), eb.row(n), mx, mean;
    }
    block.fc_out().forward(exec::seq, nn::Mode::eval, cat, ref);
    const float scale = 1.0f + ref.cwiseAbs().maxCoeff();
    CHECK((y - ref).cwiseAbs().maxCoeff() <= 2e-6f * scale * float(in + 3 * out));
    block.forward(exec::omp, nn::Mode::eval, h, y_omp);
    CHECK(test::bitwise_equal(y, y_omp));
    // a backward after the eval forward: finite differences and seq == omp still hold
    test::check_seq_equals_omp(block, &store, h, nn::Mode::eval, rng);
    test::check_warm_no_allocation(exec::seq, block, h, nn::Mode::eval);
  }
}

TEST_CASE("nn::EmbeddingBlock: gradients after the eval forward match finite differences") {
  std::mt19937_64 rng(96);
  nn::NetworkConfig cfg = nn::NetworkConfig::official();
  cfg.knn = 3;
  const Index B = 2, N = 9, in = 3, out = 4;
  nn::ParameterStore<double> store;
  nn::Rng init(3);
  std::uniform_int_distribution<int> pick(0, int(N) - 1);
  GraphIndices g(N, cfg.knn);
  for (Index i = 0; i < g.size(); ++i) g.data()[i] = pick(rng);
  nn::EmbeddingBlock<double> block(store, "blk", cfg, in, out, N, &g, init);
  test::check_gradients(test::layer_gradient_check(block, &store, random_matrix(rng, B * N, in), nn::Mode::eval, rng), 1e-5);
}
