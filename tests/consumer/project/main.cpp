// A downstream project using the installed simsr: one parallel reduction under each host policy.
#include <simsr/simsr.hpp>

#include <cstdio>
#include <functional>

int main() {
  using namespace simsr;
  auto square = [](Index i) { return double(i) * double(i); };
  const double s = exec::parallel_reduce(exec::seq, 1000, 0.0, square, std::plus<>{});
  const double o = exec::parallel_reduce(exec::omp, 1000, 0.0, square, std::plus<>{});
  std::printf("seq %.1f omp %.1f threads %d\n", s, o, exec::omp_max_threads());
  return (s == o && s == 332833500.0) ? 0 : 1;
}
