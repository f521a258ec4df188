/// The malloc counter of the core tests (tests/support/malloc_counter.hpp is included here, once),
/// and the allocation checks of exec::omp itself.

#include <doctest/doctest.h>

#include <simsr/core/core.hpp>

#include <thread>
#include <vector>

#include "../support/allocation_check.hpp"
#include "../support/malloc_counter.hpp"

using namespace simsr;

TEST_CASE("exec::omp: a warm loop allocates nothing whether it forks or runs on the calling thread, also on a fresh thread") {
  // A thread that is not an OpenMP one (a fresh std::thread: libgomp knows nothing of it yet),
  // whose loops first fork, then run on the caller: the serial path's EigenSingleThreaded writes
  // the thread's thread count, which libgomp would malloc its ICVs for at that first write.
  std::vector<double> v(4096, 1.0);
  long allocations = -1;
  std::thread([&] {
    const auto body = [&](Index i) { v[std::size_t(i)] = 2.0 * v[std::size_t(i)] + 1.0; };
    exec::set_omp_fork(exec::OmpFork::always);
    for (int warm = 0; warm < 3; ++warm) exec::parallel_for(exec::omp, Index(v.size()), body);
    exec::set_omp_fork(exec::OmpFork::never);
    const long before = simsr_test_malloc_count();
    exec::parallel_for(exec::omp, Index(v.size()), body);
    exec::set_omp_fork(exec::OmpFork::always);
    exec::parallel_for(exec::omp, Index(v.size()), body);
    allocations = simsr_test_malloc_count() - before;
    exec::set_omp_fork(exec::OmpFork::adaptive);
  }).join();
  REQUIRE(allocations >= 0);
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, allocations);
  CHECK(v[0] == 63.0);  // 5 times x -> 2x + 1 from 1
}
