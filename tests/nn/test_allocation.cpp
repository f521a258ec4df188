/// The malloc counter of the nn tests (tests/support/malloc_counter.hpp is included here, once).

#include <atomic>
#include <cstddef>

#include "gradient_check.hpp"

#include "../support/malloc_counter.hpp"

TEST_CASE("nn test support: the malloc counter sees Eigen and std allocations") {
#if defined(__GLIBC__)
  const long before = simsr_test_malloc_count();
  simsr::nn::Matrix<float> m(7, 9);
  std::vector<int> v(100);
  CHECK(simsr_test_malloc_count() - before >= 2);
  CHECK(m.size() + Eigen::Index(v.size()) == 163);
#endif
}
