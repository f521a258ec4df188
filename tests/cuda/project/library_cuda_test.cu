// The library's own kernel bodies under exec::cuda (issue #17 item 5): Embedded::apply's
// (interp::DeviceEmbedded), IDW's, MLS's, LocalLinear's and RBF's apply
// (interp::DeviceNeighborGather, interp::DeviceLocalLinear, interp::DeviceRbf), BlockCsr's
// product (physics::DeviceBlockCsr), the elastic energy, gradient and gathered Hessian (physics::DeviceElasticEnergy, isotropic and fibre materials),
// the network's upsampling gather (nn::DeviceNeighborUpsample), the whole network's inference
// (nn::DeviceInferenceNet, against SuperResolutionNet::infer and against the same launches on
// the host, nn::HostInferenceNet) and Learned::apply around it (interp::DeviceLearned): the same
// functors the host tests run under seq and omp. Compiled by nvcc in the cuda-compile test; where
// a GPU exists it runs and checks the device results against the host's (to rounding: the device
// may fuse multiply-adds the host does not). The host part (fits, training) runs without one.
#include <simsr/interp/device_embedded.hpp>
#include <simsr/interp/device_local_linear.hpp>
#include <simsr/interp/device_neighbor_gather.hpp>
#include <simsr/interp/device_rbf.hpp>
#include <simsr/interp/learned_inference.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/neighbors/kd_tree.hpp>
#include <simsr/nn/device_neighbor_upsample.hpp>
#include <simsr/nn/inference_net.hpp>
#include <simsr/physics/device_elastic_energy.hpp>
#include <simsr/physics/linear_solvers/device_block_csr.hpp>
#include <simsr/physics/materials/neo_hookean.hpp>
#include <simsr/physics/materials/teran_muscle.hpp>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "../../nn/network_fixture.hpp"

namespace {
double max_relative(const double* a, const double* b, simsr::Index n) {
  double diff = 0, scale = 0;
  for (simsr::Index i = 0; i < n; ++i) diff = std::max(diff, std::abs(a[i] - b[i])), scale = std::max(scale, std::abs(b[i]));
  return scale > 0 ? diff / scale : diff;
}

/// The elastic energy and its gradient at random positions, host (exec::seq) against device;
/// returns the larger relative difference of the two.
template <class M>
double elastic_difference(const simsr::TetMesh<double>& mesh, const simsr::Points<double>& x, const M& material,
                          const std::vector<typename M::Element>& elements) {
  using namespace simsr;
  const physics::ElasticEnergy<M> host(mesh, material, elements);
  Points<double> g_host = Points<double>::Zero(x.rows(), 3), g_device(x.rows(), 3);
  const double e_host = host.add_energy_gradient(exec::seq, x, g_host);
  const auto device = physics::to_device(host);
  DeviceBuffer<double> d_x(Span<const double>{x.data(), x.size()}), d_g(Span<const double>{g_device.setZero().data(), x.size()});
  const MatrixSpan<const double> xs{d_x.span().data, x.rows(), 3, 3};
  const MatrixSpan<double> gs{d_g.span().data, x.rows(), 3, 3};
  const double e_device = device.add_energy_gradient(exec::cuda, xs, gs);
  d_g.copy_to(Span<double>{g_device.data(), g_device.size()});
  // the separate energy and gradient bodies too: E twice, g += twice
  const double e_alone = device.energy(exec::cuda, xs);
  device.add_gradient(exec::cuda, xs, gs);
  Points<double> g_twice(x.rows(), 3), g_host_twice = 2 * g_host;
  d_g.copy_to(Span<double>{g_twice.data(), g_twice.size()});
  const double de = std::max(std::abs(e_device - e_host), std::abs(e_alone - e_host)) / std::abs(e_host);
  return std::max({de, max_relative(g_device.data(), g_host.data(), g_host.size()),
                   max_relative(g_twice.data(), g_host_twice.data(), g_host.size())});
}

/// The elastic Hessian (gathered assembly, project and exact) on the device against the host's
/// add_hessian with HessianAssembly::gather: the larger max relative difference of the values.
template <class M>
double hessian_difference(const simsr::TetMesh<double>& mesh, const simsr::Points<double>& x, const M& material,
                          const std::vector<typename M::Element>& elements) {
  using namespace simsr;
  physics::ElasticEnergy<M> host(mesh, material, elements);
  host.set_hessian_assembly(physics::HessianAssembly::gather, 1);
  auto device = physics::to_device(host);
  double worst = 0;
  for (const physics::Definiteness d : {physics::Definiteness::project, physics::Definiteness::exact}) {
    physics::BlockHessian<double> H(mesh.num_vertices(), mesh.T);
    host.add_hessian(exec::seq, x, H, d);
    device.set_hessian_pattern(exec::seq, host, H);
    std::vector<double> zeros(std::size_t(9 * H.num_blocks()), 0.0), values(zeros.size());
    DeviceBuffer<double> d_x(Span<const double>{x.data(), x.size()}), d_values(Span<const double>{zeros.data(), Index(zeros.size())});
    device.add_hessian(exec::cuda, MatrixSpan<const double>{d_x.span().data, x.rows(), 3, 3}, d_values.span(), d);
    d_values.copy_to(Span<double>{values.data(), Index(values.size())});
    worst = std::max(worst, max_relative(values.data(), H.block(0).data(), Index(values.size())));
  }
  return worst;
}

/// NeighborUpsample's inference gather (float) at a network's size, host (exec::seq) against its
/// device twin (nn::DeviceNeighborUpsample), shared and per-item weights: the larger max relative
/// difference of the two.
double neighbor_upsample_difference(std::mt19937& rng) {
  using namespace simsr;
  const Index M = 3000, N = 1000, K = 20, C = 64, B = 2;
  std::uniform_real_distribution<float> U(-1, 1);
  nn::GraphIndices idx(M, K);
  for (Index i = 0; i < idx.size(); ++i) idx.data()[i] = VIndex(rng() % std::uint32_t(N));
  const nn::NeighborUpsample<float> up(idx, N);
  nn::Matrix<float> z(B * N, C);
  for (Index i = 0; i < z.size(); ++i) z.data()[i] = U(rng);
  DeviceBuffer<float> d_z(Span<const float>{z.data(), z.size()}), d_out(B * M * C);
  double worst = 0;
  for (const Index weight_rows : {M, B * M}) {  // shared by the items, one block per item
    nn::Matrix<float> logits(weight_rows, K), w, host, device(B * M, C);
    for (Index i = 0; i < logits.size(); ++i) logits.data()[i] = 3 * U(rng);
    nn::NeighborUpsample<float>::softmax_rows(exec::seq, logits, w);
    up.apply(exec::seq, w, z, host);
    const auto d_up = nn::to_device(up, w);
    d_up.apply(exec::cuda, MatrixSpan<const float>{d_z.span().data, B * N, C, C}, MatrixSpan<float>{d_out.span().data, B * M, C, C});
    d_out.copy_to(Span<float>{device.data(), device.size()});
    double diff = 0, scale = 0;
    for (Index i = 0; i < host.size(); ++i)
      diff = std::max(diff, double(std::abs(device.data()[i] - host.data()[i]))), scale = std::max(scale, double(std::abs(host.data()[i])));
    worst = std::max(worst, scale > 0 ? diff / scale : diff);
  }
  return worst;
}
/// The whole network's inference (official widths, a small random geometry, B = 2, random
/// BatchNorm statistics) on the device against the host network's own infer and against the host
/// instance of the same launches: {vs network, vs host launches}, max relative differences.
std::pair<double, double> network_difference(std::mt19937_64& rng) {
  using namespace simsr;
  const nn::NetworkConfig cfg = nn::NetworkConfig::official();
  const Index N = 400, M = 1000, B = 2;
  const auto geo = test::small_network_geometry(rng, N, M, cfg);
  nn::Rng init(5);
  nn::SuperResolutionNet<float> net(cfg, geo, init);
  for (float& v : net.store().buffers()) v = std::uniform_real_distribution<float>(0.5f, 1.5f)(rng);
  nn::Matrix<float> ldx(B * N, 3), expected, host, device;
  for (Index i = 0; i < ldx.size(); ++i) ldx.data()[i] = std::uniform_real_distribution<float>(-0.5f, 0.5f)(rng);
  net.set_decoder_first_layer_on_lr(false);
  net.infer(exec::seq, ldx, expected);
  nn::HostInferenceNet<float> on_host(exec::seq, net);
  on_host.infer(exec::seq, ldx, host);
  auto on_device = nn::to_device(exec::seq, net);
  on_device.infer(exec::cuda, ldx, device);
  auto rel = [](const nn::Matrix<float>& a, const nn::Matrix<float>& b) {
    return double((a - b).cwiseAbs().maxCoeff()) / std::max(1e-30, double(b.cwiseAbs().maxCoeff()));
  };
  std::printf("network dynamic graph rows that differ, device vs host launches: %td of %td\n",
              Index(((on_device.dynamic_graph(1).array() != on_host.dynamic_graph(1).array()).rowwise().any()).count()), B * N);
  return {rel(device, expected), rel(device, host)};
}
/// Learned::apply (the official residual network over Embedded, fitted on a box and a sphere,
/// untrained but for random decoder output weights) on the device against the host's.
double learned_difference(std::mt19937_64& rng) {
  using namespace simsr;
  interp::UpsamplingProblem<double> problem;
  problem.lr = box_tet_mesh<double>(4, 4, 4, Vec3<>(-0.1, -0.1, -0.1), Vec3<>(0.1, 0.1, 0.1));
  problem.hr = icosphere<double>(3, 0.08);
  problem.ensure_neighborhoods(exec::seq, 20);
  nn::NetworkConfig cfg = nn::NetworkConfig::official();
  cfg.residual = true;
  interp::Learned<> learned(cfg, 3);
  learned.fit(exec::seq, problem);
  auto& store = learned.network().store();
  for (const char* n : {"net_decoder.decoder.last_layer.fc.weight", "net_decoder.decoder.last_layer.fc.bias"})
    for (float& v : store.values(store.at(n))) v = std::uniform_real_distribution<float>(-0.5f, 0.5f)(rng);
  learned.network().parameters_changed();
  Points<double> lr(problem.num_lr(), 3), host(problem.num_hr(), 3), device(problem.num_hr(), 3);
  for (Index i = 0; i < lr.size(); ++i) lr.data()[i] = std::uniform_real_distribution<double>(-0.01, 0.01)(rng);
  learned.apply(exec::seq, lr, host);
  auto twin = interp::to_device(exec::seq, learned);
  twin.apply(exec::cuda, lr, device);
  return max_relative(device.data(), host.data(), host.size());
}
}  // namespace

int main() {
  using namespace simsr;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  // Embedded: a box of tets, points inside and around it
  const TetMesh<double> lr = box_tet_mesh<double>(6, 5, 4, Vec3<>(0, 0, 0), Vec3<>(1, 1, 1));
  Points<double> hr(2000, 3);
  for (Index i = 0; i < hr.rows(); ++i) hr.row(i) << 0.5 + 0.6 * U(rng), 0.5 + 0.6 * U(rng), 0.5 + 0.6 * U(rng);
  interp::Embedded<double> embedded;
  embedded.fit(exec::seq, lr, hr);
  Points<double> lr_disp(lr.num_vertices(), 3), hr_host(hr.rows(), 3), hr_device(hr.rows(), 3);
  for (Index i = 0; i < lr_disp.size(); ++i) lr_disp.data()[i] = U(rng);
  embedded.apply(exec::seq, lr_disp, hr_host);
  // IDW, MLS and LocalLinear on the box and HR points (fitted here: the host part runs without a device)
  interp::UpsamplingProblem<double> problem;
  problem.lr = lr;
  problem.hr.V = hr;
  {  // Euclidean neighbourhoods (the HR points have no surface for the geodesic ones)
    const neighbors::KdTree<double> tree(lr.V);
    const auto nearest = tree.query(exec::seq, hr, 20);  // IDW's and MLS's default k
    neighbors::UpsamplingNeighborhoods nb;
    nb.indices = nearest.indices;
    nb.distances = nearest.distances;
    problem.neighborhoods = std::move(nb);
  }
  interp::IDW<double> idw;
  idw.fit(exec::seq, problem);
  interp::MLS<double> mls;
  mls.fit(exec::seq, problem);
  interp::LocalLinear<double> local(interp::LocalLinearOptions{.k = 4});
  local.fit(exec::seq, problem);
  {
    const Index F = 40;  // frames: random LR displacements, their IDW interpolation plus noise
    data::PairedFrames<double> frames;
    frames.lowres.resize(F, 3 * lr.num_vertices());
    frames.highres.resize(F, 3 * hr.rows());
    Points<double> a(lr.num_vertices(), 3), b(hr.rows(), 3);
    for (Index f = 0; f < F; ++f) {
      for (Index i = 0; i < a.size(); ++i) a.data()[i] = U(rng);
      idw.apply(exec::seq, a, b);
      for (Index i = 0; i < b.size(); ++i) b.data()[i] += 0.01 * U(rng);
      frames.lowres.row(f) = Eigen::Map<const Eigen::RowVectorXd>(a.data(), a.size());
      frames.highres.row(f) = Eigen::Map<const Eigen::RowVectorXd>(b.data(), b.size());
      frames.ids.push_back(f);
    }
    frames.controls.resize(F, 0);
    local.train(exec::seq, frames, {.lambda = 1e-6});
  }
  interp::RBFOptions rbf_options;
  rbf_options.distance = interp::RbfDistance::lr_mesh_geodesic;  // the HR points have no surface
  interp::RBF<double> rbf(rbf_options);
  rbf.fit(exec::seq, problem);
  Points<double> idw_host(hr.rows(), 3), mls_host(hr.rows(), 3), local_host(hr.rows(), 3), rbf_host(hr.rows(), 3);
  rbf.apply(exec::seq, lr_disp, rbf_host);
  idw.apply(exec::seq, lr_disp, idw_host);
  mls.apply(exec::seq, lr_disp, mls_host);
  local.apply(exec::seq, lr_disp, local_host);
  // BlockCsr: a random block-sparse matrix
  const Index nb = 300;
  std::vector<Eigen::Triplet<double, int>> t;
  for (Index i = 0; i < nb; ++i)
    for (int n = 0; n < 8; ++n) {
      const Index j = Index(rng() % std::uint32_t(nb));
      for (int e = 0; e < 9; ++e) t.emplace_back(int(3 * i + e / 3), int(3 * j + e % 3), U(rng));
    }
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> A(3 * nb, 3 * nb);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  physics::BlockCsr<double> blocks;
  blocks.assign(exec::seq, A);
  VecX<double> x(3 * nb), y_host, y_device(3 * nb);
  for (Index i = 0; i < x.size(); ++i) x[i] = U(rng);
  blocks.multiply(exec::seq, x, y_host);

  // elastic energy: a box perturbed by up to 40 % of a cell (the inverted tets counted and printed);
  // random muscle fibres and activations
  const TetMesh<double> body = box_tet_mesh<double>(7, 6, 5, Vec3<>(0, 0, 0), Vec3<>(0.07, 0.06, 0.05));
  Points<double> deformed = body.V;
  for (Index i = 0; i < deformed.size(); ++i) deformed.data()[i] += 0.004 * U(rng);
  std::vector<physics::MuscleFibre<double>> fibres(std::size_t(body.num_tets()));
  for (auto& f : fibres) f = physics::TeranMuscle<double>::element(Vec3<>(U(rng), U(rng), U(rng)), 0.5 + 0.5 * U(rng));

  int devices = 0;
  if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
    std::printf("no CUDA device: compiled only\n");
    return 0;
  }
  // Embedded on the device
  const auto d_embedded = interp::to_device(embedded);
  DeviceBuffer<double> d_lr(Span<const double>{lr_disp.data(), lr_disp.size()}), d_hr(hr_device.size());
  d_embedded.apply(exec::cuda, MatrixSpan<const double>{d_lr.span().data, lr_disp.rows(), 3, 3}, MatrixSpan<double>{d_hr.span().data, hr_device.rows(), 3, 3});
  d_hr.copy_to(Span<double>{hr_device.data(), hr_device.size()});
  const double e_embedded = max_relative(hr_device.data(), hr_host.data(), hr_host.size());
  // IDW, MLS and LocalLinear on the device
  auto gather_difference = [&](const auto& twin, const Points<double>& host) {
    Points<double> out(hr.rows(), 3);
    twin.apply(exec::cuda, MatrixSpan<const double>{d_lr.span().data, lr_disp.rows(), 3, 3}, MatrixSpan<double>{d_hr.span().data, out.rows(), 3, 3});
    d_hr.copy_to(Span<double>{out.data(), out.size()});
    return max_relative(out.data(), host.data(), host.size());
  };
  const double e_idw = gather_difference(interp::to_device(idw), idw_host), e_mls = gather_difference(interp::to_device(mls), mls_host),
               e_local = gather_difference(interp::to_device(local), local_host), e_rbf = gather_difference(interp::to_device(rbf), rbf_host);
  // BlockCsr on the device
  const auto d_blocks = physics::to_device(blocks);
  DeviceBuffer<double> d_x(Span<const double>{x.data(), x.size()}), d_y(y_device.size());
  d_blocks.multiply(exec::cuda, d_x.span(), d_y.span());
  d_y.copy_to(Span<double>{y_device.data(), y_device.size()});
  const double e_blocks = max_relative(y_device.data(), y_host.data(), y_host.size());
  // ElasticEnergy on the device
  const double e_neo = elastic_difference(body, deformed, physics::NeoHookean<double>::from_young_poisson(3e4, 0.45),
                                          std::vector<physics::NoElementData>(std::size_t(body.num_tets())));
  const double e_muscle = elastic_difference(body, deformed, physics::TeranMuscle<double>(), fibres);
  const double e_upsample = neighbor_upsample_difference(rng);
  const double h_neo = hessian_difference(body, deformed, physics::NeoHookean<double>::from_young_poisson(3e4, 0.45),
                                          std::vector<physics::NoElementData>(std::size_t(body.num_tets())));
  const double h_muscle = hessian_difference(body, deformed, physics::TeranMuscle<double>(), fibres);
  std::printf("Embedded::apply device vs seq: %.3g; BlockCsr product device vs seq: %.3g\n", e_embedded, e_blocks);
  std::printf("IDW::apply %.3g, MLS::apply %.3g, LocalLinear::apply %.3g, RBF::apply %.3g device vs seq\n", e_idw, e_mls, e_local, e_rbf);
  const Index inverted = physics::ElasticEnergy<physics::NeoHookean<double>>(body, physics::NeoHookean<double>::from_young_poisson(3e4, 0.45))
                             .count_inverted(exec::seq, deformed);
  std::printf("ElasticEnergy energy+gradient device vs seq: NeoHookean %.3g, TeranMuscle %.3g (%td tets, %td inverted)\n", e_neo,
              e_muscle, body.num_tets(), inverted);
  std::printf("NeighborUpsample::apply (float) device vs seq: %.3g\n", e_upsample);
  std::printf("ElasticEnergy Hessian (gathered, project and exact) device vs seq: NeoHookean %.3g, TeranMuscle %.3g\n", h_neo, h_muscle);
  std::mt19937_64 rng64(11);
  const auto [e_network, e_launches] = network_difference(rng64);
  const double e_learned = learned_difference(rng64);
  std::printf("SuperResolutionNet inference (float, official) device vs the network's infer: %.3g, vs the same launches on the host: %.3g\n",
              e_network, e_launches);
  std::printf("Learned::apply (mesh units) device vs the host's: %.3g\n", e_learned);
  const bool interpolators = e_embedded < 1e-13 && e_idw < 1e-13 && e_mls < 1e-13 && e_local < 1e-13 && e_rbf < 1e-13;
  const bool physics = e_blocks < 1e-13 && e_neo < 1e-12 && e_muscle < 1e-12 && h_neo < 1e-10 && h_muscle < 1e-10;
  const bool network = e_upsample < 1e-5 && e_network < 1e-4 && e_launches < 1e-4 && e_learned < 1e-4;
  return interpolators && physics && network ? 0 : 1;
}
