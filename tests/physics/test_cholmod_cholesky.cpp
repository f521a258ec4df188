// physics::CholmodCholesky (optional: CMake -DSIMSR_WITH_CHOLMOD=ON, Debian's libsuitesparse-dev)
// against Eigen's simplicial LDLᵀ (SparseCholesky) and a dense LDLᵀ on real stiffness systems, in
// the Newton solver and the local-global solver. Without CHOLMOD the suite reports it missing (a
// failure where peers are required).
#include <simsr/physics/linear_solvers/linear_solvers.hpp>

#include <doctest/doctest.h>

#include "../support/require.hpp"

#if defined(SIMSR_HAVE_CHOLMOD)

#include <simsr/mesh/generators.hpp>
#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/forces/bone_attachment.hpp>
#include <simsr/physics/forces/gravity.hpp>
#include <simsr/physics/linear_solvers/cholmod_cholesky.hpp>
#include <simsr/physics/local_global.hpp>
#include <simsr/physics/materials/neo_hookean.hpp>
#include <simsr/physics/materials/strain_limit.hpp>
#include <simsr/physics/quasistatic.hpp>

#include <Eigen/Dense>

#include "stiffness_system.hpp"

using namespace simsr;
using namespace simsr::physics;

TEST_CASE("CholmodCholesky solves random stiffness systems as a dense LDLT and SparseCholesky do (seq, omp)") {
  static_assert(LinearSolver<CholmodCholesky<>>);
  for (const auto& [nx, ny] : {std::pair<Index, Index>{4, 2}, {9, 3}}) {
    for (unsigned seed = 1; seed <= 4; ++seed) {
      auto s = simsr_test::stiffness_system(nx, ny, seed);
      const SparseMatrix<>& A = s.A();
      const VecX<> dense = Eigen::MatrixXd(A).ldlt().solve(s.b);
      SparseCholesky<> simplicial;
      simplicial.compute(exec::seq, A, s.H.pattern_version());
      VecX<> x_simplicial, x_seq, x_omp;
      simplicial.solve(exec::seq, s.b, x_simplicial);
      CholmodCholesky<> chol;
      chol.compute(exec::seq, A, s.H.pattern_version());
      const auto info = chol.solve(exec::seq, s.b, x_seq);
      CHECK(info.converged);
      CHECK(info.relative_residual < 1e-12);
      CHECK(chol.factor_nonzeros() >= double(A.rows()));
      CHECK((x_seq - dense).norm() <= 1e-10 * dense.norm());
      CHECK((x_seq - x_simplicial).norm() <= 1e-10 * dense.norm());
      chol.compute(exec::omp, A, s.H.pattern_version());
      CHECK(chol.solve(exec::omp, s.b, x_omp).converged);
      CHECK(x_omp == x_seq);  // the factorization is the same; only the residual check is parallel
    }
  }
}

TEST_CASE("CholmodCholesky: new values on the analysed pattern, then another pattern") {
  auto s = simsr_test::stiffness_system(5, 2, 3);
  SparseMatrix<> A = s.A();
  CholmodCholesky<> chol;
  VecX<> x1, x2;
  chol.compute(exec::seq, A, 7);
  chol.solve(exec::seq, s.b, x1);
  A *= 4.0;  // the same pattern (version 7), new values: the factorization must follow them
  chol.compute(exec::seq, A, 7);
  chol.solve(exec::seq, s.b, x2);
  CHECK((4.0 * x2 - x1).norm() <= 1e-12 * x1.norm());
  auto t = simsr_test::stiffness_system(3, 3, 5);  // another size and pattern
  const SparseMatrix<>& B = t.A();
  chol.compute(exec::seq, B, 8);
  VecX<> y;
  chol.solve(exec::seq, t.b, y);
  CHECK((Eigen::MatrixXd(B) * y - t.b).norm() <= 1e-10 * t.b.norm());
}

TEST_CASE("CholmodCholesky: a matrix that is not positive definite, a wrong size and a solve before compute are typed errors") {
  CholmodCholesky<> fresh;
  VecX<> x;
  CHECK_THROWS_AS(fresh.solve(exec::seq, VecX<>::Zero(3), x), Error);
  Eigen::Matrix3d Sd;
  Sd << 1, 1, 0, 1, 1, 0, 0, 0, 1;  // rank 2
  const SparseMatrix<> singular = Eigen::MatrixXd(Sd).sparseView();
  CHECK_THROWS_WITH_AS(fresh.compute(exec::seq, singular, 1), doctest::Contains("CholmodCholesky"), ConvergenceError);
  Eigen::Matrix3d In = Eigen::Matrix3d::Identity();
  In(2, 2) = -1;  // indefinite
  CHECK_THROWS_AS(fresh.compute(exec::seq, SparseMatrix<>(Eigen::MatrixXd(In).sparseView()), 2), ConvergenceError);
  const SparseMatrix<> rect = Eigen::MatrixXd::Ones(2, 3).sparseView();
  CHECK_THROWS_AS(fresh.compute(exec::seq, rect, 3), ShapeError);
  auto s = simsr_test::stiffness_system(3, 2, 1);
  fresh.compute(exec::seq, s.A(), s.H.pattern_version());
  CHECK_THROWS_AS(fresh.solve(exec::seq, VecX<>::Zero(5), x), ShapeError);
}

TEST_CASE("CholmodCholesky in the Newton and local-global solvers: SparseCholesky's equilibrium") {
  const auto mesh = box_tet_mesh<double>(3, 3, 5, Vec3<>(0, 0, 0), Vec3<>(0.1, 0.1, 0.2));
  Gravity<> gravity(mesh, 1000.0, Vec3<>(0, 0, -9.81));
  BoneAttachments<> top(mesh.V);
  top.add_bone("top", select_vertices(mesh.V, [&](const Vec3<>& p) { return p.z() > 0.2 - 1e-9; }));

  ElasticEnergy<NeoHookean<>> flesh(mesh, NeoHookean<>::from_young_poisson(2e4, 0.3));
  auto newton = [&](auto linear) {
    QuasistaticSolver<decltype(linear)> solver(mesh.num_vertices(), mesh.T, NewtonOptions{.relative_tolerance = 1e-10, .progress = {}},
                                               std::move(linear));
    Points<> x = mesh.V;
    CHECK(solver.solve(exec::omp, x, top.boundary(), flesh, gravity).converged);
    return x;
  };
  const Points<> xn_ch = newton(CholmodCholesky<>{}), xn_ref = newton(SparseCholesky<>{});
  const double sag = (xn_ref - mesh.V).cwiseAbs().maxCoeff();
  CHECK(sag > 1e-3);
  CHECK((xn_ch - xn_ref).cwiseAbs().maxCoeff() <= 1e-8 * sag);

  ElasticEnergy<StrainLimit<>> strain(mesh, StrainLimit<>(2e3, 1.0));
  auto local_global = [&](auto linear) {
    LocalGlobalSolver<decltype(linear)> solver(mesh.num_vertices(), mesh.T, LocalGlobalOptions{.relative_tolerance = 1e-10}, std::move(linear));
    Points<> x = mesh.V;
    CHECK(solver.solve(exec::omp, x, top.boundary(), strain, gravity).converged);
    CHECK(solver.reduced());  // the #V x #V matrix went to CHOLMOD
    return x;
  };
  const Points<> xl_ch = local_global(CholmodCholesky<>{}), xl_ref = local_global(SparseCholesky<>{});
  CHECK((xl_ref - mesh.V).cwiseAbs().maxCoeff() > 1e-3);
  CHECK((xl_ch - xl_ref).cwiseAbs().maxCoeff() <= 1e-8 * (xl_ref - mesh.V).cwiseAbs().maxCoeff());
}

#else

TEST_CASE("CholmodCholesky: CHOLMOD is available") {
  SIMSR_MISSING("CHOLMOD: configure with -DSIMSR_WITH_CHOLMOD=ON (apt-get install libsuitesparse-dev) to test physics::CholmodCholesky");
}

#endif
