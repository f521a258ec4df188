// expect: simsr::exec::cuda needs nvcc
// Must NOT compile with a host compiler: exec::cuda needs nvcc, and says so.
#include <simsr/core/parallel.hpp>
int main() {
  simsr::exec::parallel_for(simsr::exec::cuda, 10, [](simsr::Index) {});
}
