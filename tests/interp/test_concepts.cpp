// Every method is an interp::Interpolator as it is; the learning ones are TrainableInterpolators;
// needs_neighborhoods_v tells which read the §3.2 neighbourhoods.
#include <simsr/interp/interp.hpp>

#include <doctest/doctest.h>

using namespace simsr;

static_assert(interp::assert_interpolator<interp::Embedded<>>());
static_assert(interp::assert_interpolator<interp::IDW<>>());
static_assert(interp::assert_interpolator<interp::MLS<>>());
static_assert(interp::assert_interpolator<interp::RBF<>>());
static_assert(interp::assert_trainable_interpolator<interp::Ridge<>>());
static_assert(interp::assert_trainable_interpolator<interp::Ridge<double, interp::MLS<>>>());
static_assert(interp::assert_trainable_interpolator<interp::BetaVaeBaseline<>>());
static_assert(interp::assert_trainable_interpolator<interp::Learned<>>());
static_assert(interp::assert_trainable_interpolator<interp::Learned<nn::SuperResolutionNet<double>>>());

static_assert(!interp::TrainableInterpolator<interp::Embedded<>>);
static_assert(!interp::TrainableInterpolator<interp::MLS<>>);

static_assert(!interp::needs_neighborhoods_v<interp::Embedded<>>);
static_assert(interp::needs_neighborhoods_v<interp::IDW<>>);
static_assert(interp::needs_neighborhoods_v<interp::MLS<>>);
static_assert(interp::needs_neighborhoods_v<interp::RBF<>>);
static_assert(!interp::needs_neighborhoods_v<interp::Ridge<>>);              // over Embedded
static_assert(interp::needs_neighborhoods_v<interp::Ridge<double, interp::IDW<>>>);  // over IDW
static_assert(!interp::needs_neighborhoods_v<interp::BetaVaeBaseline<>>);
static_assert(interp::needs_neighborhoods_v<interp::Learned<>>);

namespace {
struct NoTrait {};  // a type that declares nothing: the trait defaults to false
struct PolicyLast {
  using scalar_type = double;
  void fit(interp::UpsamplingProblem<>&, exec::seq_t) {}
  void apply(const Points<>&, Points<>&, exec::seq_t) const {}
  Index num_lr() const { return 0; }
  Index num_hr() const { return 0; }
};
}  // namespace
static_assert(!interp::needs_neighborhoods_v<NoTrait>);
static_assert(!interp::Interpolator<PolicyLast>);  // the policy goes first
// (compile-time checks only: this file fails the build, not a test case, when a method drifts)
