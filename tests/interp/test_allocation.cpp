// Interpolator::apply allocates nothing once warm (the Interpolator contract): the malloc calls of
// repeated applies are counted on the bunny problem, under seq and omp, for every method and each
// RBF solve path. tests/support/malloc_counter.hpp is included here, once for test_interp.
#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <simsr/interp/interp.hpp>

#include "../support/allocation_check.hpp"
#include "../support/malloc_counter.hpp"
#include "bunny_fixture.hpp"

using namespace simsr;
using namespace simsr::interp;

namespace {

/// Mallocs of 3 applies after 2 warm-up applies, under `policy`.
template <class Method, class Policy>
long warm_apply_mallocs(const Method& method, Policy policy, const Points<>& lr, Points<>& hr) {
  for (int i = 0; i < 2; ++i) method.apply(policy, lr, hr);
  const long before = simsr_test_malloc_count();
  for (int i = 0; i < 3; ++i) method.apply(policy, lr, hr);
  return simsr_test_malloc_count() - before;
}

template <class Method>
void check_no_allocation(const char* name, const Method& method, const Points<>& lr, Points<>& hr) {
  INFO(name);
  SIMSR_CHECK_NO_ALLOCATION(exec::seq, warm_apply_mallocs(method, exec::seq, lr, hr));
  SIMSR_CHECK_NO_ALLOCATION(exec::omp, warm_apply_mallocs(method, exec::omp, lr, hr));
}

}  // namespace

TEST_CASE("every interpolator's warm apply allocates nothing (bunny, seq and omp)") {
#if !defined(__GLIBC__)
  SIMSR_MISSING("malloc counting needs glibc");
  return;
#endif
  if constexpr (simsr::test::allocations_counted) {  // the counter itself must see allocations,
    const long before = simsr_test_malloc_count();      // or every check below would pass vacuously
    Points<> tmp(100, 3);
    simsr::test::escape(tmp.data());
    CHECK(simsr_test_malloc_count() - before >= 1);
    CHECK(tmp.rows() == 100);
  }
  simsr::test::Bunny b;
  if (!simsr::test::load_bunny(b, {10, 50, 100, 150, 200, 250})) {
    SIMSR_MISSING("bunny data not found in " << SIMSR_DATA_DIR);
    return;
  }
  const Points<>& lr = b.lr_frames[0];
  Points<> hr(b.problem.num_hr(), 3);

  Embedded<> embedded;
  embedded.fit(exec::seq, b.problem);
  check_no_allocation("Embedded", embedded, lr, hr);
  IDW<> idw;
  idw.fit(exec::seq, b.problem);
  check_no_allocation("IDW", idw, lr, hr);
  for (const auto basis : {MlsBasis::per_coordinate, MlsBasis::linear_3d}) {
    MLS<> mls(MLSOptions{.basis = basis});
    mls.fit(exec::seq, b.problem);
    check_no_allocation(basis == MlsBasis::per_coordinate ? "MLS as written" : "MLS 3-D linear", mls, lr, hr);
  }
  for (const auto solver : {RbfSolver::dense, RbfSolver::sparse}) {
    RBFOptions o;
    o.solver = solver;
    RBF<> rbf(o);
    rbf.fit(exec::seq, b.problem);
    check_no_allocation(solver == RbfSolver::dense ? "RBF dense" : "RBF sparse", rbf, lr, hr);
  }
  {  // dense LU kept and solved per frame (operator larger than the budget)
    RBFOptions o;
    o.solver = RbfSolver::dense;
    o.max_operator_bytes = 0;
    RBF<> rbf(o);
    rbf.fit(exec::seq, b.problem);
    check_no_allocation("RBF dense, per-frame LU solves", rbf, lr, hr);
  }
  data::PairedFrames<> train;
  const Index nf = Index(b.lr_frames.size());
  train.lowres.resize(nf, b.lr_frames[0].size());
  train.highres.resize(nf, b.hr_frames[0].size());
  train.controls.resize(nf, 0);
  for (Index f = 0; f < nf; ++f) {
    train.lowres.row(f) = Eigen::Map<const Eigen::RowVectorXd>(b.lr_frames[std::size_t(f)].data(), b.lr_frames[std::size_t(f)].size());
    train.highres.row(f) = Eigen::Map<const Eigen::RowVectorXd>(b.hr_frames[std::size_t(f)].data(), b.hr_frames[std::size_t(f)].size());
    train.ids.push_back(f);
  }
  Ridge<> ridge;
  ridge.fit(exec::seq, b.problem);
  ridge.train(exec::seq, train, {});
  check_no_allocation("Ridge", ridge, lr, hr);
}
