// expect: this type is not a simsr::exec::ExecutionPolicy
// Must NOT compile: the policy comes first in every call; a primitive called with the policy last
// (the convention before issue #10) says so in one sentence instead of listing every overload.
#include <simsr/core/parallel.hpp>

#include <vector>

int main() {
  std::vector<double> y(10);
  simsr::exec::parallel_for(simsr::Index(10), [&](simsr::Index i) { y[std::size_t(i)] = 1; }, simsr::exec::seq);
}
