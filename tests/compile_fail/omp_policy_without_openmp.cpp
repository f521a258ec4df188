// expect: simsr::exec::omp needs OpenMP
// Must NOT compile without -fopenmp: exec::omp needs OpenMP, and says so.
#include <simsr/core/parallel.hpp>
int main() {
  simsr::exec::parallel_for(simsr::exec::omp, 10, [](simsr::Index) {});
}
