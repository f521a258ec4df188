#include <simsr/physics/verification/cantilever.hpp>

#include <doctest/doctest.h>

using namespace simsr;
using namespace simsr::physics;

// exec::seq throughout: the TSan build leaves it out (tests/CMakeLists.txt, "single-threaded").
TEST_CASE("cantilever under gravity converges to Euler–Bernoulli on conforming meshes; the BCC embedded beam beside it" *
          doctest::test_suite("single-threaded")) {
  // Conforming: the error must fall with every refinement, at about second order (linear tets
  // lock in bending, so the coarse meshes are far off). Within 3 % at 10 cells through the height:
  // tests/cli/test_cli_cantilever.py checks that mesh (seconds at -O3, minutes under sanitizers).
  double previous = 1;
  for (Index n : {2, 4, 6}) {
    CantileverOptions o;
    o.cells_through_height = n;
    const auto r = solve_cantilever(exec::seq, o);
    MESSAGE("conforming n=" << n << ": tip " << r.tip_deflection << " m, Euler–Bernoulli " << r.euler_bernoulli << ", error " << r.relative_error);
    CHECK(r.tip_deflection < r.euler_bernoulli);  // stiff from locking, never softer
    CHECK(r.relative_error < previous / 1.8);
    previous = r.relative_error;
  }
  CHECK(previous < 0.1);  // 8 % at 6 cells

  CantileverOptions bcc;
  bcc.discretization = BeamDiscretization::embedded_bcc;
  bcc.cells_through_height = 6;
  const auto rb = solve_cantilever(exec::seq, bcc);
  MESSAGE("BCC n=6: error " << rb.relative_error);
  CHECK(rb.relative_error < 0.03);
  CHECK(euler_bernoulli_tip_deflection(bcc) == doctest::Approx(1000 * 9.81 * 0.1 * 0.1 * 1.0 / (8 * 1e8 * 0.1 * 0.001 / 12)));
}

TEST_CASE("cantilever: PCG under omp bends the beam as the direct solve under seq does") {
  CantileverOptions four;
  four.cells_through_height = 4;
  const auto direct = solve_cantilever(exec::seq, four);
  const auto pcg = solve_cantilever<ConjugateGradient<BlockJacobi<>>>(exec::omp, four);
  CHECK(pcg.tip_deflection == doctest::Approx(direct.tip_deflection).epsilon(1e-6));
}

TEST_CASE("cantilever: lengths must be multiples of the cell size") {
  CantileverOptions o;
  o.cells_through_height = 3;
  o.width = 0.05;
  CHECK_THROWS_AS(solve_cantilever(exec::seq, o), ArgumentError);
  o.cells_through_height = 0;
  CHECK_THROWS_AS(solve_cantilever(exec::seq, o), ArgumentError);
}
