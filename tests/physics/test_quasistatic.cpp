#include <simsr/discretize/bcc_lattice.hpp>
#include <simsr/discretize/embedding.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/forces/bone_attachment.hpp>
#include <simsr/physics/forces/gravity.hpp>
#include <simsr/physics/forces/triangle_membrane.hpp>
#include <simsr/physics/materials/materials.hpp>
#include <simsr/physics/quasistatic.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <thread>
#include <stdexcept>

#include "stvk_material.hpp"

using namespace simsr;
using namespace simsr::physics;

namespace {

bool on_box_boundary(const Vec3<>& p, const Vec3<>& lo, const Vec3<>& hi) {
  for (int a = 0; a < 3; ++a)
    if (std::abs(p[a] - lo[a]) < 1e-12 || std::abs(p[a] - hi[a]) < 1e-12) return true;
  return false;
}

/// Patch test: boundary vertices follow an affine map, interior ones start perturbed; the
/// solution must be the affine map everywhere (uniform F, so div P = 0 for any material).
template <class M, class Linear>
double patch_test(const M& material, std::vector<typename M::Element> elements, Linear linear) {
  const auto mesh = box_tet_mesh<double>(3, 3, 3);
  Mat3<> A;
  A << 1.1, 0.05, 0.0, 0.02, 0.95, 0.03, 0.0, 0.04, 1.05;
  const Vec3<> b(0.1, -0.2, 0.3);
  Points<> affine = (mesh.V * A.transpose()).rowwise() + b.transpose();
  BoneAttachments<> frame(mesh.V);
  frame.add_bone("boundary", select_vertices(mesh.V, [](const Vec3<>& p) { return on_box_boundary(p, Vec3<>::Zero(), Vec3<>::Ones()); }));
  DirichletBoundary<> bc = frame.boundary();
  for (Index k = 0; k < bc.size(); ++k) bc.targets.row(k) = affine.row(bc.vertices[k]);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  Points<> x = mesh.V;
  for (Index i = 0; i < x.size(); ++i) x.data()[i] += u(rng);
  ElasticEnergy<M> elastic(mesh, material, std::move(elements));
  QuasistaticSolver<Linear> newton(mesh.num_vertices(), mesh.T, NewtonOptions{.relative_tolerance = 1e-14, .progress = {}}, std::move(linear));
  newton.solve(exec::seq, x, bc, elastic);
  return (x - affine).cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("patch test: an affine boundary displacement is reproduced exactly inside, for every material and solver") {
  CHECK(patch_test(NeoHookean<>::from_young_poisson(1e5, 0.3), {}, SparseCholesky<>{}) < 1e-10);
  CHECK(patch_test(Corotated<>::from_young_poisson(1e5, 0.3), {}, SparseCholesky<>{}) < 1e-10);
  CHECK(patch_test(MooneyRivlin<>(), {}, ConjugateGradient<BlockJacobi<>>({.tolerance = 1e-10})) < 1e-10);
  CHECK(patch_test(simsr_test::StVK{1e5, 1e5}, {}, ConjugateGradient<Jacobi<>>({.tolerance = 1e-12})) < 1e-10);
  const auto fibre = TeranMuscle<>::element(Vec3<>(1, 1, 0).normalized(), 0.3);
  CHECK(patch_test(TeranMuscle<>(), std::vector<MuscleFibre<>>(std::size_t(6 * 27), fibre), SparseCholesky<>{}) < 1e-10);
}

TEST_CASE("a mesh started fully inverted (mirrored through its clamped face) recovers its rest shape") {
  const auto mesh = box_tet_mesh<double>(2, 2, 3);
  BoneAttachments<> floor(mesh.V);
  floor.add_bone("floor", select_vertices(mesh.V, [](const Vec3<>& p) { return p.z() < 1e-12; }));
  for (const char* start : {"mirrored", "collapsed"}) {
    CAPTURE(start);
    Points<> x = mesh.V;
    if (std::string(start) == "mirrored")
      x.col(2) *= -1.0;  // every tet inverted
    else
      x.col(2).setZero();  // every tet flat (J = 0)
    ElasticEnergy<NeoHookean<>> elastic(mesh, NeoHookean<>::from_young_poisson(1e4, 0.3));
    if (std::string(start) == "mirrored") CHECK(elastic.count_inverted(exec::seq, x) == mesh.num_tets());
    QuasistaticSolver<SparseCholesky<>> newton(mesh.num_vertices(), mesh.T, NewtonOptions{.relative_tolerance = 1e-10, .progress = {}});
    const auto report = newton.solve(exec::seq, x, floor.boundary(), elastic);
    CHECK(report.converged);
    CHECK(elastic.count_inverted(exec::seq, x) == 0);
    CHECK((x - mesh.V).cwiseAbs().maxCoeff() < 1e-8);
  }
}

TEST_CASE("a muscle block contracts along its fibres when activated, more with more activation") {
  const auto mesh = box_tet_mesh<double>(8, 2, 2, Vec3<>(0, 0, 0), Vec3<>(0.04, 0.01, 0.01));  // 4 cm × 1 cm × 1 cm
  BoneAttachments<> origin(mesh.V);
  origin.add_bone("origin", select_vertices(mesh.V, [](const Vec3<>& p) { return p.x() < 1e-12; }));
  const IndexVector tip = select_vertices(mesh.V, [](const Vec3<>& p) { return p.x() > 0.04 - 1e-12; });
  ElasticEnergy<TeranMuscle<>> muscle(mesh, TeranMuscle<>());
  QuasistaticSolver<SparseCholesky<>> newton(mesh.num_vertices(), mesh.T);
  Points<> x = mesh.V;
  double previous_length = 0.04;
  for (double a : {0.0, 0.25, 0.5, 1.0}) {
    CAPTURE(a);
    muscle.set_elements(std::vector<MuscleFibre<>>(std::size_t(mesh.num_tets()), TeranMuscle<>::element(Vec3<>::UnitX(), a)));
    newton.solve(exec::seq, x, origin.boundary(), muscle);  // warm start from the previous activation
    double length = 0;
    for (Index k = 0; k < tip.size(); ++k) length += x(tip[k], 0) / double(tip.size());
    MESSAGE("activation " << a << ": muscle length " << length * 100 << " cm (rest 4 cm)");
    if (a == 0.0) {
      CHECK((x - mesh.V).cwiseAbs().maxCoeff() < 1e-12);  // passive and unloaded: stays at rest
    } else {
      CHECK(length < previous_length - 1e-4);  // shorter than with less activation, by ≥ 0.1 mm
    }
    previous_length = length;
  }
  CHECK(previous_length < 0.04 * 0.95);  // full activation shortens the block by more than 5 %
  CHECK(muscle.count_inverted(exec::seq, x) == 0);
}

TEST_CASE("coarse and fine meshes of one hanging block (conforming and BCC embedded) agree in bulk within 5 %") {
  // A soft 10×10×20 cm block hanging from its top face under gravity; bulk response = the mean
  // displacement of a fixed set of material points (the fine mesh's vertices) read through each mesh.
  const Vec3<> lo(0, 0, 0), hi(0.1, 0.1, 0.2);
  const auto fine = box_tet_mesh<double>(6, 6, 12, lo, hi);
  const auto material = NeoHookean<>::from_young_poisson(2e4, 0.3);
  const auto mean_drop = [&](const TetMesh<>& mesh) {
    ElasticEnergy<NeoHookean<>> elastic(mesh, material);
    Gravity<> gravity(mesh, 1000.0, Vec3<>(0, 0, -9.81));
    BoneAttachments<> top(mesh.V);
    top.add_bone("top", select_vertices(mesh.V, [&](const Vec3<>& p) { return p.z() > hi.z() - 1e-12; }));
    QuasistaticSolver<SparseCholesky<>> newton(mesh.num_vertices(), mesh.T);
    Points<> x = mesh.V;
    newton.solve(exec::seq, x, top.boundary(), elastic, gravity);
    const auto emb = embed(exec::seq, mesh, fine.V);
    return -(deform(exec::seq, emb, mesh.T, x).col(2) - fine.V.col(2)).mean();
  };
  const double reference = mean_drop(fine);
  const double coarse = mean_drop(box_tet_mesh<double>(3, 3, 6, lo, hi));
  const double embedded = mean_drop(discretize::bcc_lattice(boundary_surface(fine), 0.05).mesh);
  MESSAGE("mean drop: fine " << reference << " m, coarse conforming " << coarse << ", coarse BCC " << embedded);
  CHECK(reference > 0.005);  // a real load: ≥ 5 mm
  CHECK(std::abs(coarse - reference) < 0.05 * reference);
  CHECK(std::abs(embedded - reference) < 0.05 * reference);
}

TEST_CASE("Newton: warm start at the solution converges at once; seq and omp solves agree bitwise; failures are ConvergenceErrors") {
  const auto mesh = box_tet_mesh<double>(6, 1, 1, Vec3<>(0, 0, 0), Vec3<>(0.6, 0.1, 0.1));
  ElasticEnergy<NeoHookean<>> elastic(mesh, NeoHookean<>::from_young_poisson(1e5, 0.3));
  Gravity<> gravity(mesh, 1000.0, Vec3<>(0, 0, -9.81));
  BoneAttachments<> wall(mesh.V);
  wall.add_bone("wall", select_vertices(mesh.V, [](const Vec3<>& p) { return p.x() < 1e-12; }));
  // One solver type, one set of terms; the policy is an argument of each solve and reaches every
  // term and the linear solver.
  QuasistaticSolver<ConjugateGradient<BlockJacobi<>>> seq(mesh.num_vertices(), mesh.T), omp(mesh.num_vertices(), mesh.T);
  Points<> x = mesh.V, y = mesh.V;
  const auto r1 = seq.solve(exec::seq, x, wall.boundary(), elastic, gravity);
  const auto r2 = omp.solve(exec::omp, y, wall.boundary(), elastic, gravity);
  CHECK(r1.converged);
  CHECK(r1.iterations == r2.iterations);
  CHECK(r1.linear_iterations == r2.linear_iterations);
  CHECK((x - y).cwiseAbs().maxCoeff() == 0.0);
  CHECK(x(mesh.num_vertices() - 1, 2) < -1e-3);  // it sags
  const auto again = seq.solve(exec::seq, x, wall.boundary(), elastic, gravity);
  CHECK(again.iterations == 0);

  // A load far beyond what 2 iterations can reach.
  Gravity<> heavy(mesh, 1e5, Vec3<>(0, 0, -9.81));
  QuasistaticSolver<SparseCholesky<>> short_newton(mesh.num_vertices(), mesh.T, NewtonOptions{.max_iterations = 2, .progress = {}});
  Points<> z = mesh.V;
  try {
    short_newton.solve(exec::seq, z, wall.boundary(), elastic, heavy);
    FAIL("expected a ConvergenceError");
  } catch (const ConvergenceError& e) {
    CHECK(e.iterations() == 2);
    CHECK(e.residual() > 0);
  }
  // A fixed budget instead (accept_at_max_iterations): the iterate after 1 or 2 iterations is
  // returned, unconverged, its energy below the start's (far from the solution the gradient may
  // grow on the way)
  {
    std::vector<Points<>> iterates;
    QuasistaticSolver<SparseCholesky<>> full(mesh.num_vertices(), mesh.T, NewtonOptions{.progress = {}});
    Points<> w = mesh.V;
    const auto done = full.solve(exec::seq, w, wall.boundary(), elastic, heavy);
    REQUIRE(done.converged);
    REQUIRE(done.iterations > 2);
    for (Index budget : {1, 2}) {
      QuasistaticSolver<SparseCholesky<>> fixed(mesh.num_vertices(), mesh.T,
                                               NewtonOptions{.max_iterations = budget, .accept_at_max_iterations = true, .progress = {}});
      Points<> v = mesh.V;
      const auto r = fixed.solve(exec::seq, v, wall.boundary(), elastic, heavy);
      CHECK_FALSE(r.converged);
      CHECK(r.iterations == budget);
      CHECK(r.history.size() == std::size_t(budget));
      CHECK(r.energy < r.history[0].energy);
      CHECK(r.gradient_norm > done.gradient_norm);
      CHECK((v - w).cwiseAbs().maxCoeff() > 0);  // not yet the solution
      iterates.push_back(v);
    }
    // the budget of 2 continues from the budget of 1: a third solver's single step from there lands on it
    QuasistaticSolver<SparseCholesky<>> one(mesh.num_vertices(), mesh.T, NewtonOptions{.max_iterations = 1, .accept_at_max_iterations = true, .progress = {}});
    Points<> u = iterates[0];
    one.solve(exec::seq, u, wall.boundary(), elastic, heavy);
    CHECK((u - iterates[1]).cwiseAbs().maxCoeff() <= 1e-12 * iterates[1].cwiseAbs().maxCoeff());
  }
  // Bad input: wrong position shape, Dirichlet vertex out of range, non-finite target.
  Points<> wrong(3, 3);
  CHECK_THROWS_AS(seq.solve(exec::seq, wrong, wall.boundary(), elastic), ShapeError);
  DirichletBoundary<> bad = wall.boundary();
  bad.vertices[0] = VIndex(mesh.num_vertices());
  CHECK_THROWS_AS(seq.solve(exec::seq, x, bad, elastic), MeshError);
  bad = wall.boundary();
  bad.targets(0, 1) = std::nan("");
  CHECK_THROWS_AS(seq.solve(exec::seq, x, bad, elastic), MeshError);
}

TEST_CASE("Forcing::adaptive (inexact Newton): the same equilibrium to the tolerance in fewer PCG iterations; loose solves first, the solver's own tolerance back after the solve") {
  // a hanging muscle block on a BCC lattice (the LR face's kind of mesh), pulled sideways at its free end
  const auto box = box_tet_mesh<double>(2, 2, 6, Vec3<>(0, 0, 0), Vec3<>(0.1, 0.1, 0.3));
  const TetMesh<double> mesh = discretize::bcc_lattice(box, 0.025).mesh;
  ElasticEnergy<NeoHookean<>> flesh(mesh, NeoHookean<>::from_young_poisson(3e4, 0.45));
  Gravity<> gravity(mesh, 1000.0, Vec3<>(0, 0, -9.81));
  BoneAttachments<> ends(mesh.V);
  ends.add_bone("top", select_vertices(mesh.V, [&](const Vec3<>& p) { return p.z() > 0.3 - 1e-9; }));
  ends.add_bone("bottom", select_vertices(mesh.V, [&](const Vec3<>& p) { return p.z() < 1e-9; }));
  ends.set_transform("bottom", RigidTransform<>{Eigen::AngleAxisd(0.3, Vec3<>::UnitZ()).toRotationMatrix(), Vec3<>(0.04, 0.0, 0.02)});
  using Pcg = ConjugateGradient<BlockJacobi<>>;
  const auto solve = [&](NewtonOptions::Forcing forcing, std::vector<double>* tolerances) {
    NewtonOptions o;
    o.relative_tolerance = 1e-9;
    o.forcing = forcing;
    o.forcing_safeguard = false;  // Eisenstat–Walker alone (the safeguard: the next test case)
    QuasistaticSolver<Pcg> newton(mesh.num_vertices(), mesh.T, o, Pcg({.tolerance = 1e-8}));
    if (tolerances) newton.options().progress = [&](const NewtonIteration&) { tolerances->push_back(newton.linear_solver().options().tolerance); };
    Points<> x = mesh.V;
    const NewtonReport r = newton.solve(exec::omp, x, ends.boundary(), flesh, gravity);
    CHECK(r.converged);
    CHECK(newton.linear_solver().options().tolerance == 1e-8);  // given back
    return std::make_pair(x, r);
  };
  std::vector<double> tolerances;
  const auto [x_fixed, r_fixed] = solve(NewtonOptions::Forcing::fixed, nullptr);
  const auto [x_inexact, r_inexact] = solve(NewtonOptions::Forcing::adaptive, &tolerances);
  const double moved = (x_fixed - mesh.V).cwiseAbs().maxCoeff();
  REQUIRE(moved > 0.01);
  CHECK((x_inexact - x_fixed).cwiseAbs().maxCoeff() <= 1e-6 * moved);
  MESSAGE("Newton / PCG iterations: solves to 1e-8 ", r_fixed.iterations, " / ", r_fixed.linear_iterations, ", adaptive forcing ",
          r_inexact.iterations, " / ", r_inexact.linear_iterations);
  CHECK(r_inexact.linear_iterations < r_fixed.linear_iterations);
  REQUIRE(tolerances.size() >= 2);
  CHECK(tolerances.front() == 0.1);  // forcing_max first
  CHECK(tolerances.back() < tolerances.front());
  for (const double t : tolerances) CHECK((t >= 1e-8 && t <= 0.1));
  // a solver without a tolerance (a direct one) ignores the option
  NewtonOptions o;
  o.relative_tolerance = 1e-9;
  o.forcing = NewtonOptions::Forcing::adaptive;
  QuasistaticSolver<SparseCholesky<>> direct(mesh.num_vertices(), mesh.T, o);
  Points<> x = mesh.V;
  CHECK(direct.solve(exec::seq, x, ends.boundary(), flesh, gravity).converged);
  CHECK((x - x_fixed).cwiseAbs().maxCoeff() <= 1e-6 * moved);
}

namespace {
/// A muscle block (Teran: its passive fibre curve's slope jumps at λ = 1, so Newton's contraction
/// is limited) on a BCC lattice, hanging in gravity, for the Newton schedule's cases.
struct MuscleBlock {
  TetMesh<double> mesh = discretize::bcc_lattice(box_tet_mesh<double>(2, 2, 6, Vec3<>(0, 0, 0), Vec3<>(0.1, 0.1, 0.3)), 0.025).mesh;
  ElasticEnergy<TeranMuscle<>> flesh{mesh, TeranMuscle<>(), std::vector<MuscleFibre<>>(std::size_t(mesh.num_tets()), MuscleFibre<>{Vec3<>::UnitZ(), 0.3})};
  Gravity<> gravity{mesh, 1000.0, Vec3<>(0, 0, -9.81)};
  /// Bones "top" and (with `bottom`) "bottom" on the block's end faces, at rest.
  BoneAttachments<> held_ends(bool bottom = true) const {
    BoneAttachments<> ends(mesh.V);
    ends.add_bone("top", select_vertices(mesh.V, [&](const Vec3<>& p) { return p.z() > 0.3 - 1e-9; }));
    if (bottom) ends.add_bone("bottom", select_vertices(mesh.V, [&](const Vec3<>& p) { return p.z() < 1e-9; }));
    return ends;
  }
  /// Both ends held, the bottom one turned and pulled by random amounts (u: uniform on [−1, 1]).
  template <class Rng>
  BoneAttachments<> random_ends(Rng& rng) const {
    std::uniform_real_distribution<double> u(-1, 1);
    BoneAttachments<> ends = held_ends();
    ends.set_transform("bottom", RigidTransform<>{Eigen::AngleAxisd(0.4 * u(rng), Vec3<>::UnitZ()).toRotationMatrix(),
                                                  Vec3<>(0.03 * u(rng), 0.03 * u(rng), 0.03 * u(rng))});
    return ends;
  }
};
}  // namespace

TEST_CASE("Forcing::adaptive's safeguard (Kelley): no linear solve asked for much below the Newton tolerance, the same equilibrium in fewer PCG iterations") {
  // the muscle block, its ends turned and pulled by random amounts
  const MuscleBlock block;
  const TetMesh<double>& mesh = block.mesh;
  const auto& flesh = block.flesh;
  const auto& gravity = block.gravity;
  using Pcg = ConjugateGradient<BlockJacobi<>>;
  std::mt19937 rng(17);
  Index linear_safeguarded = 0, linear_eisenstat_walker = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const BoneAttachments<> ends = block.random_ends(rng);
    const double relative = trial % 2 ? 1e-9 : 1e-10;
    const auto solve = [&](bool safeguard, std::vector<NewtonIteration>& seen) {
      NewtonOptions o;
      o.relative_tolerance = relative;
      o.forcing = NewtonOptions::Forcing::adaptive;
      o.forcing_safeguard = safeguard;
      o.progress = [&](const NewtonIteration& it) { seen.push_back(it); };
      QuasistaticSolver<Pcg> newton(mesh.num_vertices(), mesh.T, o, Pcg({.tolerance = 1e-10}));
      Points<> x = mesh.V;
      const NewtonReport r = newton.solve(exec::omp, x, ends.boundary(), flesh, gravity);
      CHECK(r.converged);
      CHECK(newton.linear_solver().options().tolerance == 1e-10);  // given back
      return std::make_pair(x, r);
    };
    std::vector<NewtonIteration> guarded, plain;
    const auto [x_guarded, r_guarded] = solve(true, guarded);
    const auto [x_plain, r_plain] = solve(false, plain);
    const double moved = (x_plain - mesh.V).cwiseAbs().maxCoeff();
    REQUIRE(moved > 1e-3);
    CHECK((x_guarded - x_plain).cwiseAbs().maxCoeff() <= 1e-5 * moved);
    REQUIRE(!guarded.empty());
    for (const NewtonIteration& it : guarded) {
      CHECK(it.tolerance > 0);
      CHECK(it.gradient_norm > it.tolerance);  // an iteration that steps has not converged
      // η ≥ ½ τ/‖g‖ unless that exceeds the cap; never below the solver's own, never above the cap
      CHECK(it.linear_tolerance >= std::min(0.1, 0.5 * it.tolerance / it.gradient_norm) * (1 - 1e-12));
      CHECK((it.linear_tolerance >= 1e-10 && it.linear_tolerance <= 0.1));
    }
    for (const NewtonIteration& it : plain) CHECK((it.linear_tolerance >= 1e-10 && it.linear_tolerance <= 0.1));
    // the safeguard only ever loosens a solve: the last one at least as loose as Eisenstat–Walker's
    CHECK(guarded.back().linear_tolerance >= plain.back().linear_tolerance);
    CHECK(r_guarded.iterations <= r_plain.iterations + 1);
    linear_safeguarded += r_guarded.linear_iterations;
    linear_eisenstat_walker += r_plain.linear_iterations;
  }
  MESSAGE("PCG iterations over 6 random loadings: Eisenstat-Walker alone ", linear_eisenstat_walker, ", with Kelley's safeguard ",
          linear_safeguarded);
  CHECK(linear_safeguarded < linear_eisenstat_walker);
}

TEST_CASE("Newton progress: every iteration is reported, with the Hessian it used") {
  const auto mesh = box_tet_mesh<double>(4, 1, 1, Vec3<>(0, 0, 0), Vec3<>(0.4, 0.1, 0.1));
  ElasticEnergy<NeoHookean<>> elastic(mesh, NeoHookean<>::from_young_poisson(1e5, 0.3));
  Gravity<> gravity(mesh, 1000.0, Vec3<>(0, 0, -9.81));
  BoneAttachments<> wall(mesh.V);
  wall.add_bone("wall", select_vertices(mesh.V, [](const Vec3<>& p) { return p.x() < 1e-12; }));
  std::vector<NewtonIteration> seen;
  for (auto mode : {NewtonOptions::Hessian::adaptive, NewtonOptions::Hessian::projected}) {
    seen.clear();
    NewtonOptions o;
    o.hessian = mode;
    o.progress = [&](const NewtonIteration& it) { seen.push_back(it); };
    QuasistaticSolver<SparseCholesky<>> newton(mesh.num_vertices(), mesh.T, o);
    Points<> x = mesh.V;
    const auto r = newton.solve(exec::seq, x, wall.boundary(), elastic, gravity);
    CHECK(Index(seen.size()) == r.iterations);
    CHECK(r.history.size() == seen.size());
    for (std::size_t k = 1; k < seen.size(); ++k) CHECK(seen[k].energy <= seen[k - 1].energy);
    if (mode == NewtonOptions::Hessian::projected)
      for (const auto& it : seen) CHECK(it.projected);
  }
}

namespace {
/// An EnergyTerm that forwards to `inner` and sleeps a fixed time in each call kind, counting the
/// calls: NewtonReport::seconds must put at least calls × sleep in each call kind's bucket.
template <class Inner>
struct SlowTerm {
  const Inner* inner;
  std::chrono::milliseconds energy_sleep, gradient_sleep, hessian_sleep;
  mutable int energies = 0, gradients = 0, hessians = 0;
  template <class P>
  double energy(P policy, const Points<>& x) const {
    ++energies;
    std::this_thread::sleep_for(energy_sleep);
    return inner->energy(policy, x);
  }
  template <class P>
  void add_gradient(P policy, const Points<>& x, Points<>& g) const {
    ++gradients;
    std::this_thread::sleep_for(gradient_sleep);
    inner->add_gradient(policy, x, g);
  }
  template <class P>
  void add_hessian(P policy, const Points<>& x, BlockHessian<>& H, Definiteness d) const {
    ++hessians;
    std::this_thread::sleep_for(hessian_sleep);
    inner->add_hessian(policy, x, H, d);
  }
};
}  // namespace

TEST_CASE("NewtonReport::seconds: each call's time lands in its own part; the parts add up to at most the total") {
  const auto mesh = box_tet_mesh<double>(4, 1, 1, Vec3<>(0, 0, 0), Vec3<>(0.4, 0.1, 0.1));
  ElasticEnergy<NeoHookean<>> elastic(mesh, NeoHookean<>::from_young_poisson(1e5, 0.3));
  Gravity<> gravity(mesh, 1000.0, Vec3<>(0, 0, -9.81));
  BoneAttachments<> wall(mesh.V);
  wall.add_bone("wall", select_vertices(mesh.V, [](const Vec3<>& p) { return p.x() < 1e-12; }));
  using namespace std::chrono_literals;
  // one part made slow at a time: only its bucket may hold the sleeps
  for (int slow = 0; slow < 3; ++slow) {
    CAPTURE(slow);
    SlowTerm<ElasticEnergy<NeoHookean<>>> term{&elastic, slow == 0 ? 5ms : 0ms, slow == 1 ? 5ms : 0ms, slow == 2 ? 5ms : 0ms};
    QuasistaticSolver<ConjugateGradient<BlockJacobi<>>> newton(mesh.num_vertices(), mesh.T, {}, ConjugateGradient<BlockJacobi<>>({.tolerance = 1e-8}));
    Points<> x = mesh.V;
    const NewtonReport r = newton.solve(exec::seq, x, wall.boundary(), term, gravity);
    REQUIRE(r.converged);
    REQUIRE(r.iterations >= 2);
    const NewtonSeconds& t = r.seconds;
    const double parts = t.energy + t.gradient + t.hessian + t.linear_setup + t.linear_solve;
    for (double part : {t.energy, t.gradient, t.hessian, t.linear_setup, t.linear_solve}) CHECK(part >= 0);
    CHECK(t.linear_solve > 0);
    CHECK(parts <= t.total);
    const double slept = 0.005 * (slow == 0 ? term.energies : slow == 1 ? term.gradients : term.hessians);
    const double bucket = slow == 0 ? t.energy : slow == 1 ? t.gradient : t.hessian;
    CHECK(bucket >= slept);
    // the other buckets did not get the sleeps: on this 4-tet beam each takes microseconds, far
    // below the ≥ 10 ms slept (two or more calls of 5 ms), even under a sanitizer
    for (int other = 0; other < 3; ++other)
      if (other != slow) CHECK((other == 0 ? t.energy : other == 1 ? t.gradient : t.hessian) < slept);
  }
}

TEST_CASE("Hessian::regularized: where the exact Hessian is indefinite it is shifted, not projected; where it is definite, Newton as adaptive") {
  CHECK(std::string(hessian_name(NewtonOptions::Hessian::projected)) == "projected");
  CHECK(std::string(hessian_name(NewtonOptions::Hessian::adaptive)) == "adaptive");
  CHECK(std::string(hessian_name(NewtonOptions::Hessian::regularized)) == "regularized");
  // a cloth membrane crumpled inside its pinned boundary: compressed triangles make the exact
  // Hessian indefinite at the start; the minimum (energy 0) is the flat rest sheet
  const TriMesh<> sheet = square_sheet(1.0, 8);
  const Index n = sheet.V.rows();
  const TriangleMembrane<> stretch(n, sheet.V, sheet.F, 50.0);
  DirichletBoundary<> rim{boundary_vertices(sheet.F), Points<>()};
  REQUIRE(rim.vertices.size() == 32);  // the 8×8-cell sheet's rim
  rim.targets = sheet.V(rim.vertices, Eigen::all);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int shifted_runs = 0, warm_starts = 0;
  for (int trial = 0; trial < 8; ++trial) {
    Points<> start = sheet.V;
    for (Index i = 0; i < n; ++i) {  // towards the centre, 15-35 %, and out of the plane by up to 3 cm
      const double s = 0.75 + 0.1 * u(rng);
      start.row(i).head<2>() = Eigen::RowVector2d(0.5, 0.5) + s * (sheet.V.row(i).head<2>() - Eigen::RowVector2d(0.5, 0.5));
      start(i, 2) = 0.03 * u(rng);
    }
    std::vector<NewtonIteration> seen;
    NewtonOptions o{.relative_tolerance = 1e-10, .max_iterations = 200, .hessian = NewtonOptions::Hessian::regularized, .progress = {}};
    o.progress = [&](const NewtonIteration& it) { seen.push_back(it); };
    QuasistaticSolver<> newton(n, Tets(0, 4), o);
    Points<> x = start;
    const auto r = newton.solve(exec::seq, x, rim, stretch);
    REQUIRE(r.converged);
    CHECK(stretch.energy(exec::seq, x) < 1e-12);
    CHECK((x - sheet.V).cwiseAbs().maxCoeff() < 1e-5);
    bool shifted = false;
    for (std::size_t k = 0; k < seen.size(); ++k) {
      const NewtonIteration& it = seen[k];
      CHECK(it.shift >= 0);
      CHECK(it.shift <= 100);
      CHECK((it.shift == 0 || !it.projected));  // a shifted step is not a projected one
      // after a shift τ > 10⁻³ the exact Hessian is not tried again: the next search starts at τ/10
      if (k > 0 && seen[k - 1].shift > 1.001e-3 && !it.projected) {
        CHECK(it.shift >= seen[k - 1].shift / 10 * (1 - 1e-9));
        warm_starts += 1;
      }
      shifted = shifted || it.shift > 0;
    }
    shifted_runs += shifted;
  }
  CHECK(shifted_runs > 0);  // the case is what it is meant to be: indefinite somewhere
  CHECK(warm_starts > 0);   // and a shift follows a shift somewhere
  MESSAGE("crumpled membranes: the shifted Hessian used in " << shifted_runs << " of 8 solves; " << warm_starts
                                                             << " searches started below the last iteration's shift");

  // where the exact Hessian is positive definite throughout (a hanging cantilever), the steps are
  // adaptive's, bit for bit
  const auto mesh = box_tet_mesh<double>(4, 1, 1, Vec3<>(0, 0, 0), Vec3<>(0.4, 0.1, 0.1));
  ElasticEnergy<NeoHookean<>> elastic(mesh, NeoHookean<>::from_young_poisson(1e5, 0.3));
  Gravity<> gravity(mesh, 1000.0, Vec3<>(0, 0, -9.81));
  BoneAttachments<> wall(mesh.V);
  wall.add_bone("wall", select_vertices(mesh.V, [](const Vec3<>& p) { return p.x() < 1e-12; }));
  Points<> xa = mesh.V, xr = mesh.V;
  std::vector<NewtonIteration> seen;
  NewtonOptions ro;
  ro.hessian = NewtonOptions::Hessian::regularized;
  ro.progress = [&](const NewtonIteration& it) { seen.push_back(it); };
  QuasistaticSolver<SparseCholesky<>> adaptive(mesh.num_vertices(), mesh.T), regularized(mesh.num_vertices(), mesh.T, ro);
  const auto ra = adaptive.solve(exec::seq, xa, wall.boundary(), elastic, gravity);
  const auto rr = regularized.solve(exec::seq, xr, wall.boundary(), elastic, gravity);
  bool any = false;
  for (const auto& it : seen) any = any || it.shift > 0 || it.projected;
  REQUIRE_FALSE(any);
  CHECK(ra.iterations == rr.iterations);
  CHECK(xa == xr);
}

namespace {
/// Gravity that counts its add_hessian calls: how many Hessians a Newton solve assembled.
struct CountedGravity {
  const Gravity<>* gravity;
  mutable int hessians = 0;
  template <class P>
  double energy(P p, const Points<>& x) const { return gravity->energy(p, x); }
  template <class P>
  void add_gradient(P p, const Points<>& x, Points<>& g) const { gravity->add_gradient(p, x, g); }
  template <class P>
  void add_hessian(P p, const Points<>& x, BlockHessian<>& H, Definiteness d) const {
    ++hessians;
    gravity->add_hessian(p, x, H, d);
  }
};
}  // namespace

TEST_CASE("NewtonOptions::chord_below: after a 100x drop of the gradient the old Hessian is reused; the same equilibrium, fewer Hessians; PCG and Cholesky") {
  // the muscle block of the safeguard case (Newton's contraction limited by the fibre curve's kink),
  // random end loadings
  const MuscleBlock block;
  const TetMesh<double>& mesh = block.mesh;
  const auto& flesh = block.flesh;
  std::mt19937 rng(23);
  int chords = 0, hessians_newton = 0, hessians_chord = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const BoneAttachments<> ends = block.random_ends(rng);
    const auto solve = [&]<class Linear>(Linear linear, double chord_below, auto policy) {
      NewtonOptions o;
      o.relative_tolerance = 1e-9;
      o.forcing = NewtonOptions::Forcing::adaptive;
      o.chord_below = chord_below;
      QuasistaticSolver<Linear> newton(mesh.num_vertices(), mesh.T, o, std::move(linear));
      CountedGravity counted{&block.gravity};
      Points<> x = mesh.V;
      const NewtonReport r = newton.solve(policy, x, ends.boundary(), flesh, counted);
      CHECK(r.converged);
      int chord_iterations = 0;
      for (std::size_t k = 0; k < r.history.size(); ++k)
        if (r.history[k].chord) {
          ++chord_iterations;
          REQUIRE(k > 0);
          // only after a 100× drop of ‖g‖ (the previous iteration's ‖g‖ against this one's)
          CHECK(r.history[k].gradient_norm <= chord_below * r.history[k - 1].gradient_norm);
          CHECK(r.history[k].projected == r.history[k - 1].projected);
        }
      // every iteration that is no chord step assembles one Hessian (two where it projects after trying the exact one)
      const auto full = std::count_if(r.history.begin(), r.history.end(), [](const NewtonIteration& it) { return !it.chord; });
      CHECK(counted.hessians >= full);
      return std::make_tuple(x, r, chord_iterations, counted.hessians);
    };
    using Pcg = ConjugateGradient<BlockJacobi<>>;
    const auto [x_newton, r_newton, no_chords, h_newton] = solve(Pcg({.tolerance = 1e-10}), 0.0, exec::omp);
    const auto [x_chord, r_chord, chord_iterations, h_chord] = solve(Pcg({.tolerance = 1e-10}), 0.01, exec::omp);
    CHECK(no_chords == 0);
    const double moved = (x_newton - mesh.V).cwiseAbs().maxCoeff();
    REQUIRE(moved > 1e-3);
    CHECK((x_chord - x_newton).cwiseAbs().maxCoeff() <= 1e-5 * moved);
    CHECK(h_chord + chord_iterations <= h_newton + 2);  // a chord iteration saves its Hessian (one more iteration may be taken)
    // seq == omp bitwise with chord steps as without
    const auto [x_seq, r_seq, chord_seq, h_seq] = solve(Pcg({.tolerance = 1e-10}), 0.01, exec::seq);
    CHECK((x_seq - x_chord).cwiseAbs().maxCoeff() == 0);
    CHECK(chord_seq == chord_iterations);
    // a direct solver reuses its factorization
    const auto [x_direct, r_direct, chord_direct, h_direct] = solve(SparseCholesky<>{}, 0.01, exec::omp);
    const auto [x_direct_newton, r_direct_newton, no_chords_direct, h_direct_newton] = solve(SparseCholesky<>{}, 0.0, exec::omp);
    CHECK((x_direct - x_direct_newton).cwiseAbs().maxCoeff() <= 1e-5 * moved);
    CHECK(h_direct + chord_direct <= h_direct_newton + 2);
    chords += chord_iterations + chord_direct;
    hessians_newton += h_newton;
    hessians_chord += h_chord;
  }
  MESSAGE("8 random loadings: chord steps (PCG and LDLT) ", chords, "; Hessians assembled (PCG) full Newton ", hessians_newton, ", with chords ", hessians_chord);
  CHECK(chords > 0);
  CHECK(hessians_chord < hessians_newton);
}

namespace {
/// CountedGravity whose add_hessian throws while `fail` is set (a setup lost part-way).
struct FailingGravity : CountedGravity {
  mutable bool fail = false;
  template <class P>
  void add_hessian(P p, const Points<>& x, BlockHessian<>& H, Definiteness d) const {
    if (fail) throw std::runtime_error("FailingGravity: Hessian refused");
    CountedGravity::add_hessian(p, x, H, d);
  }
};
}  // namespace

TEST_CASE("NewtonOptions::chord_first: frames in a sequence start from the previous frame's last Hessian; the same equilibria, fewer Hessians; guarded by the fixed DOFs and by a lost setup") {
  // the muscle block in random sequences of 6 frames: the bottom end turned and pulled a little
  // further each frame (a random rate per sequence), each frame warm-started from the last
  const MuscleBlock block;
  const TetMesh<double>& mesh = block.mesh;
  const auto& flesh = block.flesh;
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto options = [](bool chord_first) {
    NewtonOptions o;
    o.relative_tolerance = 1e-9;
    o.forcing = NewtonOptions::Forcing::adaptive;
    o.chord_first = chord_first;
    return o;
  };
  int carried = 0, refused = 0, hessians_newton = 0, hessians_carried = 0;
  for (int sequence = 0; sequence < 4; ++sequence) {
    const double turn = 0.08 * u(rng), pull = 0.006 * u(rng), shear = 0.006 * u(rng);
    BoneAttachments<> ends = block.held_ends();
    const auto run = [&]<class Linear>(Linear linear, bool chord_first, auto policy) {
      QuasistaticSolver<Linear> newton(mesh.num_vertices(), mesh.T, options(chord_first), std::move(linear));
      CountedGravity counted{&block.gravity};
      Points<> x = mesh.V;
      std::vector<Points<>> frames;
      std::vector<char> first_chord;
      for (int f = 1; f <= 6; ++f) {
        ends.set_transform("bottom", RigidTransform<>{Eigen::AngleAxisd(turn * f, Vec3<>::UnitZ()).toRotationMatrix(), Vec3<>(shear * f, 0, pull * f)});
        const NewtonReport r = newton.solve(policy, x, ends.boundary(), flesh, counted);
        CHECK(r.converged);
        REQUIRE(!r.history.empty());
        for (std::size_t k = 1; k < r.history.size(); ++k) CHECK_FALSE(r.history[k].chord);  // chord_below is off
        if (f == 1 || !chord_first) CHECK_FALSE(r.history[0].chord);  // nothing to carry
        first_chord.push_back(r.history[0].chord);
        frames.push_back(x);
      }
      return std::make_tuple(frames, first_chord, counted.hessians);
    };
    using Pcg = ConjugateGradient<BlockJacobi<>>;
    const auto [x_newton, no_chords, h_newton] = run(Pcg({.tolerance = 1e-10}), false, exec::omp);
    const auto [x_carried, chords, h_carried] = run(Pcg({.tolerance = 1e-10}), true, exec::omp);
    for (std::size_t f = 0; f < x_newton.size(); ++f) {
      const double moved = (x_newton[f] - mesh.V).cwiseAbs().maxCoeff();
      REQUIRE(moved > 1e-4);
      CHECK((x_carried[f] - x_newton[f]).cwiseAbs().maxCoeff() <= 1e-5 * moved);
    }
    const int n_chords = int(std::count(chords.begin(), chords.end(), char(1)));
    carried += n_chords;
    refused += 5 - n_chords;  // frames 2–6 whose carried step the guards turned down
    hessians_newton += h_newton;
    hessians_carried += h_carried;
    // seq == omp bitwise
    const auto [x_seq, chords_seq, h_seq] = run(Pcg({.tolerance = 1e-10}), true, exec::seq);
    for (std::size_t f = 0; f < x_seq.size(); ++f) CHECK((x_seq[f] - x_carried[f]).cwiseAbs().maxCoeff() == 0);
    CHECK(chords_seq == chords);
    // a direct solver carries its factorization the same way
    const auto [x_direct, chords_direct, h_direct] = run(SparseCholesky<>{}, true, exec::omp);
    for (std::size_t f = 0; f < x_direct.size(); ++f)
      CHECK((x_direct[f] - x_newton[f]).cwiseAbs().maxCoeff() <= 1e-5 * (x_newton[f] - mesh.V).cwiseAbs().maxCoeff());
    CHECK(std::count(chords_direct.begin(), chords_direct.end(), char(1)) > 0);
  }
  MESSAGE("4 sequences of 6 frames: first steps on the carried Hessian ", carried, " (turned down ", refused, "); Hessians assembled ",
          hessians_carried, " against ", hessians_newton, " without");
  CHECK(carried > 0);
  CHECK(hessians_carried < hessians_newton);

  // the guards: other fixed DOFs, and a setup lost to a throw, carry nothing
  using Pcg = ConjugateGradient<BlockJacobi<>>;
  QuasistaticSolver<Pcg> newton(mesh.num_vertices(), mesh.T, options(true), Pcg({.tolerance = 1e-10}));
  FailingGravity failing;
  failing.gravity = &block.gravity;
  BoneAttachments<> both = block.held_ends(), top_only = block.held_ends(false);
  both.set_transform("bottom", RigidTransform<>{Mat3<>::Identity(), Vec3<>(0, 0, 0.01)});
  Points<> x = mesh.V;
  CHECK_FALSE(newton.solve(exec::omp, x, both.boundary(), flesh, failing).history.at(0).chord);
  both.set_transform("bottom", RigidTransform<>{Mat3<>::Identity(), Vec3<>(0, 0, 0.012)});
  CHECK(newton.solve(exec::omp, x, both.boundary(), flesh, failing).history.at(0).chord);  // carried
  Points<> y = x;
  CHECK_FALSE(newton.solve(exec::omp, y, top_only.boundary(), flesh, failing).history.at(0).chord);  // other fixed DOFs
  top_only.set_transform("top", RigidTransform<>{Mat3<>::Identity(), Vec3<>(0.002, 0, 0)});
  CHECK(newton.solve(exec::omp, y, top_only.boundary(), flesh, failing).history.at(0).chord);  // the same ones again
  // a Hessian that throws part-way: the next solve starts afresh (the linear solver's setup is not
  // trusted). The throwing solve's first iteration is a carried step (both ends held, as the solve
  // before it), its second assembles and throws: what it leaves held would otherwise pass the
  // fixed-DOF guard.
  both.set_transform("bottom", RigidTransform<>{Mat3<>::Identity(), Vec3<>(0, 0, 0.014)});
  CHECK_FALSE(newton.solve(exec::omp, x, both.boundary(), flesh, failing).history.at(0).chord);  // other fixed DOFs than the last solve's
  failing.fail = true;
  std::vector<NewtonIteration> seen;
  newton.options().progress = [&](const NewtonIteration& it) { seen.push_back(it); };
  y = mesh.V;
  CHECK_THROWS_AS(newton.solve(exec::omp, y, both.boundary(), flesh, failing), std::runtime_error);
  REQUIRE(seen.size() == 1);
  CHECK(seen[0].chord);  // the carried step went through; the next iteration's Hessian threw
  newton.options().progress = nullptr;
  failing.fail = false;
  x = mesh.V;
  CHECK_FALSE(newton.solve(exec::omp, x, both.boundary(), flesh, failing).history.at(0).chord);
}
