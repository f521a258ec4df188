#include <simsr/core/openmp_serial.hpp>

#include <doctest/doctest.h>

#include <thread>

#if defined(_OPENMP)
#include <omp.h>
#endif

using namespace simsr;

#if defined(_OPENMP)
namespace {
/// The team size of a region that asks for 4 threads by its clause (as CHOLMOD 3's loops do).
int team_of_four() {
  int team = 0;
#pragma omp parallel num_threads(4)
  {
#pragma omp single
    team = omp_get_num_threads();
  }
  return team;
}
}  // namespace

TEST_CASE("OpenMPSerial: a region with an explicit num_threads clause runs on the calling thread while alive; restored after; other threads unaffected") {
  const int before = omp_get_max_active_levels();
  omp_set_max_active_levels(1);
  REQUIRE(team_of_four() == 4);  // the clause wins over the thread count otherwise: what the guard is for
  {
    const OpenMPSerial serial;
    CHECK(team_of_four() == 1);
    CHECK(omp_get_max_active_levels() == 0);
    int other = 0;  // another thread's regions keep their own setting
    std::thread([&] { other = team_of_four(); }).join();
    CHECK(other == 4);
    {
      const OpenMPSerial nested;  // nesting keeps 0 and restores 0
      CHECK(team_of_four() == 1);
    }
    CHECK(team_of_four() == 1);
  }
  CHECK(omp_get_max_active_levels() == 1);
  CHECK(team_of_four() == 4);
  omp_set_max_active_levels(before);
}
#endif
