/// The super-resolution network (profile `official`) at the paper's sizes and on the bunny:
///  - BM_official_forward_paper_size/{seq,omp}: inference (eval mode; the upsampling weights are
///    precomputed once by prepare_inference(policy) outside the loop, then infer(policy, …) per frame) with
///    up_k = 20 at N = 15,872 LR and M = 35,637 HR vertices, B = 1 (issue #4's "about a second
///    per frame on 2 cores").
///  - BM_official_forward_paper_size/{seq,omp}/baseline_blocked_gemm_knn: the same with the dynamic
///    feature graph's earlier kernel (neighbors::SelfKernel::blocked_gemm; issue #17 item 4's
///    baseline, run beside the default fused kernel).
///  - BM_official_forward_paper_size/{seq,omp}/baseline_per_edge_first_layers: the same with the
///    eval layers unfactorized (FeatureEmbedding::set_factorized_eval(false)): EdgeConv's first
///    Linear per edge instead of per point, fc_out's first Linear on the stored concatenation
///    cat(h, e, max, mean) instead of its parts with the global features once per item.
///  - BM_official_forward_paper_size/{seq,omp}/baseline_decoder_first_layer_on_hr: the same with the
///    decoder's first Linear on the M upsampled rows (SuperResolutionNet::set_decoder_first_layer_on_lr(false))
///    instead of on the N LR rows before the upsampling.
///  - BM_official_dynamic_knn_paper_size/{fused,blocked_gemm}/{seq,omp}: that graph alone (k = 5
///    nearest other points of the N = 15,872 rows of h¹, 64 features, as block 1's EdgeConv builds
///    it) on the features of one inference; the setup checks that both kernels give the same graph
///    (it reports an error otherwise).
///  - BM_official_dynamic_knn_paper_size/fused/omp/baseline_unshared_thresholds: the fused kernel with
///    each worker filtering by its own candidate lists alone (BruteForceKnnParams::share_thresholds).
///  - BM_official_forward_train_mode_paper_size/omp: forward(Mode::train), B = 1, same sizes
///    (f_θ over the M·upK = 712,740 queries at every call, BatchNorm on batch statistics).
///  - BM_official_train_step_bunny/omp/B:{32,8}: one training step on the bunny (zero_grad,
///    forward(train), SuperResolutionLoss::evaluate, backward, Adam step), official config (knn 5,
///    upK 10), frames 0..B-1 of train_frames.npz normalized as dataset.py (counter: the loss).
/// Synthetic paper-size geometry: benchmarks/paper_network.hpp (shared with bench_cuda). Weights: the seeded
/// initialization (timings do not depend on them).
/// PyTorch peer: scripts/peers/nn_bench_peer.py.
#include <benchmark/benchmark.h>

#include "bench_data.hpp"
#include "paper_network.hpp"

#include <simsr/io/npz.hpp>
#include <simsr/io/npy.hpp>
#include <simsr/io/obj.hpp>
#include <simsr/neighbors/brute_force_knn.hpp>
#include <simsr/neighbors/kd_tree.hpp>
#include <simsr/nn/adam.hpp>
#include <simsr/nn/super_resolution_loss.hpp>
#include <simsr/nn/super_resolution_net.hpp>
#include <simsr/nn/trainer.hpp>

#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <random>
#include <type_traits>

using namespace simsr;
using nn::Matrix;
using namespace simsr::bench;

namespace {

/// The inference's exact rewrites (issue #17 item 4), each switched off in its baseline row.
struct ForwardRewrites {
  bool factorized_eval = true;            ///< EdgeConv's first Linear per point, fc_out on its parts
  bool decoder_first_layer_on_lr = true;  ///< the decoder's first Linear before the upsampling
};

template <class Search, exec::HostPolicy Policy>
void BM_official_forward_paper_size(Policy policy, benchmark::State& state, ForwardRewrites rewrites = {}) {
  nn::Rng rng(0);
  nn::SuperResolutionNet<float, Search> net(paper_config(), paper_geo(), rng);
  net.feature_embedding().set_factorized_eval(rewrites.factorized_eval);
  net.set_decoder_first_layer_on_lr(rewrites.decoder_first_layer_on_lr);
  const Matrix<float> ldx = paper_ldx(1);
  Matrix<float> pred;
  net.prepare_inference(policy);
  net.infer(policy, ldx, pred);  // warm the buffers
  for (auto _ : state) {
    net.infer(policy, ldx, pred);
    benchmark::DoNotOptimize(pred.data());
  }
}

void BM_official_forward_train_mode_paper_size(benchmark::State& state) {
  nn::Rng rng(0);
  nn::SuperResolutionNet<float> net(paper_config(), paper_geo(), rng);
  const Matrix<float> ldx = paper_ldx(1);
  Matrix<float> pred;
  net.forward(exec::omp, nn::Mode::train, ldx, pred);
  for (auto _ : state) {
    net.forward(exec::omp, nn::Mode::train, ldx, pred);
    benchmark::DoNotOptimize(pred.data());
  }
}

/// The bunny: geometry as scripts/torch_to_simsr.py writes it, frames normalized as dataset.py.
struct Bunny {
  nn::NetworkGeometry geo;
  Tris hr_faces;
  io::NpyArray low, high;  // frames × N × 3 raw positions (train_frames.npz)
};

const Bunny* bunny() {
  static std::unique_ptr<Bunny> b = []() -> std::unique_ptr<Bunny> {
    const auto dir = data_dir() / "bunny";
    if (!std::filesystem::exists(dir / "train_frames.npz")) return nullptr;
    auto x = std::make_unique<Bunny>();
    const auto cfg = nn::NetworkConfig::official();
    const auto lr = io::read_obj_tets<double>(dir / "lrestshape.obj");
    const auto hr = io::read_obj_triangles<double>(dir / "hrestshape.obj");
    x->geo.lr_rest = lr.V;
    x->geo.hr_rest = hr.V;
    x->hr_faces = hr.F;
    x->geo.lr_graph = io::read_npy(dir / "geo_dist_tet2tet_idx.npy").to_matrix<VIndex>().leftCols(cfg.knn);
    x->geo.up_indices = io::read_npy(dir / "geo_dist_surf2tet_idx.npy").to_matrix<VIndex>().leftCols(cfg.up_k);
    x->geo.up_distances = io::read_npy(dir / "geo_dist_surf2tet.npy").to_matrix<double>().leftCols(cfg.up_k);
    io::NpzReader z(dir / "train_frames.npz");
    x->low = z.read("lowres");
    x->high = z.read("highres");
    return x;
  }();
  return b.get();
}

/// The bunny, or nullptr with the benchmark marked skipped (no data).
const Bunny* bunny_or_skip(benchmark::State& state) {
  const Bunny* b = bunny();
  if (!b) state.SkipWithError("bunny data not found (SIMSR_DATA_DIR/bunny)");
  return b;
}

/// The first B bunny frames ((B·rows)×3) as displacements from `rest_normalized`, in the network's
/// units: dataset.py's order (positions parsed to float32, normalized in float32, the rest subtracted).
Matrix<float> bunny_displacements(const io::NpyArray& frames, const Matrix<float>& rest_normalized, const nn::NetworkConfig& cfg, Index B) {
  const Index rows = rest_normalized.rows();
  Matrix<float> d(B * rows, 3);
  for (Index f = 0; f < B; ++f)
    nn::normalized_displacements(frames.frame_points(f), rest_normalized, cfg.norm_mean, cfg.norm_std, d.middleRows(f * rows, rows));
  return d;
}

void BM_official_train_step_bunny(benchmark::State& state) {
  const Bunny* b = bunny_or_skip(state);
  if (!b) return;
  const Index B = state.range(0);
  const auto cfg = nn::NetworkConfig::official();
  nn::Rng rng(0);
  nn::SuperResolutionNet<float> net(cfg, b->geo, rng);
  const Matrix<float> ldx = bunny_displacements(b->low, net.lr_rest_normalized(), cfg, B), hdx = bunny_displacements(b->high, net.hr_rest_normalized(), cfg, B);
  nn::SuperResolutionLoss<float> loss(cfg, net.hr_rest_normalized(), b->hr_faces);
  nn::Adam<float> adam(net.store(), {.lr = cfg.lr});
  Matrix<float> pred, d_pred, d_z;
  auto step = [&] {
    net.store().zero_grad();
    net.forward(exec::omp, nn::Mode::train, ldx, pred);
    const auto t = loss.evaluate(exec::omp, pred, hdx, net.code(), 0, &d_pred, &d_z);
    net.backward(exec::omp, d_pred, &d_z);
    adam.step(exec::omp);
    return t.total;
  };
  step();  // warm
  double total = 0;
  for (auto _ : state) total = step();
  state.counters["loss"] = total;
}

/// One optimizer step through nn::Trainer (an epoch of B frames in one batch): the per-item path
/// of data-parallel training (nn/batch_split.hpp) on one process, beside BM_official_train_step_bunny
/// at the same B (the plain whole-batch step): their ratio is what the rank-independent order costs.
void BM_trainer_step_bunny(benchmark::State& state) {
  const Bunny* b = bunny_or_skip(state);
  if (!b) return;
  const Index B = state.range(0);
  auto cfg = nn::NetworkConfig::official();
  cfg.batch_size = B;
  nn::Rng rng(0);
  nn::SuperResolutionNet<float> net(cfg, b->geo, rng);
  std::vector<Index> which(static_cast<std::size_t>(B));
  for (Index f = 0; f < B; ++f) which[std::size_t(f)] = f;
  nn::Trainer<float> trainer(net, b->hr_faces, nn::training_frames<float>(cfg, b->geo.lr_rest, b->geo.hr_rest, b->low, b->high, which),
                             {.epochs = 1 << 20, .seed = 0, .progress = false});
  trainer.run_epoch(exec::omp);  // warm
  for (auto _ : state) trainer.run_epoch(exec::omp);
}

/// The upsampling's part of one training step on the bunny (B frames): f_θ's forward and backward
/// on the M·upK queries of the rest shapes (batch-independent) and the gather, beside
/// BM_official_train_step_bunny at the same B: f_θ's rows are not batch rows, so data-parallel
/// training splits them among the ranks separately (groups of HR vertices, coordinate_upsampling.hpp);
/// computed whole on every rank, this ratio would be the part R ranks do not divide.
void BM_upsampling_step_bunny(benchmark::State& state) {
  const Bunny* b = bunny_or_skip(state);
  if (!b) return;
  const Index B = state.range(0);
  const auto cfg = nn::NetworkConfig::official();
  nn::Rng rng(0);
  nn::SuperResolutionNet<float> net(cfg, b->geo, rng);
  const Matrix<float> ldx = bunny_displacements(b->low, net.lr_rest_normalized(), cfg, B);
  Matrix<float> pred, zh, d_zh, d_z;
  net.forward(exec::omp, nn::Mode::train, ldx, pred);  // the code z the upsampling reads
  const Matrix<float> z = net.code();
  auto& up = net.upsampling();
  auto step = [&] {
    up.forward(exec::omp, nn::Mode::train, z, zh);
    d_zh = zh;  // any gradient of the same shape
    up.backward(exec::omp, z, d_zh, &d_z);
  };
  step();  // warm
  for (auto _ : state) step();
  state.counters["query_rows"] = double(net.hr_points() * cfg.up_k);
}

using FusedKnn = neighbors::BruteForceKnn<float>;
using BaselineKnn = neighbors::BruteForceKnn<float, neighbors::SelfKernel::blocked_gemm>;
void BM_official_forward_paper_size_seq(benchmark::State& s) { BM_official_forward_paper_size<FusedKnn>(exec::seq, s); }
void BM_official_forward_paper_size_omp(benchmark::State& s) { BM_official_forward_paper_size<FusedKnn>(exec::omp, s); }
void BM_official_forward_paper_size_seq_baseline(benchmark::State& s) { BM_official_forward_paper_size<BaselineKnn>(exec::seq, s); }
void BM_official_forward_paper_size_omp_baseline(benchmark::State& s) { BM_official_forward_paper_size<BaselineKnn>(exec::omp, s); }
void BM_official_forward_paper_size_seq_per_edge(benchmark::State& s) { BM_official_forward_paper_size<FusedKnn>(exec::seq, s, {.factorized_eval = false}); }
void BM_official_forward_paper_size_omp_per_edge(benchmark::State& s) { BM_official_forward_paper_size<FusedKnn>(exec::omp, s, {.factorized_eval = false}); }
void BM_official_forward_paper_size_seq_decoder_on_hr(benchmark::State& s) {
  BM_official_forward_paper_size<FusedKnn>(exec::seq, s, {.decoder_first_layer_on_lr = false});
}
void BM_official_forward_paper_size_omp_decoder_on_hr(benchmark::State& s) {
  BM_official_forward_paper_size<FusedKnn>(exec::omp, s, {.decoder_first_layer_on_lr = false});
}

/// h¹ of one inference at the paper's size: the rows block 1's dynamic graph is built on.
const FusedKnn::point_matrix& paper_block1_features() {
  static const FusedKnn::point_matrix h1 = [] {
    nn::Rng rng(0);
    nn::SuperResolutionNet<float> net(paper_config(), paper_geo(), rng);
    Matrix<float> pred;
    net.prepare_inference(exec::omp);
    net.infer(exec::omp, paper_ldx(1), pred);
    return FusedKnn::point_matrix(net.feature_embedding().block_output(0));
  }();
  return h1;
}

template <class Knn, exec::HostPolicy Policy>
void BM_official_dynamic_knn_paper_size(Policy policy, benchmark::State& state, bool share_thresholds = true) {
  const auto& h1 = paper_block1_features();
  const Index k = paper_config().knn;
  Knn knn(h1, {.share_thresholds = share_thresholds});
  neighbors::KnnResult<float> r, other;
  knn.query_self_into(policy, k, r, true);
  // the other kernel's graph, once: the rows must agree (exact ties aside; the features have none)
  using Other = std::conditional_t<std::is_same_v<Knn, FusedKnn>, BaselineKnn, FusedKnn>;
  Other(h1).query_self_into(exec::omp, k, other, true);
  if (r.indices != other.indices || r.distances != other.distances) state.SkipWithError("the fused and blocked-GEMM kernels' graphs differ");
  for (auto _ : state) {
    knn.query_self_into(policy, k, r, true);
    benchmark::DoNotOptimize(r.indices.data());
  }
  state.counters["features"] = double(h1.cols());
}
void BM_dynamic_knn_fused_seq(benchmark::State& s) { BM_official_dynamic_knn_paper_size<FusedKnn>(exec::seq, s); }
void BM_dynamic_knn_fused_omp(benchmark::State& s) { BM_official_dynamic_knn_paper_size<FusedKnn>(exec::omp, s); }
void BM_dynamic_knn_fused_unshared_omp(benchmark::State& s) { BM_official_dynamic_knn_paper_size<FusedKnn>(exec::omp, s, false); }
void BM_dynamic_knn_gemm_seq(benchmark::State& s) { BM_official_dynamic_knn_paper_size<BaselineKnn>(exec::seq, s); }
void BM_dynamic_knn_gemm_omp(benchmark::State& s) { BM_official_dynamic_knn_paper_size<BaselineKnn>(exec::omp, s); }

}  // namespace

BENCHMARK(BM_official_forward_paper_size_seq)->Name("BM_official_forward_paper_size/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_official_forward_paper_size_omp)->Name("BM_official_forward_paper_size/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_official_forward_paper_size_seq_baseline)
    ->Name("BM_official_forward_paper_size/seq/baseline_blocked_gemm_knn")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK(BM_official_forward_paper_size_omp_baseline)
    ->Name("BM_official_forward_paper_size/omp/baseline_blocked_gemm_knn")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK(BM_official_forward_paper_size_seq_per_edge)
    ->Name("BM_official_forward_paper_size/seq/baseline_per_edge_first_layers")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK(BM_official_forward_paper_size_omp_per_edge)
    ->Name("BM_official_forward_paper_size/omp/baseline_per_edge_first_layers")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK(BM_official_forward_paper_size_seq_decoder_on_hr)
    ->Name("BM_official_forward_paper_size/seq/baseline_decoder_first_layer_on_hr")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK(BM_official_forward_paper_size_omp_decoder_on_hr)
    ->Name("BM_official_forward_paper_size/omp/baseline_decoder_first_layer_on_hr")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK(BM_dynamic_knn_fused_seq)->Name("BM_official_dynamic_knn_paper_size/fused/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_dynamic_knn_fused_omp)->Name("BM_official_dynamic_knn_paper_size/fused/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_dynamic_knn_fused_unshared_omp)
    ->Name("BM_official_dynamic_knn_paper_size/fused/omp/baseline_unshared_thresholds")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK(BM_dynamic_knn_gemm_seq)->Name("BM_official_dynamic_knn_paper_size/blocked_gemm/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_dynamic_knn_gemm_omp)->Name("BM_official_dynamic_knn_paper_size/blocked_gemm/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_official_forward_train_mode_paper_size)->Name("BM_official_forward_train_mode_paper_size/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_official_train_step_bunny)->Name("BM_official_train_step_bunny/omp")->Arg(32)->Arg(8)->ArgName("B")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);
BENCHMARK(BM_trainer_step_bunny)->Name("BM_trainer_step_bunny/omp")->Arg(8)->ArgName("B")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);
BENCHMARK(BM_upsampling_step_bunny)->Name("BM_upsampling_step_bunny/omp")->Arg(8)->ArgName("B")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

BENCHMARK_MAIN();
