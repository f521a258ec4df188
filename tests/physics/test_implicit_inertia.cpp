// ImplicitInertia (SoftDECA's α, β, γ): finite differences, the quasistatic case, and one
// implicit step of a free body under gravity against its closed form, by both solvers.
#include <simsr/mesh/generators.hpp>
#include <simsr/physics/forces/gravity.hpp>
#include <simsr/physics/forces/implicit_inertia.hpp>
#include <simsr/physics/local_global.hpp>
#include <simsr/physics/quasistatic.hpp>

#include <doctest/doctest.h>

#include <random>

#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;
using namespace simsr::test;

TEST_CASE("ImplicitInertia: gradient and Hessian match finite differences; alpha = beta = 0 is quasistatic") {
  std::mt19937 rng(4);
  const Points<> rest = random_points(7, -1, 1, rng);
  VecX<> m = VecX<>::Random(7).cwiseAbs() + VecX<>::Constant(7, 0.1);
  ImplicitInertia<> dyn(m, rest, {.h = 0.05, .alpha = 1.3, .beta = 0.4, .gamma = 0.8});
  dyn.advance(rest + random_points(7, -0.1, 0.1, rng));
  const Points<> x = rest + random_points(7, -0.2, 0.2, rng);
  CHECK(rel_error(gradient(dyn, x), fd_gradient(dyn, x, 1e-6)) < 1e-7);
  CHECK(rel_error(assembled_hessian(dyn, x, Definiteness::exact), fd_hessian(dyn, x, 1e-6)) < 1e-6);
  ImplicitInertia<> still(m, rest, {.h = 0.05, .alpha = 0, .beta = 0, .gamma = 2});
  still.advance(x);
  CHECK(still.energy(exec::seq, rest) == 0);
  CHECK(gradient(still, rest).norm() == 0);
  CHECK_THROWS_AS(ImplicitInertia<>(m, rest, {.h = 0, .alpha = 1, .beta = 0, .gamma = 0}), ArgumentError);
  CHECK_THROWS_AS(ImplicitInertia<>(m, rest, {.h = 0.1, .alpha = -1, .beta = 0, .gamma = 0}), ArgumentError);
}

TEST_CASE("ImplicitInertia: one step of a free body under gravity is x = (alpha x^ + beta x_n + h^2 g) / (alpha + beta), by Newton and by local-global") {
  const auto mesh = box_tet_mesh<double>(2, 2, 2);
  const Vec3<> g(0.3, -9.81, 0.5);
  const Gravity<> gravity(mesh, 1000.0, g);
  const DynamicsParameters p{.h = 0.02, .alpha = 1.5, .beta = 0.5, .gamma = 0.7};
  ImplicitInertia<> dyn(gravity.masses(), mesh.V, p);
  const Points<> xn = mesh.V.rowwise() + Vec3<>(0.01, 0.02, -0.03).transpose();  // moving at 1.5 m/s-ish
  dyn.advance(xn);
  Points<> expected(mesh.num_vertices(), 3);
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    expected.row(v) = (p.alpha * dyn.prediction(v) + p.beta * xn.row(v).transpose() + p.h * p.h * g) / (p.alpha + p.beta);
  const DirichletBoundary<> none{IndexVector(0), Points<>(0, 3)};
  Points<> xa = xn, xb = xn;
  QuasistaticSolver<> newton(mesh.num_vertices(), mesh.T, NewtonOptions{.relative_tolerance = 1e-12, .progress = {}});
  newton.solve(exec::seq, xa, none, gravity, dyn);
  LocalGlobalSolver<> pd(mesh.num_vertices(), mesh.T, LocalGlobalOptions{.relative_tolerance = 1e-12});
  const auto report = pd.solve(exec::seq, xb, none, gravity, dyn);
  CHECK((xa - expected).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((xb - expected).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(report.iterations == 1);  // a quadratic whose Hessian is L: one global step
}
