// LocalGlobalSolver: it reaches Newton's solution of the same SoftDECA problem; plain projective
// dynamics decreases the energy with every unit step; a sampled ε and volume target are met;
// seq == omp; the factorization is reused per weight set.
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/forces/gravity.hpp>
#include <simsr/physics/forces/implicit_inertia.hpp>
#include <simsr/physics/forces/surface_bending.hpp>
#include <simsr/physics/forces/vertex_targets.hpp>
#include <simsr/physics/local_global.hpp>
#include <simsr/physics/materials/strain_limit.hpp>
#include <simsr/physics/materials/volume_target.hpp>
#include <simsr/physics/quasistatic.hpp>

#include <doctest/doctest.h>

#include <random>

using namespace simsr;
using namespace simsr::physics;

namespace test_local_global {

/// A 4×3×3 box, its bottom (z = 0) held, with every SoftDECA term: strain band, volume target,
/// skin bending, the top pulled toward shifted targets, a few vertices kept at distances from
/// anchors, gravity, and one dynamic step from a moving state.
struct Problem {
  TetMesh<> mesh = box_tet_mesh<double>(4, 3, 3);
  ElasticEnergy<StrainLimit<>> strain;
  ElasticEnergy<VolumeTarget<>> volume;
  SurfaceBending<> bending;
  VertexTargets<> targets, distances;
  Gravity<> gravity;
  ImplicitInertia<> dynamics;
  DirichletBoundary<> bottom;

  static IndexVector where(const Points<>& V, int axis, double value) {
    std::vector<VIndex> v;
    for (Index i = 0; i < V.rows(); ++i)
      if (std::abs(V(i, axis) - value) < 1e-12) v.push_back(VIndex(i));
    return Eigen::Map<IndexVector>(v.data(), Index(v.size()));
  }

  /// The top (z = 1) pulled toward itself shifted by (0.15, 0, 0.1).
  static VertexTargets<> top_targets(const TetMesh<>& mesh) {
    const IndexVector top = where(mesh.V, 2, 1.0);
    Points<> s(top.size(), 3);
    for (Index k = 0; k < top.size(); ++k) s.row(k) = mesh.V.row(top[k]) + Vec3<>(0.15, 0.0, 0.1).transpose();
    return VertexTargets<>::attraction(mesh.num_vertices(), top, s, VecX<>::Constant(top.size(), 0.3));
  }
  /// The x = 1 side kept at its rest distance + 5 % from an anchor beyond it.
  static VertexTargets<> side_distances(const TetMesh<>& mesh) {
    const IndexVector side = where(mesh.V, 0, 1.0);
    Points<> anchors(side.size(), 3);
    VecX<> d(side.size());
    for (Index k = 0; k < side.size(); ++k) {
      anchors.row(k) = Vec3<>(1.5, 0.5, 0.5).transpose();
      d[k] = 1.05 * (mesh.V.row(side[k]) - anchors.row(k)).norm();
    }
    return VertexTargets<>(mesh.num_vertices(), side, anchors, d, VecX<>::Constant(side.size(), 0.2));
  }

  Problem(double eps, double v, double w_strain, double w_volume)
      : strain(mesh, StrainLimit<>(w_strain, eps)),
        volume(mesh, VolumeTarget<>(w_volume, v)),
        bending(mesh.num_vertices(), mesh.V, boundary_faces(mesh.T), 0.02),
        targets(top_targets(mesh)),
        distances(side_distances(mesh)),
        gravity(mesh, 1.0, Vec3<>(0.2, -0.4, -1.0)),
        dynamics(gravity.masses(), mesh.V, {.h = 0.1, .alpha = 1.0, .beta = 0.3, .gamma = 1.0}) {
    const IndexVector b = where(mesh.V, 2, 0.0);
    bottom.vertices = b;
    bottom.targets.resize(b.size(), 3);
    for (Index k = 0; k < b.size(); ++k) bottom.targets.row(k) = mesh.V.row(b[k]);
    dynamics.advance(mesh.V.rowwise() + Vec3<>(0.0, 0.01, 0.0).transpose());
  }
};

}  // namespace test_local_global

TEST_CASE("LocalGlobalSolver reaches the Newton solution of the same problem (every SoftDECA term, sampled parameters)") {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> eps(0.7, 1.3), vol(0.5, 1.5), logw(std::log(0.3), std::log(3.0));
  for (int sample = 0; sample < 4; ++sample) {
    const double e = eps(rng), v = vol(rng), ws = std::exp(logw(rng)), wv = std::exp(logw(rng));
    CAPTURE(e);
    CAPTURE(v);
    test_local_global::Problem p(e, v, ws, wv);
    Points<> xn = p.mesh.V, xl = p.mesh.V;
    QuasistaticSolver<> newton(p.mesh.num_vertices(), p.mesh.T, NewtonOptions{.relative_tolerance = 1e-11, .progress = {}});
    const auto rn = newton.solve(exec::seq, xn, p.bottom, p.strain, p.volume, p.bending, p.targets, p.distances, p.gravity, p.dynamics);
    LocalGlobalSolver<> pd(p.mesh.num_vertices(), p.mesh.T, LocalGlobalOptions{.relative_tolerance = 1e-11});
    const auto rl = pd.solve(exec::seq, xl, p.bottom, p.strain, p.volume, p.bending, p.targets, p.distances, p.gravity, p.dynamics);
    CHECK(rn.converged);
    CHECK(rl.converged);
    // the body moved (the problem is not trivial) and both solvers put it in the same place
    CHECK((xn - p.mesh.V).cwiseAbs().maxCoeff() > 0.02);
    CHECK((xl - xn).cwiseAbs().maxCoeff() < 1e-7);
    CHECK(rl.energy == doctest::Approx(rn.energy).epsilon(1e-9));
    MESSAGE("eps " << e << ", v " << v << ": Newton " << rn.iterations << " iterations, local-global " << rl.iterations
                   << ", |x_pd - x_newton| " << (xl - xn).cwiseAbs().maxCoeff());
  }
}

TEST_CASE("LocalGlobalSolver: plain projective dynamics (history 0) on projective terms takes every unit step and lowers the energy each time") {
  test_local_global::Problem p(1.1, 1.0, 1.0, 1.0);
  Points<> x = p.mesh.V;
  LocalGlobalSolver<> pd(p.mesh.num_vertices(), p.mesh.T, LocalGlobalOptions{.relative_tolerance = 1e-6, .max_iterations = 5000, .history = 0});
  const auto r = pd.solve(exec::seq, x, p.bottom, p.strain, p.bending, p.targets, p.distances, p.gravity, p.dynamics);
  CHECK(r.converged);
  REQUIRE(r.history.size() > 3);
  for (std::size_t i = 0; i < r.history.size(); ++i) {
    CHECK(r.history[i].step_length == 1.0);
    if (i > 0) CHECK(r.history[i].energy <= r.history[i - 1].energy);
  }
  // L-BFGS on top of the same matrix needs fewer iterations to the same tolerance
  Points<> y = p.mesh.V;
  LocalGlobalSolver<> lbfgs(p.mesh.num_vertices(), p.mesh.T, LocalGlobalOptions{.relative_tolerance = 1e-6, .history = 5});
  const auto r5 = lbfgs.solve(exec::seq, y, p.bottom, p.strain, p.bending, p.targets, p.distances, p.gravity, p.dynamics);
  MESSAGE("plain projective dynamics: " << r.iterations << " iterations; with L-BFGS(5): " << r5.iterations);
  CHECK(r5.iterations < r.iterations);
}

TEST_CASE("LocalGlobalSolver: a sampled eps and volume target are met where the energy can reach zero") {
  // Band [0.8, 1] and det F = 0.512 = 0.8³ allow one state per tet: F = 0.8 R. One vertex held.
  const auto mesh = box_tet_mesh<double>(3, 3, 3);
  const ElasticEnergy<StrainLimit<>> strain(mesh, StrainLimit<>(1.0, 0.8));
  const ElasticEnergy<VolumeTarget<>> volume(mesh, VolumeTarget<>(1.0, 0.512));
  const DirichletBoundary<> one{(IndexVector(1) << 0).finished(), mesh.V.topRows(1)};
  Points<> x = mesh.V;
  LocalGlobalSolver<> pd(mesh.num_vertices(), mesh.T, LocalGlobalOptions{.relative_tolerance = 1e-10});
  pd.solve(exec::seq, x, one, strain, volume);
  for (Index t = 0; t < mesh.num_tets(); ++t) {
    const Vec3<> s = signed_svd(strain.deformation_gradient(x, t)).sigma;
    CHECK((s.array() - 0.8).abs().maxCoeff() < 1e-5);
  }
  // Band [1, 1.3] and det F = 1.2 (reachable by a uniform 1.2^(1/3) = 1.063 stretch): every tet
  // ends inside the band with the target volume.
  const ElasticEnergy<StrainLimit<>> loose(mesh, StrainLimit<>(1.0, 1.3));
  const ElasticEnergy<VolumeTarget<>> grow(mesh, VolumeTarget<>(1.0, 1.2));
  Points<> y = mesh.V;
  LocalGlobalSolver<> pd2(mesh.num_vertices(), mesh.T, LocalGlobalOptions{.relative_tolerance = 1e-10});
  pd2.solve(exec::seq, y, one, loose, grow);
  for (Index t = 0; t < mesh.num_tets(); ++t) {
    const Mat3<> F = loose.deformation_gradient(y, t);
    const Vec3<> s = signed_svd(F).sigma;
    CHECK(s.minCoeff() > 1 - 1e-5);
    CHECK(s.maxCoeff() < 1.3 + 1e-5);
    CHECK(F.determinant() == doctest::Approx(1.2).epsilon(1e-5));
  }
}

TEST_CASE("LocalGlobalSolver: seq and omp give identical iterates; one factorization per weight set and boundary") {
  test_local_global::Problem p(0.9, 1.2, 1.0, 0.5);
  Points<> xs = p.mesh.V, xo = p.mesh.V;
  LocalGlobalSolver<> a(p.mesh.num_vertices(), p.mesh.T), b(p.mesh.num_vertices(), p.mesh.T);
  const auto rs = a.solve(exec::seq, xs, p.bottom, p.strain, p.volume, p.bending, p.targets, p.gravity);
  const auto ro = b.solve(exec::omp, xo, p.bottom, p.strain, p.volume, p.bending, p.targets, p.gravity);
  CHECK(rs.iterations == ro.iterations);
  CHECK(xs == xo);
  CHECK(rs.factored);
  // the same weights again: no new factorization
  Points<> again = p.mesh.V;
  const auto r2 = a.solve(exec::seq, again, p.bottom, p.strain, p.volume, p.bending, p.targets, p.gravity);
  CHECK_FALSE(r2.factored);
  CHECK(a.factorizations() == 1);
  // new weights: invalidate() refactors; a stale factorization would still converge (slower)
  p.targets.set_weights(VecX<>::Constant(p.targets.size(), 3.0));
  a.invalidate();
  Points<> x3 = p.mesh.V;
  CHECK(a.solve(exec::seq, x3, p.bottom, p.strain, p.volume, p.bending, p.targets, p.gravity).factored);
  CHECK(a.factorizations() == 2);
  // another boundary vertex set refactors by itself
  DirichletBoundary<> fewer = p.bottom;
  fewer.vertices.conservativeResize(fewer.size() - 1);
  fewer.targets.conservativeResize(fewer.vertices.size(), 3);
  Points<> x4 = p.mesh.V;
  CHECK(a.solve(exec::seq, x4, fewer, p.strain, p.volume, p.bending, p.targets, p.gravity).factored);
  Points<> bad = p.mesh.V;
  bad(bad.rows() - 1, 1) = std::nan("");  // a free vertex (the top corner)
  CHECK_THROWS_AS(a.solve(exec::seq, bad, p.bottom, p.strain, p.volume), ShapeError);
}

TEST_CASE("LocalGlobalSolver: the reduced #V x #V factorization (isotropic global matrix) gives the 3V one's solution") {
  for (const double eps : {0.8, 1.2}) {
    test_local_global::Problem p(eps, 1.1, 1.0, 0.7);
    Points<> xr = p.mesh.V, xf = p.mesh.V;
    LocalGlobalSolver<> reduced(p.mesh.num_vertices(), p.mesh.T, LocalGlobalOptions{.relative_tolerance = 1e-11});
    LocalGlobalSolver<> full(p.mesh.num_vertices(), p.mesh.T, LocalGlobalOptions{.relative_tolerance = 1e-11, .isotropic_reduction = false});
    const auto rr = reduced.solve(exec::omp, xr, p.bottom, p.strain, p.volume, p.bending, p.targets, p.distances, p.gravity, p.dynamics);
    const auto rf = full.solve(exec::omp, xf, p.bottom, p.strain, p.volume, p.bending, p.targets, p.distances, p.gravity, p.dynamics);
    CHECK(reduced.reduced());
    CHECK_FALSE(full.reduced());
    CHECK(rr.converged);
    CHECK(rf.converged);
    CHECK((xr - xf).cwiseAbs().maxCoeff() < 1e-9);
    // one global step: L⁻¹q by three #V solves equals the 3V solve
    VecX<> q = VecX<>::Random(3 * p.mesh.num_vertices()), dr, df;
    for (const VIndex v : p.bottom.vertices) q.segment<3>(3 * Index(v)).setZero();
    reduced.apply_inverse(exec::seq, q, dr);
    full.apply_inverse(exec::seq, q, df);
    CHECK((dr - df).cwiseAbs().maxCoeff() < 1e-10 * df.cwiseAbs().maxCoeff());
    CHECK_THROWS_AS(reduced.apply_inverse(exec::seq, VecX<>::Zero(5), dr), ShapeError);
  }
}
