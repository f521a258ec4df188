#include <simsr/mesh/generators.hpp>
#include <simsr/physics/elastic_energy.hpp>
#include <simsr/physics/materials/neo_hookean.hpp>
#include <simsr/physics/materials/strain_limit.hpp>
#include <simsr/physics/materials/teran_muscle.hpp>

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <array>
#include <numeric>
#include <random>

#include "stvk_material.hpp"

using namespace simsr;
using namespace simsr::physics;

namespace {

Points<> perturbed(const Points<>& V, double amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  Points<> x = V;
  for (Index i = 0; i < x.size(); ++i) x.data()[i] += u(rng);
  return x;
}

/// The dense 3V×3V matrix of H (no fixed DOFs).
Eigen::MatrixXd dense(auto policy, BlockHessian<>& H) {
  const std::vector<char> free(std::size_t(3 * H.num_vertices()), 0);
  return Eigen::MatrixXd(H.assemble(policy, free));
}

/// Σ_t of the element Hessians scattered into a dense 3V×3V matrix: the reference for the gather.
template <class M>
Eigen::MatrixXd element_sum(const ElasticEnergy<M>& E, const Points<>& x, Definiteness d) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3 * E.num_vertices(), 3 * E.num_vertices());
  for (Index t = 0; t < E.num_tets(); ++t) {
    const Mat12<> K = E.element_hessian(x, t, d);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) H.block<3, 3>(3 * E.tets()(t, a), 3 * E.tets()(t, b)) += K.block<3, 3>(3 * a, 3 * b);
  }
  return H;
}

}  // namespace

TEST_CASE("tet_rest_data: volumes and Dm⁻¹; flat and inverted rest tets are MeshErrors naming the tet") {
  const auto mesh = box_tet_mesh<double>(2, 1, 1, Vec3<>(0, 0, 0), Vec3<>(2, 1, 1));
  const auto rest = tet_rest_data(exec::seq, mesh.V, mesh.T);
  CHECK(rest.volume.sum() == doctest::Approx(2.0));
  for (Index t = 0; t < mesh.num_tets(); ++t)  // F(rest) = I
    CHECK((deformation_gradient(mesh.V, mesh.T, t, rest.Dm_inv[std::size_t(t)]) - Mat3<>::Identity()).norm() < 1e-14);
  auto bad = mesh;
  std::swap(bad.T(3, 1), bad.T(3, 2));
  CHECK_THROWS_WITH_AS(tet_rest_data(exec::seq, bad.V, bad.T), doctest::Contains("tet 3: inverted"), MeshError);
  bad = mesh;
  bad.V.row(bad.T(5, 3)) = bad.V.row(bad.T(5, 0));
  CHECK_THROWS_AS(tet_rest_data(exec::seq, bad.V, bad.T), MeshError);
  bad = mesh;
  bad.T(2, 0) = 99;
  CHECK_THROWS_WITH_AS(tet_rest_data(exec::seq, bad.V, bad.T), doctest::Contains("out of range"), MeshError);
}

TEST_CASE("ElasticEnergy: gradient is the finite difference of the energy, Hessian that of the gradient") {
  const auto mesh = box_tet_mesh<double>(2, 2, 1, Vec3<>(0, 0, 0), Vec3<>(1, 1, 0.5));
  simsr_test::StVK m{1.3, 0.7};
  ElasticEnergy<simsr_test::StVK> E(mesh, m);
  const Index n = mesh.num_vertices();
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Points<> x = perturbed(mesh.V, 0.15, seed);
    Points<> g = Points<>::Zero(n, 3);
    E.add_gradient(exec::seq, x, g);
    const double h = 1e-6;
    double worst = 0;
    for (Index i = 0; i < 3 * n; ++i) {
      Points<> xp = x, xm = x;
      xp.data()[i] += h;
      xm.data()[i] -= h;
      const double fd = (E.energy(exec::seq, xp) - E.energy(exec::seq, xm)) / (2 * h);
      worst = std::max(worst, std::abs(fd - g.data()[i]));
    }
    CHECK(worst < 1e-7 * std::max(1.0, g.cwiseAbs().maxCoeff()));

    BlockHessian<> HB(n, mesh.T);
    HB.set_zero();
    E.add_hessian(exec::seq, x, HB, Definiteness::exact);
    const Eigen::MatrixXd H = dense(exec::seq, HB);
    double worst_h = 0;
    for (Index i = 0; i < 3 * n; ++i) {
      Points<> xp = x, xm = x, gp = Points<>::Zero(n, 3), gm = Points<>::Zero(n, 3);
      xp.data()[i] += h;
      xm.data()[i] -= h;
      E.add_gradient(exec::seq, xp, gp);
      E.add_gradient(exec::seq, xm, gm);
      const Eigen::VectorXd col = (Eigen::Map<Eigen::VectorXd>(gp.data(), 3 * n) - Eigen::Map<Eigen::VectorXd>(gm.data(), 3 * n)) / (2 * h);
      // Points is vertex-major (row-major #V×3): data index i = 3v + c, the Hessian's DOF order.
      worst_h = std::max(worst_h, (col - H.col(i)).cwiseAbs().maxCoeff());
    }
    CHECK(worst_h < 1e-6 * std::max(1.0, H.cwiseAbs().maxCoeff()));
    CHECK((H - H.transpose()).cwiseAbs().maxCoeff() < 1e-12 * H.cwiseAbs().maxCoeff());
  }
}

TEST_CASE("ElasticEnergy: the assembled Hessian is the sum of the element Hessians; seq and omp agree bitwise") {
  const auto mesh = box_tet_mesh<double>(3, 2, 2);
  const Points<> x = perturbed(mesh.V, 0.1, 7);
  ElasticEnergy<simsr_test::StVK> E(mesh, {});
  CHECK(E.hessian_assembly() == HessianAssembly::coloured);
  CHECK(E.tets_per_chunk() == ElasticEnergy<simsr_test::StVK>::kDefaultTetsPerChunk);
  CHECK_THROWS_AS(E.set_hessian_assembly(HessianAssembly::coloured, 0), ArgumentError);
  for (const auto& setting : {std::pair{HessianAssembly::coloured, Index(1)}, std::pair{HessianAssembly::coloured, Index(5)},
                              std::pair{HessianAssembly::coloured, Index(256)}, std::pair{HessianAssembly::gather, Index(1)}}) {
    // (no structured binding: clang 14 cannot capture one in CAPTURE's lambda)
    const HessianAssembly assembly = setting.first;
    const Index chunk = setting.second;
    CAPTURE(int(assembly));
    CAPTURE(chunk);
    E.set_hessian_assembly(assembly, chunk);
    const Eigen::MatrixXd A = element_sum(E, x, Definiteness::project);
    BlockHessian<> fast(mesh.num_vertices(), mesh.T), fast_omp(mesh.num_vertices(), mesh.T);
    fast.set_zero();
    E.add_hessian(exec::seq, x, fast, Definiteness::project);
    fast_omp.set_zero();
    E.add_hessian(exec::omp, x, fast_omp, Definiteness::project);
    const Eigen::MatrixXd B = dense(exec::seq, fast);
    const Eigen::MatrixXd C = dense(exec::omp, fast_omp);
    CHECK((A - B).cwiseAbs().maxCoeff() < 1e-12 * A.cwiseAbs().maxCoeff());
    CHECK((B - C).cwiseAbs().maxCoeff() == 0.0);
    // added onto what is there, in the pattern of the tets only
    E.add_hessian(exec::seq, x, fast, Definiteness::project);
    CHECK((dense(exec::seq, fast) - 2 * B).cwiseAbs().maxCoeff() < 1e-12 * A.cwiseAbs().maxCoeff());
    BlockHessian<> diagonal_only(mesh.num_vertices());
    CHECK_THROWS_AS(E.add_hessian(exec::seq, x, diagonal_only, Definiteness::project), MeshError);
  }
  Points<> g1 = Points<>::Zero(mesh.num_vertices(), 3), g2 = g1;
  E.add_gradient(exec::seq, x, g1);
  E.add_gradient(exec::omp, x, g2);
  CHECK((g1 - g2).cwiseAbs().maxCoeff() == 0.0);
  CHECK(E.energy(exec::seq, x) == E.energy(exec::omp, x));
  CHECK(E.count_inverted(exec::seq, x) == E.count_inverted(exec::omp, x));
}

/// DeviceElasticEnergy::add_hessian's launch sequence on the host arrays it copies (the element
/// stiffness body over every tet, then the gather body over H's block slots with
/// hessian_gather_lists), against add_hessian's gathered assembly: bitwise, seq and omp.
template <class M>
void check_hessian_bodies(const TetMesh<double>& mesh, const Points<>& x, const M& material, const std::vector<typename M::Element>& elements) {
  ElasticEnergy<M> E(mesh, material, elements);
  E.set_hessian_assembly(HessianAssembly::gather, 1);
  for (const Definiteness d : {Definiteness::project, Definiteness::exact}) {
    BlockHessian<> expected(mesh.num_vertices(), mesh.T), by_bodies(mesh.num_vertices(), mesh.T);
    E.add_hessian(exec::seq, x, expected, d);
    const auto [offsets, entries] = E.hessian_gather_lists(exec::seq, by_bodies);
    REQUIRE(Index(offsets.size()) == by_bodies.num_blocks() + 1);
    CHECK(Index(entries.size()) == 16 * mesh.num_tets());  // every (tet, a, b) once
    std::vector<double> upper(std::size_t(90 * mesh.num_tets()));
    using Element = physics::detail::ElasticElementBody<M, physics::detail::ElementOutput::forces>;
    const Element element{material,
                          E.tets().data(),
                          E.rest().Dm_inv[0].data(),
                          E.element_shape_gradients()[0].data(),
                          E.rest().volume.data(),
                          E.elements().data(),
                          MatrixSpan<const double>{x.data(), x.rows(), 3, 3},
                          nullptr};
    const physics::detail::ElementStiffnessBody<M> stiffness{element, d, upper.data()};
    const physics::detail::GatherHessianBlocks<double> gather{offsets.data(), entries.data(), upper.data(), by_bodies.block(0).data()};
    exec::parallel_for(exec::omp, mesh.num_tets(), stiffness);
    exec::parallel_for(exec::omp, by_bodies.num_blocks(), gather);
    for (Index s = 0; s < expected.num_blocks(); ++s) CHECK(expected.block(s) == by_bodies.block(s));
    // a tet's stiffness from the body is element_hessian's (the same F, D and material call)
    CHECK(stiffness.stiffness(3) == E.element_hessian(x, 3, d));
  }
  BlockHessian<> other(mesh.num_vertices() + 1);
  CHECK_THROWS_AS((void)E.hessian_gather_lists(exec::seq, other), ShapeError);
}

TEST_CASE("ElasticEnergy: the Hessian bodies DeviceElasticEnergy launches give add_hessian's gathered assembly bitwise (Neo-Hookean, Teran muscle)") {
  const auto mesh = box_tet_mesh<double>(4, 3, 3, Vec3<>(0, 0, 0), Vec3<>(0.04, 0.03, 0.03));
  const Points<> x = perturbed(mesh.V, 0.004, 5);  // up to 40 % of a cell
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<MuscleFibre<double>> fibres(std::size_t(mesh.num_tets()));
  for (auto& f : fibres) f = TeranMuscle<double>::element(Vec3<>(u(rng), u(rng), u(rng)), 0.5 + 0.5 * u(rng));
  check_hessian_bodies(mesh, x, NeoHookean<double>::from_young_poisson(3e4, 0.45), std::vector<NoElementData>(std::size_t(mesh.num_tets())));
  check_hessian_bodies(mesh, x, TeranMuscle<double>(), fibres);
}

TEST_CASE("ElasticEnergy: coloured and gathered assembly agree to rounding on random meshes and states; each is seq == omp bitwise") {
  std::mt19937 rng(41);
  for (int trial = 0; trial < 16; ++trial) {
    const Index nx = 1 + Index(rng() % 4), ny = 1 + Index(rng() % 3), nz = 1 + Index(rng() % 3);
    auto mesh = box_tet_mesh<double>(nx, ny, nz);
    // shuffle the tets: the colouring follows element order, so a mesh in any order is covered
    std::vector<Index> order(std::size_t(mesh.num_tets()));
    std::iota(order.begin(), order.end(), Index(0));
    std::shuffle(order.begin(), order.end(), rng);
    const Tets T0 = mesh.T;
    for (Index t = 0; t < T0.rows(); ++t) mesh.T.row(t) = T0.row(order[std::size_t(t)]);
    const Points<> x = perturbed(mesh.V, 0.05 + 0.05 * double(trial % 4), unsigned(100 + trial));
    const Definiteness d = trial % 2 ? Definiteness::exact : Definiteness::project;
    ElasticEnergy<simsr_test::StVK> E(mesh, {});
    const Eigen::MatrixXd A = element_sum(E, x, d);
    const double scale = A.cwiseAbs().maxCoeff();
    // coloured with 1 to 9 tets a chunk (more chunks than colours, and fewer) against gathered
    const Index chunk = 1 + Index(rng() % 9);
    CAPTURE(chunk);
    std::array<Eigen::MatrixXd, 2> seq, omp;
    for (int m = 0; m < 2; ++m) {
      E.set_hessian_assembly(m == 0 ? HessianAssembly::coloured : HessianAssembly::gather, chunk);
      BlockHessian<> Hs(mesh.num_vertices(), mesh.T), Ho(mesh.num_vertices(), mesh.T);
      // start from a random H: assembly adds onto what is there
      for (Index b = 0; b < Hs.num_blocks(); ++b) Hs.block(b) = Mat3<>::Random();
      for (Index b = 0; b < Hs.num_blocks(); ++b) Ho.block(b) = Hs.block(b);
      const Eigen::MatrixXd start = dense(exec::seq, Hs);
      E.add_hessian(exec::seq, x, Hs, d);
      E.add_hessian(exec::omp, x, Ho, d);
      seq[std::size_t(m)] = dense(exec::seq, Hs) - start;
      omp[std::size_t(m)] = dense(exec::seq, Ho) - start;
      CHECK((dense(exec::seq, Hs) - dense(exec::seq, Ho)).cwiseAbs().maxCoeff() == 0.0);
      CHECK((seq[std::size_t(m)] - A).cwiseAbs().maxCoeff() < 1e-12 * (scale + 1));
      // from zero, block (j, i) is exactly block (i, j)ᵀ for i ≠ j
      BlockHessian<> Hz(mesh.num_vertices(), mesh.T);
      Hz.set_zero();
      E.add_hessian(exec::omp, x, Hz, d);
      Eigen::MatrixXd Z = dense(exec::seq, Hz);
      Z -= Eigen::MatrixXd(Z.transpose());
      for (Index v = 0; v < mesh.num_vertices(); ++v) Z.block<3, 3>(3 * v, 3 * v).setZero();
      CHECK(Z.cwiseAbs().maxCoeff() == 0.0);
    }
    CHECK((seq[0] - seq[1]).cwiseAbs().maxCoeff() < 1e-12 * (scale + 1));
  }
}

TEST_CASE("ElasticEnergy: coloured assembly follows a grown pattern and names a tet whose block is missing") {
  const auto mesh = box_tet_mesh<double>(2, 2, 1);
  const Points<> x = perturbed(mesh.V, 0.1, 8);
  ElasticEnergy<simsr_test::StVK> E(mesh, {});
  E.set_hessian_assembly(HessianAssembly::coloured, 2);
  BlockHessian<> H(mesh.num_vertices(), mesh.T);
  H.set_zero();
  E.add_hessian(exec::omp, x, H, Definiteness::project);
  const Eigen::MatrixXd once = dense(exec::seq, H);
  // a block outside the tets' pattern (vertices 0 and the last), merged by assemble(), moves
  // every slot after it and changes the pattern version
  const std::uint64_t version = H.pattern_version();
  H.add(0, VIndex(mesh.num_vertices() - 1), Mat3<>::Identity());
  H.add(VIndex(mesh.num_vertices() - 1), 0, Mat3<>::Identity());
  dense(exec::seq, H);
  REQUIRE(H.pattern_version() != version);
  E.add_hessian(exec::omp, x, H, Definiteness::project);
  Eigen::MatrixXd expected = 2 * once;
  expected.block<3, 3>(0, 3 * (mesh.num_vertices() - 1)) += Eigen::Matrix3d::Identity();
  expected.block<3, 3>(3 * (mesh.num_vertices() - 1), 0) += Eigen::Matrix3d::Identity();
  CHECK((dense(exec::seq, H) - expected).cwiseAbs().maxCoeff() < 1e-12 * once.cwiseAbs().maxCoeff());
  // a pattern from fewer tets: the first tet (in tet order) not in it is named
  const Tets some = mesh.T.topRows(3);
  BlockHessian<> partial(mesh.num_vertices(), some);
  for (const HessianAssembly a : {HessianAssembly::coloured, HessianAssembly::gather}) {
    E.set_hessian_assembly(a, 2);
    Index first_missing = -1;
    for (Index t = 3; t < mesh.num_tets() && first_missing < 0; ++t)
      for (int i = 0; i < 4 && first_missing < 0; ++i)
        for (int j = 0; j < 4; ++j)
          if (partial.slot(mesh.T(t, i), mesh.T(t, j)) < 0) {
            first_missing = t;
            break;
          }
    REQUIRE(first_missing >= 0);
    const std::string named = "tet " + std::to_string(first_missing) + ":";
    CHECK_THROWS_WITH_AS(E.add_hessian(exec::omp, x, partial, Definiteness::project), doctest::Contains(named.c_str()), MeshError);
    // the refused pattern left nothing behind: the full one still assembles to the element sum
    BlockHessian<> full(mesh.num_vertices(), mesh.T);
    full.set_zero();
    E.add_hessian(exec::omp, x, full, Definiteness::project);
    CHECK((dense(exec::seq, full) - once).cwiseAbs().maxCoeff() < 1e-12 * once.cwiseAbs().maxCoeff());
    full.set_zero();
    E.add_hessian(exec::omp, x, full, Definiteness::project);  // same pattern, lists reused
    CHECK_THROWS_AS(E.add_hessian(exec::omp, x, partial, Definiteness::project), MeshError);
    full.set_zero();
    E.add_hessian(exec::omp, x, full, Definiteness::project);  // after a refusal, with reused lists
    CHECK((dense(exec::seq, full) - once).cwiseAbs().maxCoeff() < 1e-12 * once.cwiseAbs().maxCoeff());
  }
}

TEST_CASE("BlockHessian: blocks outside the pattern grow it, keep every value and change the version") {
  const auto mesh = box_tet_mesh<double>(2, 1, 1);
  BlockHessian<> H(mesh.num_vertices(), mesh.T);
  const auto v0 = H.pattern_version();
  const VIndex far_a = 0, far_b = VIndex(mesh.num_vertices() - 1);
  REQUIRE(H.slot(far_a, far_b) < 0);
  H.set_zero();
  H.add(0, 0, Mat3<>::Identity());
  Mat3<> b = Mat3<>::Constant(2.0);
  H.add(far_a, far_b, b);
  H.add(far_b, far_a, b);
  std::vector<char> free(std::size_t(3 * mesh.num_vertices()), 0);
  const Eigen::MatrixXd A = Eigen::MatrixXd(H.assemble(exec::seq, free));
  CHECK(H.pattern_version() != v0);
  CHECK(A(0, 0) == 1.0);
  CHECK(A(3 * far_a + 1, 3 * far_b + 2) == 2.0);
  CHECK(A(3 * far_b, 3 * far_a) == 2.0);
  CHECK_THROWS_AS(H.add(0, VIndex(mesh.num_vertices()), b), ShapeError);
  // fixed DOFs: identity row and column
  free[4] = 1;
  H.set_zero();
  H.add(1, 1, Mat3<>::Constant(5.0));
  const Eigen::MatrixXd F = Eigen::MatrixXd(H.assemble(exec::seq, free));
  CHECK(F(4, 4) == 1.0);
  CHECK(F(3, 4) == 0.0);
  CHECK(F(4, 5) == 0.0);
  CHECK(F(3, 5) == 5.0);
}

TEST_CASE("BlockHessian: an isotropic matrix (every block c·I) is A ⊗ I3 with A from assemble_isotropic, fixed vertices eliminated alike") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto mesh = box_tet_mesh<double>(2, 2, 1);
  const Index n = mesh.num_vertices();
  for (int trial = 0; trial < 20; ++trial) {
    BlockHessian<> H(n, mesh.T);
    H.set_zero();
    for (Index v = 0; v < n; ++v) H.add(VIndex(v), VIndex(v), (3.0 + u(rng)) * Mat3<>::Identity());
    for (Index t = 0; t < mesh.num_tets(); ++t) {
      const double c = u(rng);
      H.add(mesh.T(t, 0), mesh.T(t, 1), c * Mat3<>::Identity());
      H.add(mesh.T(t, 1), mesh.T(t, 0), c * Mat3<>::Identity());
    }
    const double far = u(rng);  // a pair outside the tets' pattern: pending until merged
    H.add(0, VIndex(n - 1), far * Mat3<>::Identity());
    H.add(VIndex(n - 1), 0, far * Mat3<>::Identity());
    REQUIRE(H.isotropic());
    std::vector<char> fixed_vertices(std::size_t(n), 0), fixed(std::size_t(3 * n), 0);
    for (Index v = 0; v < n; ++v)
      if (rng() % 5 == 0) {
        fixed_vertices[std::size_t(v)] = 1;
        for (int c = 0; c < 3; ++c) fixed[std::size_t(3 * v + c)] = 1;
      }
    const Eigen::MatrixXd full = Eigen::MatrixXd(H.assemble(exec::seq, fixed));
    const Eigen::MatrixXd A = Eigen::MatrixXd(H.assemble_isotropic(exec::omp, fixed_vertices));
    Eigen::MatrixXd kron = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    for (Index i = 0; i < n; ++i)
      for (Index j = 0; j < n; ++j) kron.block<3, 3>(3 * i, 3 * j) = A(i, j) * Mat3<>::Identity();
    CHECK(kron == full);
    CHECK(A(0, n - 1) == (fixed_vertices[0] || fixed_vertices[std::size_t(n - 1)] ? 0.0 : far));
  }
  // one off-diagonal entry or one unequal diagonal entry in one block: not isotropic
  for (int entry = 1; entry < 9; ++entry) {
    BlockHessian<> H(n, mesh.T);
    H.set_zero();
    for (Index v = 0; v < n; ++v) H.add(VIndex(v), VIndex(v), Mat3<>::Identity());
    Mat3<> b = Mat3<>::Zero();
    b(entry % 3, entry / 3) = 1e-3;
    H.add(mesh.T(0, 2), mesh.T(0, 3), b);
    CHECK_FALSE(H.isotropic());
    CHECK_THROWS_AS(H.assemble_isotropic(exec::seq, std::vector<char>(std::size_t(n), 0)), ArgumentError);
  }
  BlockHessian<> H(n, mesh.T);
  H.set_zero();
  CHECK_THROWS_AS(H.assemble_isotropic(exec::seq, std::vector<char>(std::size_t(n - 1), 0)), ShapeError);
}

TEST_CASE("ElasticEnergy::add_energy_gradient equals energy() and add_gradient() (fused StrainLimit and the fallback), seq == omp") {
  const auto mesh = box_tet_mesh<double>(3, 2, 2);
  for (unsigned seed = 0; seed < 10; ++seed) {
    const Points<> x = perturbed(mesh.V, 0.25, 100 + seed);  // large enough to invert some tets
    const auto check = [&](const auto& E) {
      Points<> g0 = Points<>::Zero(mesh.num_vertices(), 3), g1 = g0, g2 = g0;
      E.add_gradient(exec::seq, x, g0);
      const double e1 = E.add_energy_gradient(exec::seq, x, g1);
      const double e2 = E.add_energy_gradient(exec::omp, x, g2);
      CHECK(e1 == doctest::Approx(E.energy(exec::seq, x)).epsilon(1e-13));
      CHECK(e1 == e2);
      CHECK((g1 - g0).cwiseAbs().maxCoeff() <= 1e-13 * (1 + g0.cwiseAbs().maxCoeff()));
      CHECK(g1 == g2);
    };
    check(ElasticEnergy<StrainLimit<>>(mesh, StrainLimit<>(1.5, 0.7 + 0.06 * seed)));
    check(ElasticEnergy<simsr_test::StVK>(mesh, {}));
  }
}

TEST_CASE("ElasticEnergy: element data count is checked") {
  const auto mesh = box_tet_mesh<double>(1, 1, 1);
  CHECK_THROWS_AS(ElasticEnergy<simsr_test::StVK>(mesh, {}, std::vector<NoElementData>(3)), ShapeError);
  ElasticEnergy<simsr_test::StVK> E(mesh, {});
  CHECK_THROWS_AS(E.energy(exec::seq, Points<>::Zero(3, 3)), ShapeError);
}
