// The library's own kernel bodies under exec::cuda (issue #17 item 5): Embedded::apply's
// (interp::DeviceEmbedded) and BlockCsr's product (physics::DeviceBlockCsr), the same functors
// the host tests run under seq and omp. Compiled by nvcc in the cuda-compile test; where a GPU
// exists it runs and checks the device results against the host's (to rounding: the device may
// fuse multiply-adds the host does not).
#include <simsr/interp/device_embedded.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/physics/linear_solvers/device_block_csr.hpp>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace {
double max_relative(const double* a, const double* b, simsr::Index n) {
  double diff = 0, scale = 0;
  for (simsr::Index i = 0; i < n; ++i) diff = std::max(diff, std::abs(a[i] - b[i])), scale = std::max(scale, std::abs(b[i]));
  return scale > 0 ? diff / scale : diff;
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
  // BlockCsr on the device
  const auto d_blocks = physics::to_device(blocks);
  DeviceBuffer<double> d_x(Span<const double>{x.data(), x.size()}), d_y(y_device.size());
  d_blocks.multiply(exec::cuda, d_x.span(), d_y.span());
  d_y.copy_to(Span<double>{y_device.data(), y_device.size()});
  const double e_blocks = max_relative(y_device.data(), y_host.data(), y_host.size());
  std::printf("Embedded::apply device vs seq: %.3g; BlockCsr product device vs seq: %.3g\n", e_embedded, e_blocks);
  return e_embedded < 1e-13 && e_blocks < 1e-13 ? 0 : 1;
}
