// SoftDECA's simulation on a small layered ball standing in for the head: the local-global and
// the Newton solver agree on sampled parameters; gravity's direction and the skull's scaling act
// visibly; the expression is reached.
#include <algorithm>

#include <simsr/scenario/softdeca/layered_head.hpp>
#include <simsr/scenario/softdeca/softdeca_simulator.hpp>
#include <simsr/scenario/softdeca/sphere_template.hpp>

#include <doctest/doctest.h>

#include "../support/error_of.hpp"
#include "face_fixture.hpp"  // SIMSR_TEST_SANITIZED

namespace scenario_test_softdeca_simulator {

using namespace simsr;
using namespace simsr::scenario;

/// The sphere template (sphere_template.hpp) at icosphere level 2, one layer per shell.
SoftDecaTemplate ball_template() { return sphere_softdeca_template(exec::seq, 2, 1); }

SoftDecaParameters calm() {
  SoftDecaParameters p;  // every weight 1, v = 1, ε = 1, 1 g down, skull as is, quasistatic
  return p;
}

TEST_CASE("parse_softdeca_solver: the two solvers by name; another name refused naming it") {
  CHECK(parse_softdeca_solver("local_global") == SoftDecaSolver::local_global);
  CHECK(parse_softdeca_solver("newton") == SoftDecaSolver::newton);
  for (const std::string bad : {"", "Newton", "lbfgs", "local-global"})
    CHECK(test::typed_error_of<ArgumentError>([&] { parse_softdeca_solver(bad); }) == "softdeca solver: local_global or newton (got '" + bad + "')");
}

TEST_CASE("SoftDecaSimulator: local-global and Newton agree on sampled parameters (both to 1e-9 of the forces)") {
  const SoftDecaTemplate tpl = ball_template();
  SoftDecaSimulator sim(tpl);
  const VecX<> expression = (VecX<>(2) << 0.8, 0.5).finished();
#if defined(SIMSR_TEST_SANITIZED)
  const std::uint64_t samples = 1;  // the same code path; the second sample is the Release build's
#else
  const std::uint64_t samples = 2;
#endif
  for (std::uint64_t i = 0; i < samples; ++i) {
    SoftDecaParameters p = sample_softdeca_parameters(3, i);
    p.cranium_scale = Vec3<>::Ones() + 0.2 * (p.cranium_scale - Vec3<>::Ones());  // milder skulls: one local minimum
    p.jaw_scale = Vec3<>::Ones() + 0.2 * (p.jaw_scale - Vec3<>::Ones());
    CAPTURE(p.to_json().dump());
    const SoftDecaSimulationOptions lg{.solver = SoftDecaSolver::local_global, .steps = 2, .relative_tolerance = 1e-9};
    SoftDecaSimulationOptions nw = lg;
    nw.solver = SoftDecaSolver::newton;
    const SoftDecaResult a = sim.simulate(exec::omp, p, expression, lg);
    const SoftDecaResult b = sim.simulate(exec::omp, p, expression, nw);
    const double moved = (a.skin - tpl.expression(VecX<>::Zero(2))).rowwise().norm().maxCoeff();
    CHECK(moved > 1e-3);
    CHECK((a.skin - b.skin).rowwise().norm().maxCoeff() < 1e-6 * std::max(moved, 1e-3) + 1e-9);
    MESSAGE("sample " << i << ": local-global " << a.total_iterations() << " iterations in " << a.seconds << " s, Newton " << b.total_iterations()
                      << " in " << b.seconds << " s; skin moved up to " << moved * 1e3 << " mm, solvers apart "
                      << (a.skin - b.skin).rowwise().norm().maxCoeff() * 1e9 << " nm");
  }
}

TEST_CASE("SoftDecaSimulator: a local-global solve left unconverged is finished by Newton, or is an error when asked") {
  const SoftDecaTemplate tpl = ball_template();
  SoftDecaSimulator sim(tpl);
  const VecX<> expression = (VecX<>(2) << 0.6, 0.3).finished();
  SoftDecaParameters p = sample_softdeca_parameters(3, 0);
  p.cranium_scale = p.jaw_scale = Vec3<>::Ones();
  // 3 local-global iterations per solve: none of the 3 solves converges in them
  const SoftDecaSimulationOptions capped{.solver = SoftDecaSolver::local_global, .steps = 2, .relative_tolerance = 1e-9, .max_iterations = 3};
  SoftDecaSimulationOptions newton = capped;
  newton.solver = SoftDecaSolver::newton;
  const SoftDecaResult a = sim.simulate(exec::omp, p, expression, capped);
  const SoftDecaResult b = sim.simulate(exec::omp, p, expression, newton);
  CHECK(a.newton_fallbacks == 3);
  CHECK(b.newton_fallbacks == 0);
  for (Index its : a.iterations) CHECK(its > 3);  // 3 of local-global, then Newton's
  const double moved = (b.skin - tpl.expression(VecX<>::Zero(2))).rowwise().norm().maxCoeff();
  CHECK((a.skin - b.skin).rowwise().norm().maxCoeff() < 1e-6 * moved);
  SoftDecaSimulationOptions strict = capped;
  strict.newton_fallback = false;
  CHECK_THROWS_AS(sim.simulate(exec::omp, p, expression, strict), ConvergenceError);
  // Newton's own cap: a solve that needed more Newton iterations than allowed is an error
  const Index most = *std::max_element(a.iterations.begin(), a.iterations.end()) - 3;
  REQUIRE(most >= 2);
  SoftDecaSimulationOptions short_newton = capped;
  short_newton.newton_iterations = most - 1;
  CHECK_THROWS_AS(sim.simulate(exec::omp, p, expression, short_newton), ConvergenceError);
  short_newton.newton_iterations = 0;
  CHECK_THROWS_AS(sim.simulate(exec::omp, p, expression, short_newton), ArgumentError);
}

TEST_CASE("SoftDecaSimulator: gravity's sampled direction moves the soft skin along it") {
  const SoftDecaTemplate tpl = ball_template();
  SoftDecaSimulator sim(tpl);
  const VecX<> none = VecX<>::Zero(2);
  for (const Vec3<>& dir : {Vec3<>(1, 0, 0), Vec3<>(0, 0, -1), Vec3<>(0, 1, 1).normalized()}) {
    SoftDecaParameters p = calm();
    p.w_strain_soft_tissue = p.w_strain_muscle = p.w_volume = 0.01;  // soft enough to sag visibly
    p.w_target = 1e-3;
    p.gravity = 2;
    p.gravity_direction = dir;
    const SoftDecaResult r = sim.simulate(exec::omp, p, none, {.steps = 1});
    const Points<> d = r.skin_at_rest - tpl.expression(none);
    const Vec3<> mean = d.colwise().mean().transpose();
    CAPTURE(dir.transpose());
    CHECK(mean.dot(dir) > 1e-4);                             // sags along g, by tenths of a millimetre at least
    CHECK((mean - mean.dot(dir) * dir).norm() < 0.3 * mean.dot(dir));  // and mostly along it
  }
}

TEST_CASE("SoftDecaSimulator: the skull's per-axis scaling shapes the face; the expression is reached where the target is stiff") {
  const SoftDecaTemplate tpl = ball_template();
  SoftDecaSimulator sim(tpl);
  const VecX<> none = VecX<>::Zero(2);
  SoftDecaParameters p = calm();
  p.w_target = 1e-3;
  p.cranium_scale = Vec3<>(1.3, 1.0, 1.0);
  const SoftDecaResult wide = sim.simulate(exec::omp, p, none, {.steps = 1});
  p.cranium_scale = p.jaw_scale = Vec3<>(1.0, 1.0, 0.7);
  const SoftDecaResult flat = sim.simulate(exec::omp, p, none, {.steps = 1});
  const Points<> rest = tpl.expression(none);
  const auto extent = [](const Points<>& x, int a) { return x.col(a).maxCoeff() - x.col(a).minCoeff(); };
  CHECK(extent(wide.skin_at_rest, 0) > 1.2 * extent(rest, 0));
  CHECK(extent(wide.skin_at_rest, 2) == doctest::Approx(extent(rest, 2)).epsilon(0.1));
  CHECK(extent(flat.skin_at_rest, 2) < 0.8 * extent(rest, 2));
  // a stiff target: the skin follows the expression to within a small fraction of its 1 cm
  SoftDecaParameters q = calm();
  q.w_target = 100;
  q.gravity = 1;
  const VecX<> bulge = (VecX<>(2) << 1.0, 0.0).finished();
  const SoftDecaResult r = sim.simulate(exec::omp, q, bulge, {.steps = 2});
  const double off = (r.skin - tpl.expression(bulge)).rowwise().norm().maxCoeff();
  CHECK(off < 2e-3);
  CHECK(r.inverted_tets == 0);
}

}  // namespace scenario_test_softdeca_simulator
