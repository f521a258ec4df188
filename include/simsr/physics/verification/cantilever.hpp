#pragma once
/// \file
/// The cantilever verification (issue #5): a beam clamped at x = 0 sagging under its own weight,
/// solved quasistatically on a conforming box mesh or on the BCC embedded lattice of the same
/// beam, compared with Euler–Bernoulli's tip deflection δ = q L⁴ / (8 E I), q = ρ g W H,
/// I = W H³ / 12. Small load (δ/L ≈ 1.5 % by default) and ν = 0, so linear beam theory is the
/// right reference up to shear (≈ 0.7 % at L/H = 10, Timoshenko) and discretization error.
///
///     auto r = physics::solve_cantilever(exec::seq, {.cells_through_height = 8});   // r.relative_error
///     auto p = physics::solve_cantilever<physics::ConjugateGradient<physics::Multigrid<>>>(exec::omp, options);

#include <chrono>
#include <cmath>
#include <string>

#include "../../discretize/bcc_lattice.hpp"
#include "../../discretize/embedding.hpp"
#include "../../mesh/generators.hpp"
#include "../../mesh/topology.hpp"
#include "../elastic_energy.hpp"
#include "../forces/bone_attachment.hpp"
#include "../forces/gravity.hpp"
#include "../linear_solvers/multigrid.hpp"
#include "../materials/neo_hookean.hpp"
#include "../quasistatic.hpp"

namespace simsr::physics {

/// How the beam is discretized.
enum class BeamDiscretization {
  conforming,    ///< box mesh, each cube cut into 6 tets (mesh/generators.hpp)
  embedded_bcc,  ///< BCC lattice of the beam (12 tets per cell plus face tets), tip read through the embedding
};

/// The beam, its material and its discretization (SI units).
struct CantileverOptions {
  double length = 1.0;               ///< L along x
  double width = 0.1;                ///< W along y
  double height = 0.1;               ///< H along z (gravity along −z)
  double young = 1e8;                ///< E (Pa)
  double poisson = 0.0;              ///< ν (0: no anticlastic effect, as in beam theory)
  double density = 1000;             ///< ρ (kg/m³)
  double gravity = 9.81;             ///< g (m/s²)
  Index cells_through_height = 4;    ///< resolution: cell size h = H / this; W and L must be multiples of h
  BeamDiscretization discretization = BeamDiscretization::conforming;
  NewtonOptions newton{};            ///< tolerances, progress callback
};

/// What solve_cantilever measured.
struct CantileverResult {
  double tip_deflection = 0;    ///< mean downward displacement of the tip cross-section (m)
  double euler_bernoulli = 0;   ///< q L⁴ / (8 E I) (m)
  double relative_error = 0;    ///< |tip − EB| / EB
  Index vertices = 0, tets = 0;
  Index newton_iterations = 0;
  double seconds = 0;           ///< mesh + solve wall time
  TetMesh<> mesh;               ///< the rest mesh solved on
  Points<> positions;           ///< its equilibrium positions (#V×3)
};

/// Euler–Bernoulli tip deflection of a cantilever under its own weight.
inline double euler_bernoulli_tip_deflection(const CantileverOptions& o) {
  const double q = o.density * o.gravity * o.width * o.height;
  const double I = o.width * o.height * o.height * o.height / 12;
  return q * std::pow(o.length, 4) / (8 * o.young * I);
}

/// Builds, solves (Newton from rest under `policy`; sparse Cholesky unless Linear says otherwise)
/// and measures the beam. Throws ArgumentError for a resolution that does not fit the beam.
template <class Linear = SparseCholesky<Scalar>, exec::HostPolicy P>
CantileverResult solve_cantilever(P policy, const CantileverOptions& o) {
  static_assert(assert_linear_solver<Linear>());
  if (o.cells_through_height < 1) throw ArgumentError("solve_cantilever: cells_through_height must be ≥ 1");
  const auto t0 = std::chrono::steady_clock::now();
  const double h = o.height / double(o.cells_through_height);
  const auto cells = [&](double extent, const char* what) {
    const double n = extent / h;
    if (std::abs(n - std::round(n)) > 1e-9 * n)
      throw ArgumentError(std::string("solve_cantilever: ") + what + " must be a multiple of the cell size height/cells_through_height");
    return Index(std::llround(n));
  };
  const Index nx = cells(o.length, "length"), ny = cells(o.width, "width"), nz = o.cells_through_height;
  const TetMesh<> box = box_tet_mesh<double>(nx, ny, nz, Vec3<>(0, 0, 0), Vec3<>(o.length, o.width, o.height));
  TetMesh<> mesh = box;
  if (o.discretization == BeamDiscretization::embedded_bcc) mesh = discretize::bcc_lattice(boundary_surface(box), h).mesh;

  const auto material = NeoHookean<>::from_young_poisson(o.young, o.poisson);
  ElasticEnergy<NeoHookean<>> elastic(mesh, material);
  Gravity<> gravity(mesh, o.density, Vec3<>(0, 0, -o.gravity));
  BoneAttachments<> clamp(mesh.V);
  clamp.add_bone("wall", select_vertices(mesh.V, [&](const Vec3<>& p) { return p.x() <= 1e-9 * o.length; }));
  // The tip cross-section: the conforming mesh's x = L vertices, read through the embedding.
  const IndexVector tip = select_vertices(box.V, [&](const Vec3<>& p) { return p.x() >= o.length * (1 - 1e-9); });
  Points<> tip_rest(tip.size(), 3);
  for (Index k = 0; k < tip.size(); ++k) tip_rest.row(k) = box.V.row(tip[k]);
  const auto emb = embed(policy, mesh, tip_rest);

  QuasistaticSolver<Linear> newton(mesh.num_vertices(), mesh.T, o.newton, make_linear_solver<Linear>(policy, mesh));
  Points<> x = mesh.V;
  const NewtonReport rep = newton.solve(policy, x, clamp.boundary(), elastic, gravity);
  const Points<> tip_now = deform(policy, emb, mesh.T, x);

  CantileverResult r;
  r.tip_deflection = -(tip_now.col(2) - tip_rest.col(2)).mean();
  r.euler_bernoulli = euler_bernoulli_tip_deflection(o);
  r.relative_error = std::abs(r.tip_deflection - r.euler_bernoulli) / r.euler_bernoulli;
  r.vertices = mesh.num_vertices();
  r.tets = mesh.num_tets();
  r.newton_iterations = rep.iterations;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.mesh = std::move(mesh);
  r.positions = std::move(x);
  return r;
}

}  // namespace simsr::physics
