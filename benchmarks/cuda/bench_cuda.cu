// The library's kernel bodies under exec::cuda against the same bodies under exec::seq and
// exec::omp, at the paper's sizes (issue #17 item 5). Every cuda row times the device twin on data
// already on the device (the copies in are setup, as for a solver that keeps its state there):
// CUDA events around one call, Google Benchmark's manual time. The host rows are the host
// component's own call (the baseline each ratio is taken against, in the same run).
//
//   BM_embedded_apply/<policy>          interp::Embedded::apply, N = 15,872 LR lattice vertices
//       (32×31×16, 6 tets a cube: 83,700 tets), M = 35,637 HR points (double)
//   BM_gather_apply/{idw,mls}/<policy>  IDW::apply and MLS::apply (NeighborGather: k = 20 Euclidean
//       neighbours, MLS's per-coordinate weights) on EmbeddedCase's N and M, against their device
//       twin (interp::DeviceNeighborGather)
//   BM_block_csr_multiply_73k/<policy>   physics::BlockCsr product y = A x, A the projected
//       Neo-Hookean Hessian of a 72,576-tet box (25×25×22 vertices; double)
//   BM_energy_gradient_73k/<material>/<policy>   ElasticEnergy::add_energy_gradient (E and ∂E/∂x in
//       one pass) on that box at a random deformation: neo_hookean, teran_muscle (random fibres and
//       activations: the face's muscle material)
//   BM_hessian_73k/<material>/<policy>    the elastic Hessian on that box, gathered assembly (the
//       element stiffnesses' bodies, then each block slot's sum): ElasticEnergy::add_hessian with
//       HessianAssembly::gather against DeviceElasticEnergy::add_hessian
//   BM_upsample_apply/<policy>            nn::NeighborUpsample::apply (the inference gather, Eq. 1):
//       N = 15,872 LR codes, M = 35,637 HR vertices, upK = 20, C = 64 channels (float)
//   BM_network_infer_paper_size/<policy>  the whole network's inference, official profile, upK 20,
//       B = 1, on benchmarks/paper_network.hpp's geometry (bench_nn's BM_official_forward_paper_size):
//       seq and omp run SuperResolutionNet::infer (the host's own path, its packed products), cuda
//       nn::DeviceInferenceNet::infer (ldx and the prediction in device memory). The host instance of
//       the same launches (HostInferenceNet) has no row: one entry a thread on 2 cores is the device's
//       decomposition, not the host's (the exact double-precision feature kNN alone is ~16 G products).
//
// Build: part of tests/cuda/project (ctest cuda_compile compiles it); run where a GPU is:
//   OMP_NUM_THREADS=2 build/bench_cuda --benchmark_counters_tabular=true
// Without a device the cuda rows are skipped with a message (SkipWithError), the host rows run.
#include <benchmark/benchmark.h>

#include <simsr/interp/device_embedded.hpp>
#include <simsr/interp/device_neighbor_gather.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/neighbors/kd_tree.hpp>
#include <simsr/nn/device_neighbor_upsample.hpp>
#include <simsr/nn/inference_net.hpp>
#include <simsr/physics/device_elastic_energy.hpp>
#include <simsr/physics/hessian.hpp>
#include <simsr/physics/linear_solvers/device_block_csr.hpp>
#include <simsr/physics/materials/neo_hookean.hpp>
#include <simsr/physics/materials/teran_muscle.hpp>

#include <cuda_runtime.h>

#include "../paper_network.hpp"

#include <memory>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

using namespace simsr;

namespace {

bool have_device() {
  static const bool yes = [] {
    int n = 0;
    return cudaGetDeviceCount(&n) == cudaSuccess && n > 0;
  }();
  return yes;
}

/// Times `call` with CUDA events, one iteration a sample (manual time).
template <class Call>
void time_on_device(benchmark::State& state, Call&& call) {
  if (!have_device()) {
    state.SkipWithError("no CUDA device");
    return;
  }
  cudaEvent_t start, stop;
  cudaEventCreate(&start);
  cudaEventCreate(&stop);
  call();  // warm-up: module load, first-touch of the buffers
  for (auto _ : state) {
    cudaEventRecord(start);
    call();
    cudaEventRecord(stop);
    cudaEventSynchronize(stop);
    float ms = 0;
    cudaEventElapsedTime(&ms, start, stop);
    state.SetIterationTime(double(ms) * 1e-3);
  }
  cudaEventDestroy(start);
  cudaEventDestroy(stop);
}

/// One instance of a case's data for all its rows (built on first use, outside the timing).
template <class Case>
Case& shared_case() {
  static Case c;
  return c;
}

template <class T>
DeviceBuffer<T> upload(const T* data, Index n) {
  return DeviceBuffer<T>(Span<const T>{data, n});
}

// --- Embedded::apply (N 15,872, M 35,637) ---------------------------------------------------
struct EmbeddedCase {
  TetMesh<double> lr = box_tet_mesh<double>(31, 30, 15, Vec3<>(0, 0, 0), Vec3<>(31, 30, 15));
  interp::Embedded<double> embedded;
  Points<double> lr_disp, hr_disp;
  EmbeddedCase() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    Points<double> hr(35637, 3);
    for (Index i = 0; i < hr.rows(); ++i) hr.row(i) << 31 * u(rng), 30 * u(rng), 15 * u(rng);
    embedded.fit(exec::omp, lr, hr);
    lr_disp.resize(lr.num_vertices(), 3);
    for (Index i = 0; i < lr_disp.size(); ++i) lr_disp.data()[i] = u(rng) - 0.5;
    hr_disp.resize(hr.rows(), 3);
  }
};

template <class Policy>
void BM_embedded_apply(benchmark::State& state) {
  auto& c = shared_case<EmbeddedCase>();
  for (auto _ : state) {
    c.embedded.apply(Policy{}, c.lr_disp, c.hr_disp);
    benchmark::DoNotOptimize(c.hr_disp.data());
  }
}
void BM_embedded_apply_cuda(benchmark::State& state) {
  if (!have_device()) return state.SkipWithError("no CUDA device");
  auto& c = shared_case<EmbeddedCase>();
  const auto d = interp::to_device(c.embedded);
  auto lr = upload(c.lr_disp.data(), c.lr_disp.size());
  DeviceBuffer<double> hr(c.hr_disp.size());
  time_on_device(state, [&] {
    d.apply(exec::cuda, MatrixSpan<const double>{lr.span().data, c.lr_disp.rows(), 3, 3}, MatrixSpan<double>{hr.span().data, c.hr_disp.rows(), 3, 3});
  });
}

// --- IDW's and MLS's gather (the same N, M; k 20) ----------------------------------------------
struct GatherCase {
  interp::UpsamplingProblem<double> problem;
  interp::IDW<double> idw;
  interp::MLS<double> mls;
  Points<double> lr_disp, hr_disp;
  GatherCase() {
    std::mt19937 rng(7);  // EmbeddedCase's points
    std::uniform_real_distribution<double> u(0, 1);
    problem.lr = box_tet_mesh<double>(31, 30, 15, Vec3<>(0, 0, 0), Vec3<>(31, 30, 15));
    problem.hr.V.resize(35637, 3);
    for (Index i = 0; i < problem.hr.V.rows(); ++i) problem.hr.V.row(i) << 31 * u(rng), 30 * u(rng), 15 * u(rng);
    const neighbors::KdTree<double> tree(problem.lr.V);  // Euclidean neighbourhoods (the HR points have no surface)
    const auto nearest = tree.query(exec::omp, problem.hr.V, 20);
    neighbors::UpsamplingNeighborhoods nb;
    nb.indices = nearest.indices;
    nb.distances = nearest.distances;
    problem.neighborhoods = std::move(nb);
    idw.fit(exec::omp, problem);
    mls.fit(exec::omp, problem);
    lr_disp.resize(problem.num_lr(), 3);
    for (Index i = 0; i < lr_disp.size(); ++i) lr_disp.data()[i] = u(rng) - 0.5;
    hr_disp.resize(problem.num_hr(), 3);
  }
};

template <class I>
I& gather_interpolator(GatherCase& c) {
  if constexpr (std::is_same_v<I, interp::IDW<double>>)
    return c.idw;
  else
    return c.mls;
}

template <class I, class Policy>
void BM_gather_apply(benchmark::State& state) {
  auto& c = shared_case<GatherCase>();
  const I& interpolator = gather_interpolator<I>(c);
  for (auto _ : state) {
    interpolator.apply(Policy{}, c.lr_disp, c.hr_disp);
    benchmark::DoNotOptimize(c.hr_disp.data());
  }
}
template <class I>
void BM_gather_apply_cuda(benchmark::State& state) {
  if (!have_device()) return state.SkipWithError("no CUDA device");
  auto& c = shared_case<GatherCase>();
  const auto d = interp::to_device(gather_interpolator<I>(c));
  auto lr = upload(c.lr_disp.data(), c.lr_disp.size());
  DeviceBuffer<double> hr(c.hr_disp.size());
  time_on_device(state, [&] {
    d.apply(exec::cuda, MatrixSpan<const double>{lr.span().data, c.lr_disp.rows(), 3, 3}, MatrixSpan<double>{hr.span().data, c.hr_disp.rows(), 3, 3});
  });
}

// --- the 73k-tet box: BlockCsr product, energy + gradient --------------------------------------
struct BoxCase {
  TetMesh<double> mesh = box_tet_mesh<double>(24, 24, 21, Vec3<>(0, 0, 0), Vec3<>(0.24, 0.24, 0.21));
  Points<double> x;
  std::vector<physics::MuscleFibre<double>> fibres;
  physics::BlockCsr<double> csr;
  VecX<double> v, y;
  BoxCase() {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    x = mesh.V;
    for (Index i = 0; i < x.size(); ++i) x.data()[i] += 0.002 * u(rng);
    fibres.resize(std::size_t(mesh.num_tets()));
    for (auto& f : fibres) f = physics::TeranMuscle<double>::element(Vec3<>(u(rng), u(rng), u(rng)), 0.5 + 0.5 * u(rng));
    const physics::ElasticEnergy<physics::NeoHookean<double>> neo(mesh, physics::NeoHookean<double>::from_young_poisson(3e4, 0.45));
    physics::BlockHessian<double> H(mesh.num_vertices(), mesh.T);
    neo.add_hessian(exec::omp, x, H, physics::Definiteness::project);
    csr.assign(exec::omp, H.assemble(exec::omp, std::vector<char>(std::size_t(3 * mesh.num_vertices()), 0)));
    v.resize(3 * mesh.num_vertices());
    for (Index i = 0; i < v.size(); ++i) v[i] = u(rng);
  }
};

template <class Policy>
void BM_block_csr_multiply(benchmark::State& state) {
  auto& c = shared_case<BoxCase>();
  for (auto _ : state) {
    c.csr.multiply(Policy{}, c.v, c.y);
    benchmark::DoNotOptimize(c.y.data());
  }
}
void BM_block_csr_multiply_cuda(benchmark::State& state) {
  if (!have_device()) return state.SkipWithError("no CUDA device");
  auto& c = shared_case<BoxCase>();
  const auto d = physics::to_device(c.csr);
  auto v = upload(c.v.data(), c.v.size());
  DeviceBuffer<double> y(c.v.size());
  time_on_device(state, [&] { d.multiply(exec::cuda, v.span(), y.span()); });
}

template <class M>
physics::ElasticEnergy<M> box_energy(const BoxCase& c) {
  if constexpr (std::is_same_v<M, physics::TeranMuscle<double>>)
    return physics::ElasticEnergy<M>(c.mesh, M(), c.fibres);
  else
    return physics::ElasticEnergy<M>(c.mesh, M::from_young_poisson(3e4, 0.45));
}

template <class M, class Policy>
void BM_energy_gradient(benchmark::State& state) {
  auto& c = shared_case<BoxCase>();
  const auto elastic = box_energy<M>(c);
  Points<double> g = Points<double>::Zero(c.x.rows(), 3);
  for (auto _ : state) benchmark::DoNotOptimize(elastic.add_energy_gradient(Policy{}, c.x, g));
}
template <class M>
void BM_energy_gradient_cuda(benchmark::State& state) {
  if (!have_device()) return state.SkipWithError("no CUDA device");
  auto& c = shared_case<BoxCase>();
  const auto d = physics::to_device(box_energy<M>(c));
  auto x = upload(c.x.data(), c.x.size());
  DeviceBuffer<double> g(c.x.size());
  time_on_device(state, [&] {
    benchmark::DoNotOptimize(d.add_energy_gradient(exec::cuda, MatrixSpan<const double>{x.span().data, c.x.rows(), 3, 3},
                                                   MatrixSpan<double>{g.span().data, c.x.rows(), 3, 3}));
  });
}

/// The elastic Hessian's gathered assembly (the element stiffnesses, then each block slot's
/// sum) into the box's block pattern: the host energy's add_hessian (HessianAssembly::gather,
/// the bodies DeviceElasticEnergy launches) against the device twin's.
template <class M, class Policy>
void BM_hessian(benchmark::State& state) {
  auto& c = shared_case<BoxCase>();
  auto elastic = box_energy<M>(c);
  elastic.set_hessian_assembly(physics::HessianAssembly::gather, 1);
  physics::BlockHessian<double> H(c.mesh.num_vertices(), c.mesh.T);
  elastic.add_hessian(Policy{}, c.x, H, physics::Definiteness::project);  // warm: the gather lists, the scratch
  for (auto _ : state) {
    H.set_zero();
    elastic.add_hessian(Policy{}, c.x, H, physics::Definiteness::project);
    benchmark::DoNotOptimize(H.block(0).data());
  }
}
template <class M>
void BM_hessian_cuda(benchmark::State& state) {
  if (!have_device()) return state.SkipWithError("no CUDA device");
  auto& c = shared_case<BoxCase>();
  const auto elastic = box_energy<M>(c);
  physics::BlockHessian<double> H(c.mesh.num_vertices(), c.mesh.T);
  auto d = physics::to_device(elastic);
  d.set_hessian_pattern(exec::omp, elastic, H);
  auto x = upload(c.x.data(), c.x.size());
  DeviceBuffer<double> values(9 * H.num_blocks());
  time_on_device(state, [&] {
    d.add_hessian(exec::cuda, MatrixSpan<const double>{x.span().data, c.x.rows(), 3, 3}, values.span(), physics::Definiteness::project);
  });
}

// --- NeighborUpsample::apply (N 15,872, M 35,637, upK 20, C 64) ---------------------------------
struct UpsampleCase {
  static constexpr Index N = 15872, M = 35637, K = 20, C = 64;
  std::unique_ptr<nn::NeighborUpsample<float>> up;
  nn::Matrix<float> weights, z, out;
  UpsampleCase() {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1, 1);
    nn::GraphIndices idx(M, K);
    for (Index j = 0; j < M; ++j) {
      const Index centre = j * N / M;  // neighbours near the HR vertex's "position" in the LR order
      for (Index i = 0; i < K; ++i) idx(j, i) = VIndex((centre + Index(rng() % 200) + N - 100) % N);
    }
    up = std::make_unique<nn::NeighborUpsample<float>>(idx, N);
    nn::Matrix<float> logits(M, K);
    for (Index i = 0; i < logits.size(); ++i) logits.data()[i] = u(rng);
    nn::NeighborUpsample<float>::softmax_rows(exec::seq, logits, weights);
    z.resize(N, C);
    for (Index i = 0; i < z.size(); ++i) z.data()[i] = u(rng);
  }
};

template <class Policy>
void BM_upsample_apply(benchmark::State& state) {
  auto& c = shared_case<UpsampleCase>();
  for (auto _ : state) {
    c.up->apply(Policy{}, c.weights, c.z, c.out);
    benchmark::DoNotOptimize(c.out.data());
  }
}
void BM_upsample_apply_cuda(benchmark::State& state) {
  if (!have_device()) return state.SkipWithError("no CUDA device");
  auto& c = shared_case<UpsampleCase>();
  const auto d = nn::to_device(*c.up, c.weights);
  auto z = upload(c.z.data(), c.z.size());
  DeviceBuffer<float> out(UpsampleCase::M * UpsampleCase::C);
  time_on_device(state, [&] {
    d.apply(exec::cuda, MatrixSpan<const float>{z.span().data, UpsampleCase::N, UpsampleCase::C, UpsampleCase::C},
            MatrixSpan<float>{out.span().data, UpsampleCase::M, UpsampleCase::C, UpsampleCase::C});
  });
}

// --- the whole network's inference (official, N 15,872, M 35,637, upK 20, B 1) --------------
struct NetworkCase {
  nn::Rng rng{0};
  nn::SuperResolutionNet<float> net{bench::paper_config(), bench::paper_geo(), rng};
  nn::Matrix<float> ldx = bench::paper_ldx(1), pred;
  NetworkCase() { net.prepare_inference(exec::omp); }
};

template <class Policy>
void BM_network_infer(benchmark::State& state) {
  auto& c = shared_case<NetworkCase>();
  c.net.infer(Policy{}, c.ldx, c.pred);  // warm the buffers
  for (auto _ : state) {
    c.net.infer(Policy{}, c.ldx, c.pred);
    benchmark::DoNotOptimize(c.pred.data());
  }
}
void BM_network_infer_cuda(benchmark::State& state) {
  if (!have_device()) return state.SkipWithError("no CUDA device");
  auto& c = shared_case<NetworkCase>();
  auto d = nn::to_device(exec::omp, c.net);
  auto ldx = upload(c.ldx.data(), c.ldx.size());
  DeviceBuffer<float> pred(bench::kHr * 3);
  time_on_device(state, [&] {
    d.infer(exec::cuda, MatrixSpan<const float>{ldx.span().data, bench::kLr, 3, 3}, MatrixSpan<float>{pred.span().data, bench::kHr, 3, 3});
  });
}

using Neo = physics::NeoHookean<double>;
using Muscle = physics::TeranMuscle<double>;

}  // namespace

BENCHMARK_TEMPLATE(BM_embedded_apply, exec::seq_t)->Name("BM_embedded_apply/seq")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_embedded_apply, exec::omp_t)->Name("BM_embedded_apply/omp")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_embedded_apply_cuda)->Name("BM_embedded_apply/cuda")->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_TEMPLATE(BM_gather_apply, interp::IDW<double>, exec::seq_t)->Name("BM_gather_apply/idw/seq")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_gather_apply, interp::IDW<double>, exec::omp_t)->Name("BM_gather_apply/idw/omp")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_gather_apply_cuda, interp::IDW<double>)->Name("BM_gather_apply/idw/cuda")->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_TEMPLATE(BM_gather_apply, interp::MLS<double>, exec::seq_t)->Name("BM_gather_apply/mls/seq")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_gather_apply, interp::MLS<double>, exec::omp_t)->Name("BM_gather_apply/mls/omp")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_gather_apply_cuda, interp::MLS<double>)->Name("BM_gather_apply/mls/cuda")->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_TEMPLATE(BM_block_csr_multiply, exec::seq_t)->Name("BM_block_csr_multiply_73k/seq")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_block_csr_multiply, exec::omp_t)->Name("BM_block_csr_multiply_73k/omp")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_block_csr_multiply_cuda)->Name("BM_block_csr_multiply_73k/cuda")->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_TEMPLATE(BM_energy_gradient, Neo, exec::seq_t)->Name("BM_energy_gradient_73k/neo_hookean/seq")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_energy_gradient, Neo, exec::omp_t)->Name("BM_energy_gradient_73k/neo_hookean/omp")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_energy_gradient_cuda, Neo)->Name("BM_energy_gradient_73k/neo_hookean/cuda")->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_TEMPLATE(BM_energy_gradient, Muscle, exec::seq_t)->Name("BM_energy_gradient_73k/teran_muscle/seq")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_energy_gradient, Muscle, exec::omp_t)->Name("BM_energy_gradient_73k/teran_muscle/omp")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_energy_gradient_cuda, Muscle)->Name("BM_energy_gradient_73k/teran_muscle/cuda")->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_TEMPLATE(BM_hessian, Neo, exec::seq_t)->Name("BM_hessian_73k/neo_hookean/seq")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_hessian, Neo, exec::omp_t)->Name("BM_hessian_73k/neo_hookean/omp")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_hessian_cuda, Neo)->Name("BM_hessian_73k/neo_hookean/cuda")->Unit(benchmark::kMillisecond)->UseManualTime();
BENCHMARK_TEMPLATE(BM_hessian, Muscle, exec::seq_t)->Name("BM_hessian_73k/teran_muscle/seq")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_hessian, Muscle, exec::omp_t)->Name("BM_hessian_73k/teran_muscle/omp")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_hessian_cuda, Muscle)->Name("BM_hessian_73k/teran_muscle/cuda")->Unit(benchmark::kMillisecond)->UseManualTime();
BENCHMARK_TEMPLATE(BM_upsample_apply, exec::seq_t)->Name("BM_upsample_apply/seq")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_upsample_apply, exec::omp_t)->Name("BM_upsample_apply/omp")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_upsample_apply_cuda)->Name("BM_upsample_apply/cuda")->Unit(benchmark::kMicrosecond)->UseManualTime();

BENCHMARK_TEMPLATE(BM_network_infer, exec::seq_t)->Name("BM_network_infer_paper_size/seq")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_network_infer, exec::omp_t)->Name("BM_network_infer_paper_size/omp")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_network_infer_cuda)->Name("BM_network_infer_paper_size/cuda")->Unit(benchmark::kMillisecond)->UseManualTime();

BENCHMARK_MAIN();
