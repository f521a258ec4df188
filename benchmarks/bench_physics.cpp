// One quasistatic frame at the paper's LR size (Park et al. 2023 §4: ~73k tets), and its kernels.
//
// Scene (built once, lazily, shared by every case): a 12-tet BCC lattice (discretize::bcc_lattice)
// of the bunny, with the cell size h found by bisection so that it has ≈ 73,000 tets (printed to
// stderr, and as counters h_mm / tets / vertices). The code voxelizes the HR surface
// data/bunny/hrestshape.obj if it is closed; the shipped one is open (an edge of triangle 4882 has
// no neighbour), so it falls back to the cells overlapping the LR tet mesh lrestshape.obj
// (bcc_lattice(TetMesh, h)): h = 6.35 mm → 73,008 tets, 14,131 vertices. The bunny is
// ~16 × 15 × 12 cm as stored: a face-sized body, so the data's units are taken as metres
// unchanged (y up).
//   flesh    TeranMuscle<> (default Mooney–Rivlin μ10 6e4, μ01 2e4, κ 1.6e6 Pa, σ_max 3e5 Pa)
//            in every tet, fibres along x; tets whose centroid lies above mid-height are the
//            active "muscle" (activation per frame), the others passive fibres (activation 0)
//   cranium  lattice vertices in the bottom 10 % of the height, held fixed (Dirichlet)
//   jaw      lattice vertices in the front-lower block x < x_min + 25 % width,
//            y in [y_min + 15 %, y_min + 45 %] height, rotated rigidly about a hinge along z
//            through (x_min + 25 % width, y_min + 45 % height, z_mid) (hinge_rotation)
//   gravity  1060 kg/m³, g = (0, −9.81, 0)
//   tracks   track springs (κ = 1e4 N/m³ × Voronoi area) on the HR surface vertices in the top
//            30 % of the height (the ears), embedded in the lattice; targets = rest positions
//            shifted along z per frame
// A frame: controls change from frame A (jaw 0.10 rad, activation 0.10, targets +0 mm) to frame B
// (jaw 0.12 rad, activation 0.15, targets +0.5 mm) — at 30 fps a jaw opening at ~34°/s — and
// Newton (NewtonOptions defaults: ‖g‖ ≤ 1e-6 × force scale, adaptive Hessian) runs to tolerance
// from frame A's converged solution (computed once at setup). Every timed iteration copies
// frame A's solution into x first (a 14k×3 copy, negligible next to a solve) and sets frame B's
// controls, so iterations repeat the same frame exactly; one untimed warm-up Newton iteration per
// case builds the gather lists and the Cholesky's symbolic analysis (done once per simulation).
//
// Cases (all wall-clock, UseRealTime; ms):
//   BM_frame_73k/<linear>/<policy>   one frame: Newton to tolerance. <linear>: cholesky
//       (Eigen SimplicialLDLT, AMD; sequential itself — /omp runs the energy, Hessian assembly
//       and gradient under exec::omp), pcg_jacobi, pcg_block_jacobi, pcg_ichol (ConjugateGradient
//       with relative tolerance kCgTolerance, products/dots under the policy; incomplete Cholesky
//       is Eigen's, sequential setup and triangular solves), pcg_multigrid (the lattice V-cycle;
//       its products and PCG's on 3×3-block copies, BlockCsr, the Galerkin levels in blocks),
//       pcg_multigrid_csr (the same on the scalar CSR: the baseline of the block products),
//       pcg_multigrid_single (the V-cycle's level matrices in single precision), cholmod
//       (CHOLMOD's supernodal LLᵀ; built with -DSIMSR_WITH_CHOLMOD=ON). Counters:
//       newton_iterations, linear_iterations (PCG iterations summed over the frame), projected
//       (Newton iterations whose exact Hessian was not positive definite: assembled twice), fps,
//       and the last frame's NewtonReport::seconds as ms_energy, ms_gradient, ms_hessian,
//       ms_setup (the linear solver's compute) and ms_solve.
//   `_doubling` rows: the multigrid's lattice hierarchy with the cell size doubling per level
//       (LatticeHierarchyOptions::coarsening = 0, as before 2026-12-07), the baseline of the
//       coarsened default; `pcg_multigrid_doubling` is the options of the day issue #17 was filed
//       (scripts/bench_frame_vs_filing.sh runs that day's code itself beside these rows)
//   BM_frame_73k/pcg_multigrid_inexact…/omp   NewtonOptions::Forcing::adaptive (Eisenstat–Walker's
//       forcing, each Newton system solved to η_k instead of kCgTolerance) with Kelley's safeguard
//       η_k ≥ ½ τ/‖g_k‖ (forcing_safeguard, default); `_unguarded` without it (the baseline);
//       `_jacobi_svd` with the element Hessians on Eigen's Jacobi SVD (JacobiSvdMuscle, the
//       baseline of signed_svd_from_eigen); `_coloured` with HessianAssembly::coloured (the library's
//       default since 2026-12-04; every other row sets the gather, its baseline); `_chebyshev2` the V-cycle
//       smoothed by MultigridOptions::Smoother::chebyshev of degree 2 (one Jacobi sweep its baseline);
//       `_gauss_seidel` the V-cycle smoothed by one multicolour block Gauss–Seidel sweep
//       (Smoother::gauss_seidel; one Jacobi sweep its baseline);
//       `_chord` with NewtonOptions::chord_below = 0.01 (an iteration whose ‖g‖ fell 100× reuses the
//       previous Hessian and multigrid; counter `chord`: such iterations), `_coloured` its baseline;
//       `…_after_a` rows solve frame A (from the frame before it, untimed) before each timed frame B,
//       as in a sequence of frames, so what the solver carries into B (the lagged coarse levels, a
//       chord_first setup) is A's; `_chord_first` with NewtonOptions::chord_first (B's first
//       iteration solves with A's last Hessian and multigrid), the `…_after_a` row without it its
//       baseline
//   BM_frame_73k/<linear>_extrapolated/omp   the same frame from the face simulator's warm start:
//       2 x_A − x_before, with x_before the frame before A (jaw 0.08 rad, activation 0.05, targets
//       −0.5 mm: the same step back), solved once at setup from x_A
//   BM_kernel_73k/energy+gradient/<policy>   E(x) and ∂E/∂x of the elastic energy
//   BM_kernel_73k/hessian/<policy>           projected element Hessians (Newton tries the exact
//       one first; same cost: both go through the signed SVD) gathered into the
//       BlockHessian + assemble() of the scalar CSR with the Dirichlet rows (what each Newton
//       iteration does before the linear solve)
//   BM_kernel_73k/hessian_coloured/<policy>   the same assembled by HessianAssembly::coloured
//       (chunks of 256 consecutive tets, coloured; each tet's blocks added straight into H, no
//       per-tet buffer) against the default gather (a per-tet buffer, then summed block by
//       block); `hessian_coloured_per_tet` the coloured one with one tet a chunk
//   BM_kernel_73k/hessian_jacobi_svd/<policy>  the same with the Mooney–Rivlin part's SVD on Eigen's
//       Jacobi sweeps (signed_svd) instead of the checked closed form (signed_svd_from_eigen)
//   BM_linear_73k/<solver>[/<policy>]        one linear solve of the first Newton system of the
//       frame (projected Hessian at frame A's solution with frame B's boundary applied, rhs = −g):
//       cholesky = numeric LDLᵀ + solve (symbolic analysis done once before), cholesky_symbolic =
//       analysis + factorization + solve, pcg_* = preconditioner setup + PCG solve; cholmod and
//       cholmod_symbolic the same with CHOLMOD (issue #17 item 2: beside the simplicial LDLᵀ).
//
// Run:   build/benchmarks/bench_physics
//        OMP_NUM_THREADS=1 build/benchmarks/bench_physics --benchmark_filter=omp
//        build/benchmarks/bench_physics --benchmark_filter='BM_frame'
// Setup (lattice search + frame A from rest, PCG) takes ~3.5 s. The whole binary takes ~5 min on 2
// cores, 2 × ~70 s of it the Cholesky frames (a ~17 s factorization per Newton iteration);
// --benchmark_filter=-cholesky leaves them out.
#include <benchmark/benchmark.h>

#include "bench_data.hpp"

#include <simsr/discretize/bcc_lattice.hpp>
#include <simsr/discretize/embedding.hpp>
#include <simsr/io/obj.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/vertex_areas.hpp>
#include <simsr/physics/dirichlet_boundary.hpp>
#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/forces/bone_attachment.hpp>
#include <simsr/physics/forces/embedded_springs.hpp>
#include <simsr/physics/forces/gravity.hpp>
#include <simsr/physics/forces/triangle_membrane.hpp>
#include <simsr/physics/hessian.hpp>
#include <simsr/physics/linear_solvers/linear_solvers.hpp>
#if defined(SIMSR_HAVE_CHOLMOD)
#include <simsr/physics/linear_solvers/cholmod_cholesky.hpp>
#endif
#include <simsr/physics/materials/teran_muscle.hpp>
#include <simsr/physics/quasistatic.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <typeinfo>
#include <filesystem>
#include <memory>
#include <random>
#include <optional>
#include <string>
#include <vector>

using namespace simsr;
using namespace simsr::physics;

namespace {

constexpr Index kTargetTets = 73000;
constexpr double kCgTolerance = 1e-4;  ///< PCG relative residual (inexact Newton; NewtonOptions stay default)
constexpr double kDensity = 1060;      ///< soft tissue, kg/m³
constexpr double kTrackStiffness = 1e4;  ///< N/m³ (× surface area → N/m)
struct Controls {
  double jaw_angle;   ///< rad
  double activation;  ///< of the muscle tets
  double target_dz;   ///< m, track targets' shift along z
};
constexpr Controls kFrameA{0.10, 0.10, 0.0};
constexpr Controls kFrameB{0.12, 0.15, 0.0005};
/// The frame before A, the same step back (for the extrapolated warm start 2 x_A − x_before).
constexpr Controls kFrameBeforeA{0.08, 0.05, -0.0005};


double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Everything shared by the cases (see the file comment).
struct Scene {
  double h = 0;
  std::string source;
  TetMesh<> mesh;
  std::optional<BoneAttachments<>> bones;
  Vec3<> hinge_point, hinge_axis{0, 0, 1};
  std::vector<char> muscle;  ///< per tet
  std::optional<Gravity<>> gravity;
  std::optional<EmbeddedSprings<>> springs;
  Points<> track_rest;  ///< rest positions of the tracked points
  // per frame
  std::vector<MuscleFibre<>> elements_a, elements_b;
  Points<> targets_a, targets_b;
  DirichletBoundary<> bc_a, bc_b;
  Points<> x_a;  ///< frame A's converged solution (the warm start of every timed frame)
  Points<> x_before_a;  ///< the frame before A's (kFrameBeforeA), for the extrapolated warm start
  Index setup_iterations = 0;

  std::vector<MuscleFibre<>> elements(const Controls& c) const {
    std::vector<MuscleFibre<>> e(std::size_t(mesh.num_tets()));
    for (std::size_t t = 0; t < e.size(); ++t) e[t] = MuscleFibre<>{Vec3<>::UnitX(), muscle[t] ? c.activation : 0.0};
    return e;
  }
  DirichletBoundary<> boundary(const Controls& c) {
    bones->set_transform("jaw", hinge_rotation(hinge_point, hinge_axis, c.jaw_angle));
    return bones->boundary();
  }
  Points<> targets(const Controls& c) const {
    Points<> y = track_rest;
    y.col(2).array() += c.target_dz;
    return y;
  }
};

/// Lattice of ≈ kTargetTets tets: geometric bisection on h (the count falls roughly as h⁻³, with
/// small jumps from the grid anchoring); the closest count seen wins.
template <class Body>
discretize::Lattice<> search_lattice(const Body& body, double& h_out) {
  double lo = 1e-3, hi = 0.05;  // h (m): far too many tets / far too few
  std::optional<discretize::Lattice<>> best;
  double best_h = 0;
  for (int it = 0; it < 24; ++it) {
    const double h = std::sqrt(lo * hi);
    discretize::Lattice<> L = discretize::bcc_lattice(body, h);
    const Index n = L.mesh.num_tets();
    if (!best || std::abs(double(n - kTargetTets)) < std::abs(double(best->mesh.num_tets() - kTargetTets))) {
      best = std::move(L);
      best_h = h;
    }
    if (std::abs(double(n - kTargetTets)) <= 0.002 * double(kTargetTets)) break;
    (n > kTargetTets ? lo : hi) = h;
  }
  h_out = best_h;
  return std::move(*best);
}

Scene build_scene() {
  const auto t0 = std::chrono::steady_clock::now();
  Scene s;
  const TriMesh<> surface = io::read_obj_triangles<double>(data_dir() / "bunny" / "hrestshape.obj");
  try {
    s.mesh = search_lattice(surface, s.h).mesh;
    s.source = "bunny/hrestshape.obj (closed HR surface)";
  } catch (const MeshError& e) {  // not closed: voxelize the LR tet mesh instead
    std::fprintf(stderr, "bench_physics: HR surface not usable (%s); using lrestshape.obj\n", e.what());
    const TetMesh<> lr = io::read_obj_tets<double>(data_dir() / "bunny" / "lrestshape.obj");
    s.mesh = search_lattice(lr, s.h).mesh;
    s.source = "bunny/lrestshape.obj (LR tet mesh)";
  }
  const TetMesh<>& m = s.mesh;
  const Vec3<> lo = m.V.colwise().minCoeff().transpose(), hi = m.V.colwise().maxCoeff().transpose(), ext = hi - lo;

  // Bones: cranium (bottom 10 %) and jaw (front-lower block), hinge at the jaw's upper back edge.
  s.bones.emplace(m.V);
  s.bones->add_bone("cranium", select_vertices(m.V, [&](const Vec3<>& p) { return p.y() < lo.y() + 0.10 * ext.y(); }));
  s.bones->add_bone("jaw", select_vertices(m.V, [&](const Vec3<>& p) {
                      return p.x() < lo.x() + 0.25 * ext.x() && p.y() >= lo.y() + 0.15 * ext.y() && p.y() <= lo.y() + 0.45 * ext.y();
                    }));
  if (s.bones->vertices("jaw").size() == 0) throw Error("bench_physics: the jaw block holds no lattice vertex");
  s.hinge_point = Vec3<>(lo.x() + 0.25 * ext.x(), lo.y() + 0.45 * ext.y(), lo.z() + 0.5 * ext.z());

  // Muscle tets: centroid above mid-height.
  s.muscle.resize(std::size_t(m.num_tets()));
  for (Index t = 0; t < m.num_tets(); ++t) {
    double y = 0;
    for (int k = 0; k < 4; ++k) y += 0.25 * m.V(m.T(t, k), 1);
    s.muscle[std::size_t(t)] = y > lo.y() + 0.5 * ext.y();
  }
  s.gravity.emplace(m, kDensity, Vec3<>(0, -9.81, 0));

  // Track springs on the HR surface vertices of the top 30 %.
  const VecX<> areas = voronoi_areas(surface.V, surface.F);
  std::vector<Index> tracked;
  const double y_top = surface.V.col(1).minCoeff() + 0.7 * (surface.V.col(1).maxCoeff() - surface.V.col(1).minCoeff());
  for (Index v = 0; v < surface.num_vertices(); ++v)
    if (surface.V(v, 1) > y_top) tracked.push_back(v);
  s.track_rest.resize(Index(tracked.size()), 3);
  VecX<> k(Index(tracked.size()));
  for (std::size_t q = 0; q < tracked.size(); ++q) {
    s.track_rest.row(Index(q)) = surface.V.row(tracked[q]);
    k[Index(q)] = kTrackStiffness * areas[tracked[q]];
  }
  s.springs.emplace(embed(exec::omp, m, s.track_rest), m.T, m.num_vertices(), k, s.track_rest);

  s.elements_a = s.elements(kFrameA);
  s.elements_b = s.elements(kFrameB);
  s.targets_a = s.targets(kFrameA);
  s.targets_b = s.targets(kFrameB);
  s.bc_a = s.boundary(kFrameA);
  s.bc_b = s.boundary(kFrameB);

  // Frame A from rest (PCG block-Jacobi, omp): the "previous frame" of every timed frame.
  const double t_mesh = seconds_since(t0);
  ElasticEnergy<TeranMuscle<>> elastic(m, TeranMuscle<>(), s.elements_a);
  s.springs->set_targets(s.targets_a);
  using Pcg = ConjugateGradient<BlockJacobi<>>;
  QuasistaticSolver<Pcg> newton(m.num_vertices(), m.T, NewtonOptions{}, Pcg({.tolerance = kCgTolerance}));
  s.x_a = m.V;
  const NewtonReport r = newton.solve(exec::omp, s.x_a, s.bc_a, elastic, *s.gravity, *s.springs);
  s.setup_iterations = r.iterations;
  {  // the frame before A, from A's solution
    ElasticEnergy<TeranMuscle<>> before(m, TeranMuscle<>(), s.elements(kFrameBeforeA));
    EmbeddedSprings<> springs = *s.springs;
    springs.set_targets(s.targets(kFrameBeforeA));
    s.x_before_a = s.x_a;
    newton.solve(exec::omp, s.x_before_a, s.boundary(kFrameBeforeA), before, *s.gravity, springs);
    s.bones->set_transform("jaw", hinge_rotation(s.hinge_point, s.hinge_axis, kFrameB.jaw_angle));  // boundary() moved it
  }
  std::fprintf(stderr,
               "bench_physics scene: %s, h = %.5f m -> %lld tets, %lld vertices (bbox %.3f x %.3f x %.3f m); cranium %lld, jaw %lld "
               "vertices; %lld muscle tets; %lld track springs; mass %.3f kg; lattice %.1f s; frame A from rest: %lld Newton "
               "iterations, %.1f s, %lld inverted tets\n",
               s.source.c_str(), s.h, (long long)m.num_tets(), (long long)m.num_vertices(), ext.x(), ext.y(), ext.z(),
               (long long)s.bones->vertices("cranium").size(), (long long)s.bones->vertices("jaw").size(),
               (long long)std::count(s.muscle.begin(), s.muscle.end(), char(1)), (long long)s.springs->num_springs(),
               s.gravity->total_mass(), t_mesh, (long long)r.iterations, seconds_since(t0) - t_mesh,
               (long long)elastic.count_inverted(exec::omp, s.x_a));
  return s;
}

const Scene& scene() {
  static const Scene s = build_scene();
  return s;
}

void scene_counters(benchmark::State& state) {
  const Scene& s = scene();
  state.counters["tets"] = double(s.mesh.num_tets());
  state.counters["vertices"] = double(s.mesh.num_vertices());
  state.counters["h_mm"] = 1e3 * s.h;
}

using Storage = MultigridOptions::Storage;
using Smoother = MultigridOptions::Smoother;

/// The case's linear solver, built for the scene's mesh (PCG + multigrid builds its lattice
/// levels here, once per mesh like the gather lists: not timed). `coarse_refresh_every`,
/// `storage`: the multigrid's MultigridOptions (ignored by the other solvers); Storage::csr also
/// runs PCG's own products on the scalar CSR (ConjugateGradientOptions::block_products = false):
/// the baseline of every 3×3-block product. `smoother`, `chebyshev_degree`: the V-cycle's smoother
/// (MultigridOptions::Smoother; the degree for the Chebyshev one). `coarsening`: the lattice
/// hierarchy's LatticeHierarchyOptions::coarsening (0: the cell size doubles per level, as before
/// 2026-12-07).
template <class Linear>
Linear make_linear(int coarse_refresh_every = 1, Storage storage = Storage::block, Smoother smoother = Smoother::jacobi, int chebyshev_degree = 2,
                   double coarsening = LatticeHierarchyOptions{}.coarsening) {
  return make_linear_solver<Linear>(
      exec::omp, scene().mesh, {.tolerance = kCgTolerance, .block_products = storage != Storage::csr}, {.coarsening = coarsening},
      {.coarse_refresh_every = coarse_refresh_every,
       .storage = storage,
       .smoother = smoother,
       .chebyshev_degree = chebyshev_degree});
}

/// The baseline of the element Hessians: M without its own element_stiffness, so ElasticEnergy
/// takes the 9×9 route (stress_derivative, then tet_elements.hpp's element_stiffness), as every
/// material did before issue #17.
template <class M>
struct NineByNine {
  using scalar_type = typename M::scalar_type;
  using Element = typename M::Element;
  M m;
  static void check(const Element& e) { M::check(e); }
  scalar_type energy(const Mat3<>& F, const Element& e) const { return m.energy(F, e); }
  Mat3<> stress(const Mat3<>& F, const Element& e) const { return m.stress(F, e); }
  Mat9<> stress_derivative(const Mat3<>& F, const Element& e, Definiteness d) const { return m.stress_derivative(F, e, d); }
};
static_assert(!physics::detail::HasElementStiffness<NineByNine<TeranMuscle<>>> && physics::detail::HasElementStiffness<TeranMuscle<>>);

/// The baseline of signed_svd_from_eigen (issue #17 item 1): TeranMuscle's element stiffness with
/// its Mooney–Rivlin part on Eigen's Jacobi SVD (signed_svd), as before.
struct JacobiSvdMuscle : TeranMuscle<> {
  Mat12<> element_stiffness(const Mat3<>& F, const Element& e, Definiteness d, const ShapeGradients<>& D, double vol) const {
    Mat12<> K = isotropic().element_stiffness(signed_svd(F), {}, d, D, vol);
    add_fibre_element_stiffness(F, e, d, D, vol, K);
    return K;
  }
};

/// The multigrid levels' sizes as counters (vertices of level 1 and of the coarsest level).
template <class Linear>
void multigrid_counters(benchmark::State& state, Linear& linear) {
  if constexpr (is_multigrid_pcg<Linear>) {
    const auto& mg = linear.preconditioner();
    state.counters["mg_levels"] = double(mg.num_levels());
    if (mg.num_levels() > 1) state.counters["mg_level1_vertices"] = double(mg.level_size(1) / 3);
    state.counters["mg_coarsest_vertices"] = double(mg.level_size(mg.num_levels() - 1) / 3);
  }
}

// ---------------------------------------------------------------------------------------------
// One frame.

/// `Extrapolate`: the frame starts from 2 x_A − x_before (the last two frames' linear extrapolation,
/// as the face simulator's warm start), not from x_A.
template <class Linear, class Policy, class Material = TeranMuscle<>, int CoarseRefreshEvery = 1,
          NewtonOptions::Forcing Forcing = NewtonOptions::Forcing::fixed, Storage MultigridStorage = Storage::block, bool Extrapolate = false,
          bool ForcingSafeguard = true, HessianAssembly Assembly = HessianAssembly::gather, Smoother FrameSmoother = Smoother::jacobi, int ChebyshevDegree = 2, int ChordDrop = 0,
          bool SolveAFirst = false, bool ChordFirst = false, int Coarsening = 8>
void BM_frame(benchmark::State& state) {
  const Scene& s = scene();
  ElasticEnergy<Material> elastic(s.mesh, Material(), s.elements_a);
  elastic.set_hessian_assembly(Assembly);
  EmbeddedSprings<> springs = *s.springs;
  NewtonOptions options;
  options.forcing = Forcing;
  options.forcing_safeguard = ForcingSafeguard;
  options.chord_below = ChordDrop > 0 ? 1.0 / ChordDrop : 0.0;  // a chord step after a ChordDrop-fold drop of ‖g‖
  options.chord_first = ChordFirst;
  QuasistaticSolver<Linear> newton(s.mesh.num_vertices(), s.mesh.T, options, make_linear<Linear>(CoarseRefreshEvery, MultigridStorage, FrameSmoother, ChebyshevDegree, Coarsening));
  Points<> x(s.mesh.num_vertices(), 3);
  NewtonReport report;
  // x solved under one frame's activations, track targets and jaw (its Dirichlet boundary)
  const auto solve = [&](const std::vector<MuscleFibre<>>& elements, const Points<>& targets, const DirichletBoundary<>& bc) {
    elastic.set_elements(elements);
    springs.set_targets(targets);
    return newton.solve(Policy{}, x, bc, elastic, *s.gravity, springs);
  };
  // SolveAFirst: frame A solved (untimed) from the frame before it, just before each frame B, as
  // in a sequence of frames: what the solver carries into B (a chord_first setup, lagged coarse
  // levels) is then A's, not the last timed B's
  const auto frame_a = [&] {
    x = s.x_before_a;
    solve(s.elements_a, s.targets_a, s.bc_a);
  };
  const auto frame = [&] {
    if constexpr (Extrapolate)
      x = 2 * s.x_a - s.x_before_a;    // the last two frames extrapolated
    else
      x = s.x_a;                       // previous frame's converged solution
    report = solve(s.elements_b, s.targets_b, s.bc_b);
  };
  // Warm-up: one Newton iteration of the frame (gather lists, the Cholesky's symbolic analysis,
  // buffers), cut short by max_iterations = 1 (which reports as a ConvergenceError).
  newton.options().max_iterations = 1;
  try {
    frame();
  } catch (const ConvergenceError&) {
  }
  newton.options().max_iterations = NewtonOptions{}.max_iterations;
  for (auto _ : state) {
    if constexpr (SolveAFirst) {
      state.PauseTiming();
      frame_a();
      state.ResumeTiming();
    }
    frame();
    benchmark::DoNotOptimize(x.data());
    benchmark::ClobberMemory();
  }
  scene_counters(state);
  state.counters["newton_iterations"] = double(report.iterations);
  state.counters["linear_iterations"] = double(report.linear_iterations);
  state.counters["projected"] = double(std::count_if(report.history.begin(), report.history.end(), [](const NewtonIteration& it) { return it.projected; }));
  state.counters["chord"] = double(std::count_if(report.history.begin(), report.history.end(), [](const NewtonIteration& it) { return it.chord; }));
  state.counters["fps"] = benchmark::Counter(1, benchmark::Counter::kIsIterationInvariantRate);
  multigrid_counters(state, newton.linear_solver());
  // the last frame's time breakdown (NewtonReport::seconds), ms
  state.counters["ms_energy"] = 1e3 * report.seconds.energy;
  state.counters["ms_gradient"] = 1e3 * report.seconds.gradient;
  state.counters["ms_hessian"] = 1e3 * report.seconds.hessian;
  state.counters["ms_setup"] = 1e3 * report.seconds.linear_setup;
  state.counters["ms_solve"] = 1e3 * report.seconds.linear_solve;
  if (std::getenv("SIMSR_BENCH_NEWTON_HISTORY"))  // the last frame's Newton iterations, on stderr
    for (const NewtonIteration& it : report.history)
      std::fprintf(stderr, "BM_frame (%s, coarse levels every %d, forcing %s): iteration %lld |g| %.3e step %.3g backtracks %lld PCG %lld eta %.3g%s\n",
                   typeid(Linear).name(), CoarseRefreshEvery, Forcing == NewtonOptions::Forcing::adaptive ? "adaptive" : "fixed", (long long)it.iteration,
                   it.gradient_norm, it.step_length, (long long)it.backtracks, (long long)it.linear_iterations, it.linear_tolerance, it.chord ? " chord" : "");
}

using Cholesky = SparseCholesky<>;
using PcgJacobi = ConjugateGradient<Jacobi<>>;
using PcgBlockJacobi = ConjugateGradient<BlockJacobi<>>;
using PcgIncompleteCholesky = ConjugateGradient<IncompleteCholesky<>>;
using PcgMultigrid = ConjugateGradient<Multigrid<>>;

BENCHMARK_TEMPLATE(BM_frame, Cholesky, exec::seq_t)->Name("BM_frame_73k/cholesky/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_TEMPLATE(BM_frame, Cholesky, exec::omp_t)->Name("BM_frame_73k/cholesky/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_TEMPLATE(BM_frame, PcgJacobi, exec::seq_t)->Name("BM_frame_73k/pcg_jacobi/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgJacobi, exec::omp_t)->Name("BM_frame_73k/pcg_jacobi/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgBlockJacobi, exec::seq_t)->Name("BM_frame_73k/pcg_block_jacobi/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgBlockJacobi, exec::omp_t)->Name("BM_frame_73k/pcg_block_jacobi/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgIncompleteCholesky, exec::seq_t)->Name("BM_frame_73k/pcg_ichol/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgIncompleteCholesky, exec::omp_t)->Name("BM_frame_73k/pcg_ichol/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::seq_t)->Name("BM_frame_73k/pcg_multigrid/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t)->Name("BM_frame_73k/pcg_multigrid/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
// the configuration of the day issue #17 was filed (587 ms then): the default solver with the
// lattice hierarchy as it was, the cell size doubling per level (coarsening 0)
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 1, NewtonOptions::Forcing::fixed, Storage::block, false, true, HessianAssembly::gather, Smoother::jacobi, 2, 0, false, false, 0)->Name("BM_frame_73k/pcg_multigrid_doubling/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
// issue #17's baseline beside it: element Hessians through the 9×9 ∂P/∂F, coarse levels rebuilt every Newton iteration
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, NineByNine<TeranMuscle<>>, 1)->Name("BM_frame_73k/pcg_multigrid_9x9/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 2)->Name("BM_frame_73k/pcg_multigrid_coarse_every_2/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4)->Name("BM_frame_73k/pcg_multigrid_coarse_every_4/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 1, NewtonOptions::Forcing::adaptive)->Name("BM_frame_73k/pcg_multigrid_inexact/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 2, NewtonOptions::Forcing::adaptive)->Name("BM_frame_73k/pcg_multigrid_inexact_coarse_every_2/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
// the 3×3-block products' baseline (scalar CSR everywhere) and single-precision multigrid levels
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 1, NewtonOptions::Forcing::fixed, Storage::csr)->Name("BM_frame_73k/pcg_multigrid_csr/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 1, NewtonOptions::Forcing::fixed, Storage::block_single)->Name("BM_frame_73k/pcg_multigrid_single/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::fixed, Storage::block_single)->Name("BM_frame_73k/pcg_multigrid_single_coarse_every_4/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
// the warm start of the face simulator: the last two frames extrapolated
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 1, NewtonOptions::Forcing::fixed, Storage::block, true)->Name("BM_frame_73k/pcg_multigrid_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::fixed, Storage::block_single, true)->Name("BM_frame_73k/pcg_multigrid_single_coarse_every_4_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
// the inexact Newton from the extrapolated warm start: Eisenstat–Walker's forcing with Kelley's
// safeguard (NewtonOptions::forcing_safeguard, the default), and without it (`…_unguarded…`)
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 1, NewtonOptions::Forcing::adaptive, Storage::block, true)->Name("BM_frame_73k/pcg_multigrid_inexact_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true)->Name("BM_frame_73k/pcg_multigrid_inexact_single_coarse_every_4_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, false)->Name("BM_frame_73k/pcg_multigrid_inexact_unguarded_single_coarse_every_4_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
// the same with the element Hessians' SVD on Eigen's Jacobi sweeps (the baseline of signed_svd_from_eigen)
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_single_coarse_every_4_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured, Smoother::chebyshev, 2)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_chebyshev2_single_coarse_every_4_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured, Smoother::jacobi, 2, 100)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_chord_single_coarse_every_4_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
// in a sequence (frame A solved untimed before each timed B: what the solver carries into B is
// A's), with and without NewtonOptions::chord_first, with one Jacobi sweep or Chebyshev degree 2
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured, Smoother::jacobi, 2, 0, true)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_single_coarse_every_4_extrapolated_after_a/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured, Smoother::jacobi, 2, 0, true, true)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_chord_first_single_coarse_every_4_extrapolated_after_a/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured, Smoother::jacobi, 2, 100, true, true)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_chord_first_chord_single_coarse_every_4_extrapolated_after_a/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured, Smoother::chebyshev, 2, 0, true)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_chebyshev2_single_coarse_every_4_extrapolated_after_a/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured, Smoother::chebyshev, 2, 0, true, true)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_chebyshev2_chord_first_single_coarse_every_4_extrapolated_after_a/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured, Smoother::chebyshev, 2, 0, true, true, 0)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_chebyshev2_chord_first_single_coarse_every_4_extrapolated_after_a_doubling/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, TeranMuscle<>, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true, true, HessianAssembly::coloured, Smoother::gauss_seidel)->Name("BM_frame_73k/pcg_multigrid_inexact_coloured_gauss_seidel_single_coarse_every_4_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_frame, PcgMultigrid, exec::omp_t, JacobiSvdMuscle, 4, NewtonOptions::Forcing::adaptive, Storage::block_single, true)->Name("BM_frame_73k/pcg_multigrid_inexact_jacobi_svd_single_coarse_every_4_extrapolated/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
#if defined(SIMSR_HAVE_CHOLMOD)
BENCHMARK_TEMPLATE(BM_frame, CholmodCholesky<>, exec::omp_t)->Name("BM_frame_73k/cholmod/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
#endif

// ---------------------------------------------------------------------------------------------
// Kernels, at frame A's solution with frame B's controls (the start of a timed frame).

/// x = frame A's solution with frame B's Dirichlet targets applied; the fixed-DOF mask.
Points<> frame_start(std::vector<char>& fixed) {
  const Scene& s = scene();
  Points<> x = s.x_a;
  fixed.assign(std::size_t(3 * s.mesh.num_vertices()), 0);
  for (Index k = 0; k < s.bc_b.size(); ++k) {
    x.row(s.bc_b.vertices[k]) = s.bc_b.targets.row(k);
    for (int c = 0; c < 3; ++c) fixed[std::size_t(3 * s.bc_b.vertices[k] + c)] = 1;
  }
  return x;
}

template <class Policy>
void BM_energy_gradient(benchmark::State& state) {
  const Scene& s = scene();
  ElasticEnergy<TeranMuscle<>> elastic(s.mesh, TeranMuscle<>(), s.elements_b);
  std::vector<char> fixed;
  const Points<> x = frame_start(fixed);
  Points<> g(s.mesh.num_vertices(), 3);
  double e = 0;
  for (int warm = 0; warm < 2; ++warm) {
    e = elastic.energy(Policy{}, x);
    g.setZero();
    elastic.add_gradient(Policy{}, x, g);
  }
  for (auto _ : state) {
    e = elastic.energy(Policy{}, x);
    g.setZero();
    elastic.add_gradient(Policy{}, x, g);
    benchmark::DoNotOptimize(e);
    benchmark::DoNotOptimize(g.data());
    benchmark::ClobberMemory();
  }
  scene_counters(state);
  state.counters["tets/s"] = benchmark::Counter(double(s.mesh.num_tets()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK_TEMPLATE(BM_energy_gradient, exec::seq_t)->Name("BM_kernel_73k/energy+gradient/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_energy_gradient, exec::omp_t)->Name("BM_kernel_73k/energy+gradient/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

template <class Policy, class Material = TeranMuscle<>, HessianAssembly Assembly = HessianAssembly::gather,
          int TetsPerChunk = ElasticEnergy<Material>::kDefaultTetsPerChunk>
void BM_hessian(benchmark::State& state) {
  const Scene& s = scene();
  ElasticEnergy<Material> elastic(s.mesh, Material(), s.elements_b);
  elastic.set_hessian_assembly(Assembly, TetsPerChunk);
  std::vector<char> fixed;
  const Points<> x = frame_start(fixed);
  BlockHessian<> H(s.mesh.num_vertices(), s.mesh.T);
  const auto assemble = [&]() -> const SparseMatrix<>& {
    H.set_zero();
    elastic.add_hessian(Policy{}, x, H, Definiteness::project);
    return H.assemble(Policy{}, fixed);
  };
  assemble();  // warm-up: gather lists
  for (auto _ : state) {
    const SparseMatrix<>& A = assemble();
    benchmark::DoNotOptimize(A.valuePtr());
    benchmark::ClobberMemory();
  }
  scene_counters(state);
  state.counters["blocks"] = double(H.num_blocks());
  state.counters["tets/chunk"] = double(Assembly == HessianAssembly::coloured ? TetsPerChunk : 0);
  state.counters["tets/s"] = benchmark::Counter(double(s.mesh.num_tets()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK_TEMPLATE(BM_hessian, exec::seq_t)->Name("BM_kernel_73k/hessian/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_hessian, exec::omp_t)->Name("BM_kernel_73k/hessian/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_hessian, exec::seq_t, TeranMuscle<>, HessianAssembly::coloured)->Name("BM_kernel_73k/hessian_coloured/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_hessian, exec::omp_t, TeranMuscle<>, HessianAssembly::coloured)->Name("BM_kernel_73k/hessian_coloured/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_hessian, exec::seq_t, TeranMuscle<>, HessianAssembly::coloured, 1)->Name("BM_kernel_73k/hessian_coloured_per_tet/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_hessian, exec::omp_t, TeranMuscle<>, HessianAssembly::coloured, 1)->Name("BM_kernel_73k/hessian_coloured_per_tet/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_hessian, exec::seq_t, JacobiSvdMuscle)->Name("BM_kernel_73k/hessian_jacobi_svd/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_hessian, exec::omp_t, JacobiSvdMuscle)->Name("BM_kernel_73k/hessian_jacobi_svd/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_hessian, exec::seq_t, NineByNine<TeranMuscle<>>)->Name("BM_kernel_73k/hessian_9x9/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_hessian, exec::omp_t, NineByNine<TeranMuscle<>>)->Name("BM_kernel_73k/hessian_9x9/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

/// The first Newton system of the frame: A (projected Hessian of all terms, Dirichlet rows
/// eliminated) and b = −g over the free DOFs. Built once (omp).
struct NewtonSystem {
  BlockHessian<> H;
  SparseMatrix<> A;
  VecX<> b;
};
const NewtonSystem& newton_system() {
  static const NewtonSystem sys = [] {
    const Scene& s = scene();
    NewtonSystem out;
    std::vector<char> fixed;
    const Points<> x = frame_start(fixed);
    ElasticEnergy<TeranMuscle<>> elastic(s.mesh, TeranMuscle<>(), s.elements_b);
    EmbeddedSprings<> springs = *s.springs;
    springs.set_targets(s.targets_b);
    out.H = BlockHessian<>(s.mesh.num_vertices(), s.mesh.T);
    out.H.set_zero();
    elastic.add_hessian(exec::omp, x, out.H, Definiteness::project);
    springs.add_hessian(exec::omp, x, out.H, Definiteness::project);
    out.A = out.H.assemble(exec::omp, fixed);
    Points<> g = Points<>::Zero(s.mesh.num_vertices(), 3);
    elastic.add_gradient(exec::omp, x, g);
    s.gravity->add_gradient(exec::omp, x, g);
    springs.add_gradient(exec::omp, x, g);
    out.b = -Eigen::Map<const VecX<>>(g.data(), g.size());
    for (std::size_t d = 0; d < fixed.size(); ++d)
      if (fixed[d]) out.b[Index(d)] = 0;
    return out;
  }();
  return sys;
}

template <class Linear, class Policy, bool Symbolic, Storage MultigridStorage = Storage::block>
void BM_linear(benchmark::State& state) {
  const NewtonSystem& sys = newton_system();
  Linear linear = make_linear<Linear>(1, MultigridStorage);
  VecX<> d(sys.b.size());
  LinearSolveInfo info;
  std::uint64_t version = 1;
  if (!Symbolic) {  // warm-up (and the symbolic analysis of the numeric-only case)
    linear.compute(Policy{}, sys.A, version);
    info = linear.solve(Policy{}, sys.b, d);
  }
  for (auto _ : state) {
    if (Symbolic) ++version;  // a new pattern version: SparseCholesky redoes analyzePattern
    linear.compute(Policy{}, sys.A, version);
    info = linear.solve(Policy{}, sys.b, d);
    benchmark::DoNotOptimize(d.data());
    benchmark::ClobberMemory();
  }
  scene_counters(state);
  state.counters["dofs"] = double(sys.A.rows());
  state.counters["nnz"] = double(sys.A.nonZeros());
  state.counters["linear_iterations"] = double(info.iterations);
  state.counters["rel_residual"] = info.relative_residual;
  multigrid_counters(state, linear);
}
BENCHMARK_TEMPLATE(BM_linear, Cholesky, exec::seq_t, false)->Name("BM_linear_73k/cholesky")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_TEMPLATE(BM_linear, Cholesky, exec::seq_t, true)->Name("BM_linear_73k/cholesky_symbolic")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_TEMPLATE(BM_linear, PcgJacobi, exec::seq_t, false)->Name("BM_linear_73k/pcg_jacobi/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, PcgJacobi, exec::omp_t, false)->Name("BM_linear_73k/pcg_jacobi/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, PcgBlockJacobi, exec::seq_t, false)->Name("BM_linear_73k/pcg_block_jacobi/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, PcgBlockJacobi, exec::omp_t, false)->Name("BM_linear_73k/pcg_block_jacobi/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, PcgIncompleteCholesky, exec::seq_t, false)->Name("BM_linear_73k/pcg_ichol/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, PcgMultigrid, exec::seq_t, false)->Name("BM_linear_73k/pcg_multigrid/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, PcgMultigrid, exec::omp_t, false)->Name("BM_linear_73k/pcg_multigrid/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, PcgMultigrid, exec::omp_t, false, Storage::csr)->Name("BM_linear_73k/pcg_multigrid_csr/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, PcgMultigrid, exec::omp_t, false, Storage::block_single)->Name("BM_linear_73k/pcg_multigrid_single/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
#if defined(SIMSR_HAVE_CHOLMOD)
// CHOLMOD's supernodal LLᵀ beside Eigen's simplicial LDLᵀ (issue #17 item 2), numeric only and
// with the analysis; /omp: CHOLMOD's own OpenMP loops and the BLAS (OpenBLAS: its threads).
BENCHMARK_TEMPLATE(BM_linear, CholmodCholesky<>, exec::seq_t, false)->Name("BM_linear_73k/cholmod/seq")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, CholmodCholesky<>, exec::omp_t, false)->Name("BM_linear_73k/cholmod/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_TEMPLATE(BM_linear, CholmodCholesky<>, exec::omp_t, true)->Name("BM_linear_73k/cholmod_symbolic/omp")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
#endif

// Newton's fallback where the exact Hessian is indefinite (NewtonOptions::Hessian): a 1,089-
// vertex cloth membrane (k = 50 N/m) crumpled inside its pinned rim (every vertex pulled 15-35 %
// towards the centre, up to 3 cm out of plane; the same start every iteration) solved back to
// its flat rest to ‖g‖ ≤ 1e-10 × force scale. The compression makes the exact Hessian indefinite,
// as in DISK's hanging tablecloth (README, "Thin shells"); counters: Newton iterations, how many
// used the projected Hessian and how many the shifted one. One run (OMP_NUM_THREADS=1, idle
// machine): adaptive 41 iterations (8 projected) in 0.60 s, regularized 119 (87 shifted) in
// 3.2 s: far from the solution without inertia, the shifted steps are too short.
template <NewtonOptions::Hessian mode>
void BM_newton_crumpled(benchmark::State& state) {
  const TriMesh<> sheet = square_sheet(1.0, 32);
  const Index n = sheet.V.rows();
  const TriangleMembrane<> stretch(n, sheet.V, sheet.F, 50.0);
  DirichletBoundary<> rim{boundary_vertices(sheet.F), Points<>()};
  rim.targets = sheet.V(rim.vertices, Eigen::all);
  Points<> start = sheet.V;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (Index i = 0; i < n; ++i) {
    const double s = 0.75 + 0.1 * u(rng);
    start.row(i).head<2>() = Eigen::RowVector2d(0.5, 0.5) + s * (sheet.V.row(i).head<2>() - Eigen::RowVector2d(0.5, 0.5));
    start(i, 2) = 0.03 * u(rng);
  }
  Index projected = 0, shifted = 0;
  NewtonOptions o{.relative_tolerance = 1e-10, .max_iterations = 1000, .hessian = mode, .progress = {}};
  o.progress = [&](const NewtonIteration& it) {
    projected += it.projected;
    shifted += it.shift > 0;
  };
  QuasistaticSolver<> newton(n, Tets(0, 4), o);
  Points<> x = start;
  newton.solve(exec::seq, x, rim, stretch);  // warm-up: the pattern and the symbolic analysis
  Index iterations = 0;
  projected = shifted = 0;
  for (auto _ : state) {
    x = start;
    iterations = newton.solve(exec::seq, x, rim, stretch).iterations;
  }
  state.counters["newton_iterations"] = double(iterations);
  state.counters["projected"] = double(projected) / double(state.iterations());
  state.counters["shifted"] = double(shifted) / double(state.iterations());
}
BENCHMARK_TEMPLATE(BM_newton_crumpled, NewtonOptions::Hessian::adaptive)->Name("BM_newton_crumpled_1089/adaptive")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_newton_crumpled, NewtonOptions::Hessian::regularized)->Name("BM_newton_crumpled_1089/regularized")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
