#include <simsr/discretize/bcc_lattice.hpp>
#include <simsr/discretize/embedding.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/forces/bone_attachment.hpp>
#include <simsr/physics/forces/gravity.hpp>
#include <simsr/physics/linear_solvers/linear_solvers.hpp>
#include <simsr/physics/materials/neo_hookean.hpp>
#include <simsr/physics/quasistatic.hpp>

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <limits>
#include <random>

#include "stiffness_system.hpp"

using namespace simsr;
using namespace simsr::physics;

using simsr_test::stiffness_system;

namespace {
/// The checks every hierarchy must pass, level by level: P is (3·fine)×(3·coarse), each level at
/// most 60 % of the one before, every row of P sums to 1, every coarse vertex is used, and an affine
/// displacement u(x) = G x + t on the coarse level interpolates to the same on the fine one.
void check_prolongations(const LatticeHierarchy<double>& levels) {
  REQUIRE(levels.prolongations.size() + 1 == levels.vertices.size());
  const Eigen::Matrix3d G{{0.3, -1.2, 0.5}, {2.0, 0.1, -0.7}, {-0.4, 0.9, 1.1}};
  const Eigen::RowVector3d t(0.25, -3.0, 1.5);
  const auto affine = [&](const Points<double>& X) {
    VecX<> u(3 * X.rows());
    for (Index v = 0; v < X.rows(); ++v) u.segment<3>(3 * v) = (X.row(v) * G.transpose() + t).transpose();
    return u;
  };
  for (std::size_t l = 0; l < levels.prolongations.size(); ++l) {
    CAPTURE(l);
    const auto& P = levels.prolongations[l];
    const auto& fine = levels.vertices[l];
    const auto& coarse = levels.vertices[l + 1];
    CHECK(coarse.rows() <= 0.6 * double(fine.rows()));
    REQUIRE(P.rows() == 3 * fine.rows());
    REQUIRE(P.cols() == 3 * coarse.rows());
    const VecX<> row_sums = P * VecX<>::Ones(P.cols());
    CHECK((row_sums.array() - 1).abs().maxCoeff() < 1e-12);
    const VecX<> col_sums = P.transpose() * VecX<>::Ones(P.rows());
    CHECK(col_sums.minCoeff() > 0);
    CHECK((P * affine(coarse) - affine(fine)).cwiseAbs().maxCoeff() < 1e-11);
  }
}
}  // namespace

TEST_CASE("lattice_hierarchy: levels shrink, weights sum to 1 and reproduce affine fields exactly") {
  for (const bool lattice_mesh : {false, true}) {
    const auto box = box_tet_mesh<double>(16, 8, 8, Vec3<>(0, 0, 0), Vec3<>(2, 1, 1));
    const TetMesh<double> mesh = lattice_mesh ? discretize::bcc_lattice(box, 0.0625).mesh : box;
    const auto levels = lattice_hierarchy(exec::seq, mesh, {.max_coarse_vertices = 60});
    CAPTURE(lattice_mesh);
    REQUIRE(levels.num_levels() >= 3);
    CHECK(levels.vertices.back().rows() <= 60);
    check_prolongations(levels);
  }
  CHECK_THROWS_AS(lattice_hierarchy(exec::seq, TetMesh<double>{}), ArgumentError);
  CHECK_THROWS_AS(lattice_hierarchy(exec::seq, box_tet_mesh<double>(2, 2, 2), {.h = -1}), ArgumentError);
  for (double bad : {-1.0, 0.5, 1.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()})
    CHECK_THROWS_AS(lattice_hierarchy(exec::seq, box_tet_mesh<double>(2, 2, 2), {.coarsening = bad}), ArgumentError);
  CHECK_THROWS_AS(lattice_hierarchy(exec::seq, box_tet_mesh<double>(2, 2, 2), {.coarsening_tries = -1}), ArgumentError);
}

TEST_CASE("lattice_hierarchy: coarsening keeps each level at most 1/coarsening of the one before where the tries allow; 0 doubles the cell size, as bcc_lattice at h, 2h, 4h") {
  // a lattice body whose coarse lattices keep many boundary cells (a thin, curved slab): doubling
  // the cell size alone keeps far more than 1/8 of the vertices
  const auto box = box_tet_mesh<double>(24, 12, 3, Vec3<>(0, 0, 0), Vec3<>(2, 1, 0.25));
  const TetMesh<double> mesh = discretize::bcc_lattice(box, 0.05).mesh;
  const double h0 = 0.1;
  // coarsening 0: level 1 is exactly the used vertices of bcc_lattice(mesh, h0), and level l ≥ 1
  // lies on the BCC lattice of cell size h0·2^(l−1) anchored at 0 (corners h·ℤ³, centres h·(ℤ+½)³)
  const auto doubling = lattice_hierarchy(exec::seq, mesh, {.h = h0, .max_coarse_vertices = 50, .coarsening = 0});
  REQUIRE(doubling.num_levels() >= 3);
  {
    const TetMesh<double> lattice = discretize::bcc_lattice(mesh, h0).mesh;
    const Embedding<double> emb = embed(exec::seq, lattice, mesh.V);
    std::vector<char> used(std::size_t(lattice.num_vertices()), 0);
    for (Index q = 0; q < emb.size(); ++q)
      for (int k = 0; k < 4; ++k)
        if (emb.weights(q, k) != 0) used[std::size_t(lattice.T(emb.tet[q], k))] = 1;
    CHECK(doubling.vertices[1].rows() == Index(std::count(used.begin(), used.end(), char(1))));
  }
  double h = h0;
  for (std::size_t l = 1; l < doubling.vertices.size(); ++l, h *= 2) {
    CAPTURE(l);
    const Points<double>& V = doubling.vertices[l];
    Index off_lattice = 0;
    for (Index v = 0; v < V.rows(); ++v) {
      const Vec3<> c = V.row(v).transpose() / (0.5 * h);  // doubled lattice coordinates: all even or all odd
      const Vec3<> r = c.array().round();
      const bool whole = (c - r).cwiseAbs().maxCoeff() < 1e-6;
      const long p0 = std::lround(r.x()) & 1;
      off_lattice += !(whole && (std::lround(r.y()) & 1) == p0 && (std::lround(r.z()) & 1) == p0);
    }
    CHECK(off_lattice == 0);
  }
  // the first doubled level keeps more than 1/8 here (what the option is for)
  REQUIRE(8 * doubling.vertices[1].rows() > doubling.vertices[0].rows());
  for (const double target : {4.0, 8.0, 12.0}) {
    CAPTURE(target);
    const auto levels = lattice_hierarchy(exec::seq, mesh, {.h = h0, .max_coarse_vertices = 50, .coarsening = target, .coarsening_tries = 12});
    REQUIRE(levels.num_levels() >= 3);
    if (target * double(doubling.vertices[1].rows()) > double(doubling.vertices[0].rows())) CHECK(levels.vertices[1].rows() < doubling.vertices[1].rows());
    // every level but the coarsest meets the target (the coarsest may stop early: a cell size
    // past the level's extent keeps no cell, and the last lattice that did stands)
    for (std::size_t l = 0; l + 2 < levels.vertices.size(); ++l) {
      CAPTURE(l);
      CHECK(target * double(levels.vertices[l + 1].rows()) <= double(levels.vertices[l].rows()));
    }
    check_prolongations(levels);  // and every level is a hierarchy's, as the first case's
  }
  // no tries: the cell size doubles, whatever the target
  const auto untried = lattice_hierarchy(exec::seq, mesh, {.h = h0, .max_coarse_vertices = 50, .coarsening = 8, .coarsening_tries = 0});
  REQUIRE(untried.num_levels() == doubling.num_levels());
  for (std::size_t l = 0; l < untried.vertices.size(); ++l) CHECK(untried.vertices[l] == doubling.vertices[l]);
}

/// Checks that `mg` (computed) is symmetric and positive on `trials` pairs of random vectors: PCG's
/// requirement of a preconditioner.
template <class Rng>
void check_symmetric_positive(Multigrid<>& mg, Index n, Rng& rng, int trials) {
  std::normal_distribution<double> N;
  for (int trial = 0; trial < trials; ++trial) {
    VecX<> a(n), b(n), Ma, Mb;
    for (Index i = 0; i < n; ++i) a[i] = N(rng), b[i] = N(rng);
    mg.apply(exec::seq, a, Ma);
    mg.apply(exec::seq, b, Mb);
    CHECK(std::abs(a.dot(Mb) - b.dot(Ma)) <= 1e-10 * a.norm() * Mb.norm());
    CHECK(a.dot(Ma) > 0);
    CHECK(b.dot(Mb) > 0);
  }
}

/// A smoother's checks on the system A x = b whose solution is `ref`: the V-cycle with `options`
/// symmetric positive, seq == omp bitwise, and PCG to 1e-10 reaching ref. Returns PCG's iterations.
template <class Rng>
Index check_smoother(const std::vector<SparseMatrix<>>& levels, const MultigridOptions& options, const SparseMatrix<>& A, const VecX<>& b,
                     const VecX<>& ref, Rng& rng) {
  const Index n = A.rows();
  std::normal_distribution<double> N;
  Multigrid<> mg(levels, options), mg_omp(levels, options);
  mg.compute(exec::seq, A);
  mg_omp.compute(exec::omp, A);
  check_symmetric_positive(mg, n, rng, 8);
  VecX<> a(n), Ma, Ma_omp;
  for (Index i = 0; i < n; ++i) a[i] = N(rng);
  mg.apply(exec::seq, a, Ma);
  mg_omp.apply(exec::omp, a, Ma_omp);
  CHECK(Ma == Ma_omp);
  ConjugateGradient<Multigrid<>> pcg({.tolerance = 1e-10}, Multigrid<>(levels, options));
  pcg.compute(exec::omp, A);
  VecX<> x;
  const auto report = pcg.solve(exec::omp, b, x);
  CHECK(report.converged);
  CHECK((x - ref).norm() <= 1e-8 * ref.norm());
  return report.iterations;
}

TEST_CASE("Multigrid: the V-cycle is a symmetric positive definite operator (PCG's requirement); seq == omp bitwise") {
  auto s = stiffness_system(16, 4, 3);
  const SparseMatrix<>& A = s.A();
  // the cell size doubling per level (coarsening 0) keeps this small beam at 3+ levels: the V-cycle
  // is checked through more than one coarse level (the default coarsening would stop at two)
  Multigrid<> mg(lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 40, .coarsening = 0}).prolongations);
  mg.compute(exec::seq, A);
  REQUIRE(mg.num_levels() >= 3);
  for (Index l = 0; l + 1 < mg.num_levels(); ++l) {
    CHECK(mg.damping(l) > 0.1);
    CHECK(mg.damping(l) < 4.0 / 3.0);
  }
  std::mt19937 rng(11);
  const Index n = A.rows();
  check_symmetric_positive(mg, n, rng, 20);
  const auto levels_omp = lattice_hierarchy(exec::omp, s.mesh, {.max_coarse_vertices = 40, .coarsening = 0});
  Multigrid<> mg_omp(levels_omp.prolongations);
  mg_omp.compute(exec::omp, A);
  VecX<> z_seq, z_omp;
  mg.apply(exec::seq, s.b, z_seq);
  mg_omp.apply(exec::omp, s.b, z_omp);
  CHECK(z_seq == z_omp);
  // the preconditioner leaves fixed DOFs where their residual is (zero)
  for (Index i = 0; i < n; ++i)
    if (s.fixed[std::size_t(i)]) CHECK(z_seq[i] == 0.0);
}

TEST_CASE("Multigrid: a second compute starts its eigenvalue estimate warm; forget_estimates makes it a fresh one's, bitwise") {
  auto s = stiffness_system(12, 4, 3);
  const SparseMatrix<>& A = s.A();
  const auto prolongations = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 40}).prolongations;
  SparseMatrix<> B = A;  // another matrix of the same pattern (the next Newton iteration's)
  B *= 1.5;
  Multigrid<> used(prolongations), fresh(prolongations);
  used.compute(exec::omp, A);
  used.compute(exec::omp, B);  // warm: 2 power iterations from A's vector
  fresh.compute(exec::omp, B);  // cold: 12 from the fixed start
  REQUIRE(used.num_levels() >= 2);
  bool differs = false;
  for (Index l = 0; l + 1 < used.num_levels(); ++l) differs = differs || used.damping(l) != fresh.damping(l);
  CHECK(differs);  // the history shows (else this test could not fail)
  used.forget_estimates();
  used.compute(exec::omp, B);
  for (Index l = 0; l + 1 < used.num_levels(); ++l) CHECK(used.damping(l) == fresh.damping(l));
  VecX<> zu, zf;
  used.apply(exec::omp, s.b, zu);
  fresh.apply(exec::omp, s.b, zf);
  CHECK(zu == zf);
}

/// λ_max(B⁻¹A), B the 3×3 diagonal blocks of A, by a dense generalized eigensolve (the
/// brute-force reference of the multigrid's estimates).
double dense_block_jacobi_lambda_max(const SparseMatrix<>& A) {
  const Eigen::MatrixXd D = Eigen::MatrixXd(A);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(D.rows(), D.cols());
  for (Index v = 0; v < D.rows() / 3; ++v) B.block<3, 3>(3 * v, 3 * v) = D.block<3, 3>(3 * v, 3 * v);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(D, B, Eigen::EigenvaluesOnly);
  REQUIRE(eig.info() == Eigen::Success);
  return eig.eigenvalues().maxCoeff();
}

/// Level 1's matrix as Multigrid builds it: Pᵀ A P with the rows of A's decoupled (Dirichlet)
/// DOFs left out of P, a zero row made an identity row.
SparseMatrix<> galerkin_level_1(const SparseMatrix<>& A, const SparseMatrix<>& P, const std::vector<char>& fixed) {
  Eigen::MatrixXd Pd = Eigen::MatrixXd(P);
  for (Index r = 0; r < Pd.rows(); ++r)
    if (fixed[std::size_t(r)]) Pd.row(r).setZero();
  Eigen::MatrixXd C = Pd.transpose() * Eigen::MatrixXd(A) * Pd;
  for (Index r = 0; r < C.rows(); ++r)
    if (C.row(r).cwiseAbs().maxCoeff() == 0) C(r, r) = 1;
  return C.sparseView();
}

TEST_CASE("Multigrid: the Lanczos estimate of λ_max(B⁻¹A) (the Chebyshev smoother's) is a Ritz value within 10% of the dense eigensolve's on levels 0 and 1, also with a vertex scaled by 1e-20") {
  int checked = 0;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    auto s = stiffness_system(5 + seed, 3, seed);
    const SparseMatrix<> A = s.A();
    const auto prolongations = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 30, .coarsening = 0}).prolongations;
    REQUIRE(prolongations.size() >= 2);
    // a vertex whose rows and columns are 1e-20 of the others' (a Galerkin level's DOF that almost no
    // fine DOF reaches): D A D has B⁻¹A's spectrum (D B D)⁻¹(D A D) = D⁻¹ B⁻¹A D, so the same λ
    std::mt19937 rng(seed);
    const Index tiny = Index(rng() % std::uint32_t(s.mesh.num_vertices()));
    VecX<> d = VecX<>::Ones(A.rows());
    d.segment<3>(3 * tiny).setConstant(1e-20);
    const SparseMatrix<> scaled = d.asDiagonal() * A * d.asDiagonal();
    for (const bool scale : {false, true}) {
      const SparseMatrix<>& M = scale ? scaled : A;
      MultigridOptions o;
      o.smoother = MultigridOptions::Smoother::chebyshev;
      REQUIRE(o.spectrum == MultigridOptions::Spectrum::automatic);  // Lanczos for Chebyshev
      Multigrid<> mg(prolongations, o);
      mg.compute(exec::omp, M);
      const double truth0 = dense_block_jacobi_lambda_max(M);
      const double truth1 = dense_block_jacobi_lambda_max(galerkin_level_1(M, prolongations[0], s.fixed));
      for (const Index level : {Index(0), Index(1)}) {
        const double truth = level == 0 ? truth0 : truth1;
        const double ritz = mg.spectrum_bound(level) / 1.1;
        CAPTURE(seed);
        CAPTURE(scale);
        CAPTURE(level);
        CHECK(ritz <= truth * (1 + 1e-9));  // a Ritz value: never above λ_max
        CHECK(ritz >= 0.9 * truth);
        CHECK(mg.damping(level) == doctest::Approx(4.0 / (3.0 * mg.spectrum_bound(level))));
        ++checked;
      }
    }
  }
  CHECK(checked == 16);
  CHECK_THROWS_AS(Multigrid<>({}, {.lanczos_iterations = 0}), ArgumentError);
}

TEST_CASE("Multigrid: the Lanczos estimate starts cold at every compute (no history, no forget_estimates needed), seq == omp bitwise") {
  auto s = stiffness_system(12, 4, 3);
  const SparseMatrix<>& A = s.A();
  const auto prolongations = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 40, .coarsening = 0}).prolongations;
  SparseMatrix<> B = A;
  B *= 1.5;
  MultigridOptions o;
  o.spectrum = MultigridOptions::Spectrum::lanczos;  // with the Jacobi smoother too, when asked for
  Multigrid<> used(prolongations, o), fresh(prolongations, o), serial(prolongations, o);
  used.compute(exec::omp, A);
  used.compute(exec::omp, B);
  fresh.compute(exec::omp, B);
  serial.compute(exec::seq, B);
  REQUIRE(used.num_levels() >= 3);
  for (Index l = 0; l + 1 < used.num_levels(); ++l) {
    CHECK(used.spectrum_bound(l) == fresh.spectrum_bound(l));
    CHECK(serial.spectrum_bound(l) == fresh.spectrum_bound(l));
    CHECK(fresh.spectrum_bound(l) > 1.0);
  }
  VecX<> zu, zf, zs;
  used.apply(exec::omp, s.b, zu);
  fresh.apply(exec::omp, s.b, zf);
  serial.apply(exec::seq, s.b, zs);
  CHECK(zu == zf);
  CHECK(zs == zf);
}

TEST_CASE("Multigrid: coarse levels lagged (coarse_refresh_every): SPD and symmetric, PCG converges to the new matrix's solution; rebuilt on schedule, after forget_estimates and when the Dirichlet rows change") {
  auto s = stiffness_system(16, 4, 3);
  const auto prolongations = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 40}).prolongations;
  const SparseMatrix<> A = s.A();
  // a nearby matrix of the same pattern and Dirichlet rows (the next Newton iteration's): free
  // entries scaled by a smooth random factor, kept symmetric and positive definite
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0.7, 1.3);
  VecX<> scale(A.rows());
  for (Index i = 0; i < scale.size(); ++i) scale[i] = s.fixed[std::size_t(i)] ? 1.0 : u(rng);
  SparseMatrix<> B = A;
  for (Index r = 0; r < B.outerSize(); ++r)
    for (SparseMatrix<>::InnerIterator it(B, r); it; ++it)
      if (!s.fixed[std::size_t(it.row())] && !s.fixed[std::size_t(it.col())]) it.valueRef() *= std::sqrt(scale[it.row()] * scale[it.col()]);
  const Eigen::SimplicialLDLT<SparseMatrix<>> ldlt(B);
  REQUIRE(ldlt.info() == Eigen::Success);
  const VecX<> reference = ldlt.solve(s.b);

  using Pcg = ConjugateGradient<Multigrid<>>;
  Pcg lagged({.tolerance = 1e-10}, Multigrid<>(prolongations, {.coarse_refresh_every = 3})), fresh({.tolerance = 1e-10}, Multigrid<>(prolongations));
  lagged.compute(exec::seq, A);
  CHECK(lagged.preconditioner().refreshed());
  lagged.compute(exec::seq, B);  // B's residuals, A's coarse levels
  CHECK_FALSE(lagged.preconditioner().refreshed());
  fresh.compute(exec::seq, B);
  VecX<> x_lagged, x_fresh;
  const auto i_lagged = lagged.solve(exec::seq, s.b, x_lagged);
  const auto i_fresh = fresh.solve(exec::seq, s.b, x_fresh);
  CHECK(i_lagged.converged);
  CHECK((x_lagged - reference).norm() <= 1e-8 * reference.norm());
  CHECK((x_fresh - reference).norm() <= 1e-8 * reference.norm());
  MESSAGE("PCG iterations with B's coarse levels ", i_fresh.iterations, ", with A's (lagged) ", i_lagged.iterations);
  CHECK(i_lagged.iterations <= 2 * i_fresh.iterations);
  for (Index i = 0; i < x_lagged.size(); ++i)
    if (s.fixed[std::size_t(i)]) CHECK(x_lagged[i] == 0.0);
  // the lagged V-cycle is still a symmetric positive definite operator
  std::normal_distribution<double> N;
  for (int trial = 0; trial < 10; ++trial) {
    VecX<> a(B.rows()), b(B.rows()), Ma, Mb;
    for (Index i = 0; i < a.size(); ++i) a[i] = N(rng), b[i] = N(rng);
    lagged.preconditioner().apply(exec::seq, a, Ma);
    lagged.preconditioner().apply(exec::seq, b, Mb);
    CHECK(std::abs(a.dot(Mb) - b.dot(Ma)) <= 1e-10 * a.norm() * Mb.norm());
    CHECK(a.dot(Ma) > 0);
  }
  lagged.compute(exec::seq, B);  // the 3rd compute with these coarse levels
  CHECK_FALSE(lagged.preconditioner().refreshed());
  lagged.compute(exec::seq, B);  // the 4th: a rebuild
  CHECK(lagged.preconditioner().refreshed());
  lagged.compute(exec::seq, B);
  CHECK_FALSE(lagged.preconditioner().refreshed());
  lagged.preconditioner().forget_estimates();
  lagged.compute(exec::seq, B);
  CHECK(lagged.preconditioner().refreshed());
  VecX<> z_lagged, z_fresh;
  lagged.preconditioner().apply(exec::seq, s.b, z_lagged);
  fresh.preconditioner().apply(exec::seq, s.b, z_fresh);
  CHECK(z_lagged == z_fresh);  // after forget_estimates: a fresh build on B, bitwise
  // another Dirichlet set: the coarse levels are rebuilt at once (they must not move a fixed DOF)
  lagged.compute(exec::seq, A);
  REQUIRE_FALSE(lagged.preconditioner().refreshed());
  std::vector<char> more_fixed = s.fixed;
  for (Index v = 0; v < s.mesh.num_vertices(); ++v)
    if (s.mesh.V(v, 0) == 4.0)
      for (int c = 0; c < 3; ++c) more_fixed[std::size_t(3 * v + c)] = 1;
  const SparseMatrix<> C = s.H.assemble(exec::seq, more_fixed);
  lagged.compute(exec::seq, C);
  CHECK(lagged.preconditioner().refreshed());
  VecX<> rhs = s.b, x_c;
  for (Index i = 0; i < rhs.size(); ++i)
    if (more_fixed[std::size_t(i)]) rhs[i] = 0;
  CHECK(lagged.solve(exec::seq, rhs, x_c).converged);
  for (Index i = 0; i < x_c.size(); ++i)
    if (more_fixed[std::size_t(i)]) CHECK(x_c[i] == 0.0);
  CHECK_THROWS_AS(Multigrid<>(prolongations, {.coarse_refresh_every = 0}), ArgumentError);
}

TEST_CASE("PCG + multigrid solves stiffness systems like a direct LDLT, in far fewer iterations than block-Jacobi") {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    auto s = stiffness_system(24, 4, seed);
    const SparseMatrix<>& A = s.A();
    // Eigen's sparse LDLT: the same factorization as a dense LDLT of these 1875 unknowns, which
    // took 25 s of the TSan run for nothing TSan looks at (a single-threaded dense factorization).
    const Eigen::SimplicialLDLT<SparseMatrix<>> ldlt(A);
    REQUIRE(ldlt.info() == Eigen::Success);
    const VecX<> ref = ldlt.solve(s.b);
    ConjugateGradient<Multigrid<>> mg({.tolerance = 1e-10}, Multigrid<>(lattice_hierarchy(exec::omp, s.mesh, {.max_coarse_vertices = 40}).prolongations));
    ConjugateGradient<BlockJacobi<>> bj({.tolerance = 1e-10});
    mg.compute(exec::omp, A);
    bj.compute(exec::omp, A);
    VecX<> x_mg, x_bj;
    const auto i_mg = mg.solve(exec::omp, s.b, x_mg);
    const auto i_bj = bj.solve(exec::omp, s.b, x_bj);
    CAPTURE(i_mg.iterations);
    CAPTURE(i_bj.iterations);
    CHECK(i_mg.converged);
    CHECK((x_mg - ref).norm() <= 1e-8 * ref.norm());
    CHECK(3 * i_mg.iterations <= i_bj.iterations);
    MESSAGE("beam 24x4x4, seed ", seed, ": PCG iterations multigrid ", i_mg.iterations, ", block-Jacobi ", i_bj.iterations);
  }
  // no coarse level: the "V-cycle" is the exact solve, PCG converges in one iteration
  auto s = stiffness_system(4, 2, 5);
  ConjugateGradient<Multigrid<>> direct({.tolerance = 1e-10}, Multigrid<>(std::vector<SparseMatrix<>>{}));
  direct.compute(exec::seq, s.A());
  VecX<> x;
  CHECK(direct.solve(exec::seq, s.b, x).iterations == 1);
}

TEST_CASE("Newton with multigrid PCG reaches Cholesky's equilibrium (hanging neo-Hookean block, BCC lattice)") {
  const auto box = box_tet_mesh<double>(2, 2, 4, Vec3<>(0, 0, 0), Vec3<>(0.1, 0.1, 0.2));
  const TetMesh<double> mesh = discretize::bcc_lattice(box, 0.02).mesh;
  ElasticEnergy<NeoHookean<>> flesh(mesh, NeoHookean<>::from_young_poisson(2e4, 0.3));
  Gravity<> gravity(mesh, 1000.0, Vec3<>(0, 0, -9.81));
  BoneAttachments<> top(mesh.V);
  top.add_bone("top", select_vertices(mesh.V, [&](const Vec3<>& p) { return p.z() > 0.2 - 1e-9; }));
  auto solve = [&](auto policy, auto linear) {
    QuasistaticSolver<decltype(linear)> newton(mesh.num_vertices(), mesh.T, NewtonOptions{}, std::move(linear));
    Points<double> x = mesh.V;
    const auto report = newton.solve(policy, x, top.boundary(), flesh, gravity);
    CHECK(report.converged);
    return x;
  };
  using Pcg = ConjugateGradient<Multigrid<>>;
  const Points<double> x_mg = solve(exec::omp, make_linear_solver<Pcg>(exec::omp, mesh, {.tolerance = 1e-6}, {.max_coarse_vertices = 30}));
  const Points<double> x_mg_seq = solve(exec::seq, make_linear_solver<Pcg>(exec::seq, mesh, {.tolerance = 1e-6}, {.max_coarse_vertices = 30}));
  const Points<double> x_ch = solve(exec::seq, SparseCholesky<>{});
  const double sag = (mesh.V - x_ch).cwiseAbs().maxCoeff();
  CHECK(sag > 1e-3);
  CHECK((x_mg - x_ch).cwiseAbs().maxCoeff() <= 1e-6 * sag);
  CHECK(x_mg == x_mg_seq);  // the whole Newton solve, multigrid included: seq == omp bitwise
}

TEST_CASE("Multigrid, Chebyshev smoother: degree 1 is damped Jacobi with omega = 2 / (lo + hi); every degree gives a symmetric positive definite V-cycle, seq == omp bitwise, and PCG reaches LDLT's solution") {
  auto s = stiffness_system(16, 4, 7);
  const SparseMatrix<>& A = s.A();
  const Index n = A.rows();
  // one smoothed level (the second is the coarsest, solved directly): the Jacobi V-cycle with the
  // Chebyshev smoother's lambda estimate and omega = 2 / (lambda / ratio + lambda) is the degree-1 polynomial
  const auto two_levels = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 40, .max_levels = 1}).prolongations;
  REQUIRE(two_levels.size() == 1);
  const double ratio = 7;
  Multigrid<> cheb1(two_levels, {.smoother = MultigridOptions::Smoother::chebyshev, .chebyshev_degree = 1, .chebyshev_ratio = ratio});
  cheb1.compute(exec::seq, A);
  const double lambda = cheb1.spectrum_bound(0);
  Multigrid<> jac(two_levels, {.damping = 2.0 / (lambda / ratio + lambda)});
  jac.compute(exec::seq, A);
  std::mt19937 rng(5);
  std::normal_distribution<double> N;
  VecX<> r(n), z_cheb, z_jac;
  for (Index i = 0; i < n; ++i) r[i] = N(rng);
  cheb1.apply(exec::seq, r, z_cheb);
  jac.apply(exec::seq, r, z_jac);
  CHECK((z_cheb - z_jac).norm() <= 1e-12 * z_jac.norm());

  const Eigen::SimplicialLDLT<SparseMatrix<>> ldlt(A);
  REQUIRE(ldlt.info() == Eigen::Success);
  const VecX<> ref = ldlt.solve(s.b);
  const auto levels = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 40}).prolongations;
  for (const int degree : {1, 2, 3, 4}) {
    for (const double chebyshev_ratio : {4.0, 10.0, 30.0}) {
      CAPTURE(degree);
      CAPTURE(chebyshev_ratio);
      const MultigridOptions options{.smoother = MultigridOptions::Smoother::chebyshev, .chebyshev_degree = degree, .chebyshev_ratio = chebyshev_ratio};
      const Index iterations = check_smoother(levels, options, A, s.b, ref, rng);
      if (chebyshev_ratio == 10.0) MESSAGE("beam 16x4x4: PCG iterations with Chebyshev degree ", degree, ": ", iterations);
    }
  }
  ConjugateGradient<Multigrid<>> pcg_jacobi({.tolerance = 1e-10}, Multigrid<>(levels));
  pcg_jacobi.compute(exec::omp, A);
  VecX<> x;
  MESSAGE("beam 16x4x4: PCG iterations with one damped block-Jacobi sweep: ", pcg_jacobi.solve(exec::omp, s.b, x).iterations);
}

TEST_CASE("Multigrid, Gauss-Seidel smoother: the V-cycle equals a dense multicolour block Gauss-Seidel two-level cycle; symmetric positive definite, seq == omp bitwise; PCG reaches LDLT's solution in fewer iterations than with Jacobi") {
  auto s = stiffness_system(16, 4, 7);
  const SparseMatrix<>& A = s.A();
  const Index n = A.rows(), nv = n / 3;
  std::mt19937 rng(8);
  std::normal_distribution<double> N;
  // two levels, the second solved directly: the cycle written out with dense matrices
  const auto two_levels = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 40, .max_levels = 1}).prolongations;
  REQUIRE(two_levels.size() == 1);
  for (const int sweeps : {1, 2}) {
    CAPTURE(sweeps);
    Multigrid<> mg(two_levels, {.smoothing_sweeps = sweeps, .smoother = MultigridOptions::Smoother::gauss_seidel});
    mg.compute(exec::seq, A);
    VecX<> r(n), z;
    for (Index i = 0; i < n; ++i) r[i] = N(rng);
    mg.apply(exec::seq, r, z);
    // the reference: the vertex colours of A's block pattern, vertices updated one at a time
    BlockCsr<> blocks;
    blocks.assign(exec::seq, A);
    const ElementColouring colours = greedy_graph_colouring(blocks.block_outer(), blocks.block_inner(), nv);
    for (Index v = 0; v < nv; ++v)  // a proper colouring of the coupling: no block between two vertices of a colour
      for (Index w = 0; w < nv; ++w)
        if (v != w && colours.colour_of[std::size_t(v)] == colours.colour_of[std::size_t(w)]) REQUIRE(blocks.block(v, w).isZero(0));
    const Eigen::MatrixXd Ad = Eigen::MatrixXd(A);
    const auto sweep = [&](VecX<>& x, bool forward) {
      for (int k = 0; k < sweeps; ++k)
        for (Index q = 0; q < colours.num_colours(); ++q) {
          const Index c = forward ? q : colours.num_colours() - 1 - q;
          for (Index i = 0; i < colours.size(c); ++i) {
            const Index v = colours.element(c, i);
            const Vec3<> res = r.segment<3>(3 * v) - Ad.middleRows(3 * v, 3) * x;
            x.segment<3>(3 * v) += Ad.block(3 * v, 3 * v, 3, 3).inverse() * res;
          }
        }
    };
    VecX<> x = VecX<>::Zero(n);
    sweep(x, true);
    // the coarse correction: P with the rows of decoupled DOFs (no off-diagonal entry: the identity
    // rows of fixed DOFs) zeroed, PᵀAP solved
    Eigen::MatrixXd P = Eigen::MatrixXd(two_levels[0]);
    for (Index i = 0; i < n; ++i) {
      Eigen::RowVectorXd off = Ad.row(i);
      off[i] = 0;
      if (off.isZero(0)) P.row(i).setZero();
    }
    Eigen::MatrixXd Ac = P.transpose() * Ad * P;
    for (Index i = 0; i < Ac.rows(); ++i)
      if (Ac.row(i).isZero(0)) Ac(i, i) = 1;
    Ac.diagonal().array() += 1e-10 * Ac.diagonal().cwiseAbs().maxCoeff();  // the coarsest level's shift (Multigrid::factorize_coarsest)
    x += P * Ac.ldlt().solve(P.transpose() * (r - Ad * x));
    sweep(x, false);
    MESSAGE("sweeps ", sweeps, ": the V-cycle against the dense reference, relative difference ", (z - x).norm() / x.norm());
    CHECK((z - x).norm() <= 1e-10 * x.norm());
  }

  const Eigen::SimplicialLDLT<SparseMatrix<>> ldlt(A);
  REQUIRE(ldlt.info() == Eigen::Success);
  const VecX<> ref = ldlt.solve(s.b);
  const auto levels = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 40, .coarsening = 0}).prolongations;
  REQUIRE(levels.size() >= 2);
  ConjugateGradient<Multigrid<>> pcg_jacobi({.tolerance = 1e-10}, Multigrid<>(levels));
  pcg_jacobi.compute(exec::omp, A);
  VecX<> x;
  const Index jacobi_iterations = pcg_jacobi.solve(exec::omp, s.b, x).iterations;
  for (const auto storage : {MultigridOptions::Storage::block, MultigridOptions::Storage::block_single}) {
    const MultigridOptions options{.storage = storage, .smoother = MultigridOptions::Smoother::gauss_seidel};
    const Index iterations = check_smoother(levels, options, A, s.b, ref, rng);
    MESSAGE("beam 16x4x4: PCG iterations with one Gauss-Seidel sweep (", storage == MultigridOptions::Storage::block ? "double" : "single",
            " blocks): ", iterations, ", with one damped block-Jacobi sweep: ", jacobi_iterations);
    CHECK(iterations < jacobi_iterations);
  }
  // the csr storage has no blocks to sweep
  CHECK_THROWS_AS(Multigrid<>(levels, {.storage = MultigridOptions::Storage::csr, .smoother = MultigridOptions::Smoother::gauss_seidel}),
                  ArgumentError);
}

TEST_CASE("Multigrid: bad input is a typed error") {
  auto s = stiffness_system(8, 2, 1);
  auto P = lattice_hierarchy(exec::seq, s.mesh, {.max_coarse_vertices = 10}).prolongations;
  REQUIRE(P.size() >= 1);
  CHECK_THROWS_AS(Multigrid<>(P, {.smoothing_sweeps = 0}), ArgumentError);
  CHECK_THROWS_AS(Multigrid<>(P, {.damping = 2.5}), ArgumentError);
  CHECK_THROWS_AS(Multigrid<>(P, {.smoother = MultigridOptions::Smoother::chebyshev, .chebyshev_degree = 0}), ArgumentError);
  CHECK_THROWS_AS(Multigrid<>(P, {.smoother = MultigridOptions::Smoother::chebyshev, .chebyshev_ratio = 1}), ArgumentError);
  CHECK_THROWS_AS(Multigrid<>(P, {.chebyshev_ratio = std::numeric_limits<double>::infinity()}), ArgumentError);
  if (P.size() >= 2) {
    auto swapped = P;
    std::swap(swapped[0], swapped[1]);
    CHECK_THROWS_AS(Multigrid<>{swapped}, ShapeError);
  }
  Multigrid<> mg(P);
  VecX<> z;
  CHECK_THROWS_AS(mg.apply(exec::seq, s.b, z), Error);
  auto other = stiffness_system(4, 2, 1);
  CHECK_THROWS_AS(mg.compute(exec::seq, other.A()), ShapeError);
  // an indefinite matrix is the ConvergenceError QuasistaticSolver takes as "project the Hessian"
  SparseMatrix<> negative = -s.A();
  CHECK_THROWS_AS(mg.compute(exec::seq, negative), ConvergenceError);
}
