/// The malloc counter of the nn tests (tests/support/malloc_counter.hpp is included here, once).

#include <atomic>
#include <cstddef>

#include "gradient_check.hpp"

#include "../support/malloc_counter.hpp"

TEST_CASE("nn test support: the malloc counter sees Eigen and std allocations") {
  const long before = simsr_test_malloc_count();
  simsr::nn::Matrix<float> m(7, 9);
  std::vector<int> v(100);
  simsr::test::escape(m.data());
  simsr::test::escape(v.data());
  const long counted = simsr_test_malloc_count() - before;
  CHECK(m.size() + Eigen::Index(v.size()) == 163);
  if constexpr (!simsr::test::allocations_counted) {
    MESSAGE("allocations are not counted in this build (tests/support/allocation_check.hpp); counted " << counted);
  } else {
#if defined(__GLIBC__)
    CHECK(counted >= 2);
#else
    FAIL("the malloc counter needs glibc or a sanitizer's allocation hook");
#endif
  }
}
