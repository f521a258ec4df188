// Instantiates every algorithm of the cuda policy with the same kernel bodies the host tests use.
// Compiled by nvcc in the cuda-compile test; where a GPU exists it also runs and checks itself.
#include <simsr/core/core.hpp>

#include <cstdio>
#include <functional>
#include <vector>

namespace {
struct Axpy {  // same body under seq, omp and cuda
  double a;
  const double* x;
  double* y;
  SIMSR_HOST_DEVICE void operator()(simsr::Index i) const { y[i] = a * x[i] + y[i]; }
};
struct Square {
  const double* x;
  SIMSR_HOST_DEVICE double operator()(simsr::Index i) const { return x[i] * x[i]; }
};
struct Plus {
  SIMSR_HOST_DEVICE double operator()(double a, double b) const { return a + b; }
};
}  // namespace

int main() {
  using namespace simsr;
  const Index n = 1 << 20;
  std::vector<double> hx(n), hy(n);
  for (Index i = 0; i < n; ++i) hx[i] = 1e-3 * double(i % 997), hy[i] = 1.0;
  int devices = 0;
  if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
    std::printf("no CUDA device: compiled only\n");
    return 0;
  }
  double *x = nullptr, *y = nullptr;
  cudaMalloc(&x, n * sizeof(double));
  cudaMalloc(&y, n * sizeof(double));
  cudaMemcpy(x, hx.data(), n * sizeof(double), cudaMemcpyHostToDevice);
  cudaMemcpy(y, hy.data(), n * sizeof(double), cudaMemcpyHostToDevice);
  exec::parallel_for(exec::cuda, n, Axpy{2.0, x, y});
  exec::parallel_for(exec::cuda, n, [=] __device__(Index i) { y[i] -= 1.0; });
  const double dev = exec::parallel_reduce(exec::cuda, n, 0.0, Square{y}, Plus{});
  exec::parallel_for(exec::seq, n, Axpy{2.0, hx.data(), hy.data()});
  for (auto& v : hy) v -= 1.0;
  const double host = exec::parallel_reduce(exec::seq, n, 0.0, Square{hy.data()}, Plus{});
  cudaFree(x);
  cudaFree(y);
  const double rel = std::abs(dev - host) / host;
  std::printf("cuda %.17g seq %.17g rel %.3g\n", dev, host, rel);
  return rel < 1e-12 ? 0 : 1;
}
