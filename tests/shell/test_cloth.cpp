// The thin-shell data's simulator (issue #14 item 3): wind forces, the SHEET and DISK scenes'
// meshes, and short runs of both scenes at reduced sizes (the full sizes are the datagen's).
#include <doctest/doctest.h>

#include "../support/require.hpp"

#include <simsr/shell/cloth_scenes.hpp>
#include <simsr/shell/cloth_simulator.hpp>
#if defined(SIMSR_HAVE_CHOLMOD)
#include <simsr/physics/linear_solvers/cholmod_cholesky.hpp>
#endif

#include <simsr/mesh/closest_point.hpp>
#include <simsr/mesh/loop_subdivision.hpp>

#include <array>
#include <cmath>
#include <random>

namespace shell_test_cloth {

using namespace simsr;
using namespace simsr::shell;

TEST_CASE("wind_forces: ½ρC_d A |v_n| v_n n per triangle, a third per corner; none along the cloth or moving with the air; bad input named") {
  TriMesh<> tri;
  tri.V.resize(3, 3);
  tri.V << 0, 0, 0, 2, 0, 0, 0, 1, 0;  // area 1, normal +z
  tri.F.resize(1, 3);
  tri.F << 0, 1, 2;
  const Points<> still = Points<>::Zero(3, 3);
  Air air;
  air.velocity = Vec3<>(1, 2, -3);
  air.density = 1.25;
  air.drag = 0.8;
  Points<> f;
  wind_forces(exec::seq, tri.V, still, tri.F, air, f);
  const double expected = 0.5 * 1.25 * 0.8 * 1.0 * 3 * (-3) / 3;  // |v_n| v_n with v_n = −3
  for (Index i = 0; i < 3; ++i) CHECK((f.row(i) - Eigen::RowVector3d(0, 0, expected)).norm() < 1e-14);
  // the cloth moving with the air: no relative velocity, no force
  Points<> with_air = still.rowwise() + air.velocity.transpose();
  wind_forces(exec::seq, tri.V, with_air, tri.F, air, f);
  CHECK(f.cwiseAbs().maxCoeff() < 1e-14);
  air.velocity = Vec3<>(4, -1, 0);  // along the cloth
  wind_forces(exec::seq, tri.V, still, tri.F, air, f);
  CHECK(f.cwiseAbs().maxCoeff() == 0);
  // a curved sheet: the total force is the sum of the triangles' own, each along its normal
  TriMesh<> sheet = square_sheet(1.0, 4);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (Index i = 0; i < sheet.V.rows(); ++i) sheet.V(i, 2) = u(rng);
  Points<> v = Points<>::Zero(sheet.V.rows(), 3);
  for (Index i = 0; i < v.rows(); ++i) v.row(i) << u(rng), u(rng), u(rng);
  air.velocity = Vec3<>(0.5, -0.3, 2.0);
  wind_forces(exec::seq, sheet.V, v, sheet.F, air, f);
  Vec3<> total = Vec3<>::Zero();
  for (Index t = 0; t < sheet.F.rows(); ++t) {
    const Vec3<> a = sheet.V.row(sheet.F(t, 0)), b = sheet.V.row(sheet.F(t, 1)), c = sheet.V.row(sheet.F(t, 2));
    const Vec3<> n = (b - a).cross(c - a).normalized();
    const double area = 0.5 * (b - a).cross(c - a).norm();
    const Vec3<> vbar = (v.row(sheet.F(t, 0)) + v.row(sheet.F(t, 1)) + v.row(sheet.F(t, 2))).transpose() / 3;
    const double vn = (air.velocity - vbar).dot(n);
    total += 0.5 * air.density * air.drag * area * std::abs(vn) * vn * n;
  }
  CHECK((f.colwise().sum().transpose() - total).norm() < 1e-12 * (1 + total.norm()));
  CHECK(total.z() > 0);  // the wind blows up through it
  CHECK_THROWS_AS(wind_forces(exec::seq, sheet.V, Points<>(v.topRows(3)), sheet.F, air, f), ShapeError);
  Tris bad = sheet.F;
  bad(2, 1) = 99;
  CHECK_THROWS_AS(wind_forces(exec::seq, sheet.V, v, bad, air, f), MeshError);
  air.density = -1;
  CHECK_THROWS_AS(wind_forces(exec::seq, sheet.V, v, sheet.F, air, f), ArgumentError);
}

TEST_CASE("cloth_pair: SHEET 81 / 4,225 and DISK 127 / 7,057 vertices, the fine rest the Loop-subdivided coarse, the pins the same ids") {
  const ClothPair sheet = cloth_pair(ClothDataset::sheet, default_scene_size(ClothDataset::sheet));
  CHECK(sheet.coarse.V.rows() == 81);
  // the command line's overrides: 0 cells / −1 levels keep the scene's default
  CHECK(scene_size(ClothDataset::sheet, 0, -1).coarse_cells == 8);
  CHECK(scene_size(ClothDataset::sheet, 4, -1).coarse_cells == 4);
  CHECK(scene_size(ClothDataset::sheet, 4, -1).levels == 3);
  CHECK(scene_size(ClothDataset::disk, 0, 0).levels == 0);
  CHECK(scene_size(ClothDataset::disk, 0, 0).coarse_cells == 6);
  CHECK(sheet.fine.V.rows() == 4225);
  CHECK(sheet.fine.F.rows() == 8192);
  CHECK((Points<>(sheet.subdivision * sheet.coarse.V) - sheet.fine.V).cwiseAbs().maxCoeff() == 0);
  for (Index k = 0; k < 4; ++k)  // the corners are kept: pinned at the same spot in both
    CHECK((sheet.fine.V.row(sheet.pinned[k]) - sheet.coarse.V.row(sheet.pinned[k])).norm() == 0);
  CHECK((sheet.fine_pinned.array() == sheet.pinned.array()).all());
  CHECK(std::abs(sheet.coarse.V.col(0).mean()) < 1e-15);
  const ClothPair disk = cloth_pair(ClothDataset::disk, default_scene_size(ClothDataset::disk));
  CHECK(disk.coarse.V.rows() == 127);
  CHECK(disk.fine.V.rows() == 7057);
  CHECK(disk.pinned.size() == 7);
  for (Index k = 0; k < 7; ++k) CHECK((disk.fine.V.row(disk.pinned[k]) - disk.coarse.V.row(disk.pinned[k])).norm() < 0.02);
  CHECK(disk_table().distance(disk.coarse.V.row(0).transpose()) == doctest::Approx(0.03));  // just above the table
  CHECK(cloth_dataset("disk") == ClothDataset::disk);
  CHECK_THROWS_WITH_AS(cloth_dataset("skirt"), doctest::Contains("got 'skirt'"), ArgumentError);
  CHECK_THROWS_AS(cloth_pair(ClothDataset::sheet, {1, 2}), ArgumentError);
  CHECK_THROWS_AS(cloth_pair(ClothDataset::disk, {6, -1}), ArgumentError);
}

/// Brute force over every triangle of `surface` (rest positions) for the closest point to each
/// fine rest vertex, then the deformed surface `moved` read there: what ClothPair::subdivision
/// must do for a fine sheet of its own, written without the kd-tree.
Points<> resampled_by_brute_force(const TriMesh<>& surface, const Points<>& moved, const Points<>& fine_rest) {
  Points<> out(fine_rest.rows(), 3);
  for (Index i = 0; i < fine_rest.rows(); ++i) {
    const Vec3<> q = fine_rest.row(i).transpose();
    double best = 1e300;
    for (Index t = 0; t < surface.F.rows(); ++t) {
      const Vec3<> a = surface.V.row(surface.F(t, 0)).transpose(), b = surface.V.row(surface.F(t, 1)).transpose(), c = surface.V.row(surface.F(t, 2)).transpose();
      const Vec3<> w = closest_point_on_triangle(q, a, b, c);
      const double d = (w[0] * a + w[1] * b + w[2] * c - q).norm();
      if (d < best - 1e-14) {
        best = d;
        out.row(i) = w[0] * moved.row(surface.F(t, 0)) + w[1] * moved.row(surface.F(t, 1)) + w[2] * moved.row(surface.F(t, 2));
      }
    }
  }
  return out;
}

TEST_CASE("cloth_pair, a fine sheet of its own (the scale study's ×16 / ×256 beside the default fine cloth): the same fine cloth and pins, the baseline map resampled") {
  const ClothPair standard = cloth_pair(ClothDataset::sheet, default_scene_size(ClothDataset::sheet));
  CHECK(scene_size(ClothDataset::sheet, 16, -1, 8).fine_cells == 8);
  CHECK(scene_size(ClothDataset::sheet, 16, -1).fine_source_cells() == 16);
  // the paper's three: 512 / 128 / 32 coarse faces against the one 8,192-face fine sheet
  for (const Index cells : {16, 8, 4, 2}) {
    CAPTURE(cells);
    const ClothPair p = cloth_pair(ClothDataset::sheet, {cells, 3, 8});
    CHECK(p.coarse.F.rows() == 2 * cells * cells);
    CHECK(p.fine.V == standard.fine.V);  // bitwise: the fine simulation is the default's
    CHECK(p.fine.F == standard.fine.F);
    CHECK((p.fine_pinned.array() == standard.pinned.array()).all());
    CHECK(p.fine_pins_are_coarse_pins() == (cells == 8));
    REQUIRE(p.pinned.size() == 4);
    for (Index a = 0; a < 4; ++a) CHECK((p.fine.V.row(p.fine_pinned[a]) - p.coarse.V.row(p.pinned[a])).norm() == 0);
    REQUIRE(p.subdivision.rows() == 4225);
    REQUIRE(p.subdivision.cols() == p.coarse.V.rows());
    const Eigen::SparseMatrix<double> S = p.subdivision;
    CHECK((Eigen::VectorXd(S * Eigen::VectorXd::Ones(S.cols())).array() - 1).abs().maxCoeff() < 1e-12);  // rows sum to 1
    for (Index k = 0; k < S.outerSize(); ++k)
      for (Eigen::SparseMatrix<double>::InnerIterator it(S, k); it; ++it) CHECK(it.value() >= 0);
    // at rest both are the flat 1 m square: the map gives the fine rest sheet itself
    CHECK((Points<>(S * p.coarse.V) - p.fine.V).cwiseAbs().maxCoeff() < 1e-12);
  }
  CHECK(cloth_pair(ClothDataset::sheet, {8, 3, 8}).subdivision.isApprox(standard.subdivision));  // the same cells: Loop's own map
  // a bent, turned coarse cloth: the map against Loop then a brute-force closest point
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& cells : std::vector<std::array<Index, 3>>{{4, 2, 2}, {2, 4, 1}, {3, 2, 2}, {5, 3, 1}}) {
    const Index coarse_cells = cells[0], fine_cells = cells[1], levels = cells[2];  // (no structured binding: clang's CAPTURE can't name one)
    CAPTURE(coarse_cells);
    CAPTURE(fine_cells);
    const ClothPair p = cloth_pair(ClothDataset::sheet, {coarse_cells, levels, fine_cells});
    Points<> moved = p.coarse.V;
    const double a = u(rng), b = u(rng);
    for (Index i = 0; i < moved.rows(); ++i) moved(i, 2) = 0.2 * std::sin(3 * moved(i, 0) + a) * std::cos(2 * moved(i, 1) + b) + 0.05 * u(rng);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(u(rng) * 3, Vec3<>(u(rng), u(rng), 1).normalized()).toRotationMatrix();
    moved = (moved * R.transpose()).rowwise() + Vec3<>(u(rng), u(rng), u(rng)).transpose();
    const LoopSubdivision sub = loop_subdivision(p.coarse.V, p.coarse.F, shell::detail::loop_levels_to_reach(coarse_cells, fine_cells << levels));
    TriMesh<> surface;
    surface.V = sub.S * p.coarse.V;
    surface.F = sub.F;
    const Points<> expected = resampled_by_brute_force(surface, Points<>(sub.S * moved), p.fine.V);
    CHECK((Points<>(p.subdivision * moved) - expected).cwiseAbs().maxCoeff() < 1e-12);
  }
  CHECK(shell::detail::loop_levels_to_reach(16, 64) == 2);  // the study's ×16 and ×256 inputs
  CHECK(shell::detail::loop_levels_to_reach(4, 64) == 4);
  CHECK(shell::detail::loop_levels_to_reach(3, 64) == 5);  // not a power of two: at least as fine
  CHECK(shell::detail::loop_levels_to_reach(8, 8) == 0);
  CHECK_THROWS_WITH_AS(cloth_pair(ClothDataset::disk, {6, 3, 4}), doctest::Contains("first ring"), ArgumentError);
  CHECK(cloth_pair(ClothDataset::disk, {3, 1, 3}).fine.V == cloth_pair(ClothDataset::disk, {3, 1}).fine.V);  // its own ring count: allowed
  CHECK_THROWS_AS(cloth_pair(ClothDataset::sheet, {4, 1, -1}), ArgumentError);
  CHECK_THROWS_AS(cloth_pair(ClothDataset::sheet, {4, 1, 1}), ArgumentError);
}

TEST_CASE("ClothSimulator on SHEET (reduced: 25 / 81 vertices): a sphere comes down and leaves; pins held, no vertex deep in it, the two resolutions agree") {
  const ClothPair pair = cloth_pair(ClothDataset::sheet, {4, 1});
  SheetSequence seq;
  seq.radius = 0.12;
  seq.centre = Vec3<>(0.05, -0.03, -0.25);
  seq.descent_time = 0.5;
  seq.hold_time = 0.2;
  seq.start_height = 0.7;
  ClothSimulator<physics::Capsule<>> coarse(pair.coarse, pair.pinned, seq.obstacle_at(0));
  ClothSimulator<physics::Capsule<>> fine(pair.fine, pair.pinned, seq.obstacle_at(0));
  auto move = [&](physics::Capsule<>& o, double t) { o = seq.obstacle_at(t); };
  // the coarse cloth again with each step solved to convergence (the default's 8 steps per
  // frame): the inexact steps (at most 3 Newton iterations each, the default) stay within a
  // centimetre of it (3.6 mm measured), the linearized ones (1 iteration, ARCSim's) within 5 cm
  // (2.9 cm): the crash makes any two schemes drift apart
  ClothOptions converged_options;
  converged_options.newton = cloth_newton_options(ClothStepping::converged);
  ClothSimulator<physics::Capsule<>> converged(pair.coarse, pair.pinned, seq.obstacle_at(0), {}, converged_options);
  ClothOptions linearized_options;
  linearized_options.newton = cloth_newton_options(ClothStepping::inexact, 1);
  ClothSimulator<physics::Capsule<>> linearized(pair.coarse, pair.pinned, seq.obstacle_at(0), {}, linearized_options);
  // and, at 2 steps per frame, a run whose Newton solves are cut short: the failed steps are
  // halved, and it follows the converged run of 2 steps per frame (the momentum carried over
  // each shorter step)
  ClothOptions converged_2 = converged_options;
  converged_2.substeps = 2;
  ClothSimulator<physics::Capsule<>> converged_by_2(pair.coarse, pair.pinned, seq.obstacle_at(0), {}, converged_2);
  ClothOptions short_newton = converged_2;
  short_newton.newton.max_iterations = 5;
  ClothSimulator<physics::Capsule<>> halving(pair.coarse, pair.pinned, seq.obstacle_at(0), {}, short_newton);
  Index halvings = 0;
  double halving_gap = 0, inexact_gap = 0, linearized_gap = 0;
  const Index frames = Index(std::ceil(seq.duration() / coarse.options().frame_time));
  double lowest = 0, deepest = 0, worst_gap = 0, largest_motion = 0;
  for (Index f = 0; f < frames; ++f) {
    const ClothFrameReport rc = coarse.advance(exec::omp, move), rf = fine.advance(exec::omp, move);
    converged.advance(exec::seq, move);
    CHECK(linearized.advance(exec::seq, move).newton_iterations == linearized_options.substeps);  // one iteration per step, none halved
    converged_by_2.advance(exec::seq, move);
    halvings += halving.advance(exec::seq, move).halvings;
    halving_gap = std::max(halving_gap, (halving.positions() - converged_by_2.positions()).rowwise().norm().maxCoeff());
    inexact_gap = std::max(inexact_gap, (coarse.positions() - converged.positions()).rowwise().norm().maxCoeff());
    linearized_gap = std::max(linearized_gap, (linearized.positions() - converged.positions()).rowwise().norm().maxCoeff());
    CHECK(rc.newton_iterations <= 3 * coarse.options().substeps);  // the budget of 3 per step, none halved
    CHECK(rc.halvings == 0);
    deepest = std::min({deepest, rc.deepest, rf.deepest});
    lowest = std::min(lowest, fine.positions().col(2).minCoeff());
    const Points<> up = pair.subdivision * coarse.positions();
    worst_gap = std::max(worst_gap, (up - fine.positions()).rowwise().norm().maxCoeff());
    largest_motion = std::max(largest_motion, (fine.positions() - pair.fine.V).rowwise().norm().maxCoeff());
  }
  CHECK(coarse.time() == doctest::Approx(double(frames) * coarse.options().frame_time));
  for (Index k = 0; k < 4; ++k) CHECK((fine.positions().row(pair.pinned[k]) - pair.fine.V.row(pair.pinned[k])).norm() == 0);
  CHECK(lowest < -0.1);        // pushed down by the sphere (it stops 0.13 m below the sheet)
  CHECK(deepest > -0.01);      // the penalty holds every vertex within a centimetre of the surface
  CHECK(worst_gap < 0.5 * largest_motion);  // the same cloth at two resolutions, unconstrained
  CHECK(halvings > 0);
  CHECK(halving_gap < 0.02);
  CHECK(inexact_gap < 0.01);
  CHECK(linearized_gap < 0.05);
  MESSAGE("Newton cut at 5 iterations (2 steps per frame): " << halvings << " steps halved, at most " << halving_gap << " m from the converged run");
  MESSAGE("8 steps per frame, at most from the converged run: inexact (3 iterations) " << inexact_gap << " m, linearized (1) " << linearized_gap
                                                                                       << " m, of " << largest_motion << " m motion");
  MESSAGE("SHEET 25/81: lowest " << lowest << " m, deepest " << deepest << " m, subdivided-coarse to fine gap " << worst_gap << " m of " << largest_motion << " m motion");
}

TEST_CASE("ClothSimulator's linear solver is a type: CHOLMOD steps a sheet into a pole as Eigen's LDLT does, frame after frame, halvings included") {
#if defined(SIMSR_HAVE_CHOLMOD)
  // SHEET at 81 fine vertices, a pole pressed into it: contact, the membrane compressed (its exact
  // Hessian indefinite, so Newton falls back to the projected one) and, with Newton cut at 4
  // iterations, failed steps halved: every path of a step through the solver
  const ClothPair pair = cloth_pair(ClothDataset::sheet, {4, 1});
  SheetSequence seq;
  seq.pole = true;
  seq.radius = 0.04;
  seq.centre = Vec3<>(0.08, 0.02, -0.2);
  seq.heading = 0.4;
  seq.descent_time = 0.4;
  seq.hold_time = 0.1;
  seq.start_height = 0.05;  // touching within the first frames
  auto move = [&](physics::Capsule<>& o, double t) { o = seq.obstacle_at(t); };
  ClothOptions o;
  o.substeps = 2;
  o.newton = cloth_newton_options(ClothStepping::converged);
  o.newton.max_iterations = 4;
  ClothSimulator<physics::Capsule<>> simplicial(pair.fine, pair.pinned, seq.obstacle_at(0), {}, o);
  ClothSimulator<physics::Capsule<>, physics::CholmodCholesky<>> cholmod(pair.fine, pair.pinned, seq.obstacle_at(0), {}, o);
  Index halvings = 0, iterations = 0;
  double worst = 0, motion = 0;
  for (Index f = 0; f < 6; ++f) {
    const ClothFrameReport a = simplicial.advance(exec::omp, move), b = cholmod.advance(exec::omp, move);
    CHECK(a.newton_iterations == b.newton_iterations);
    CHECK(a.halvings == b.halvings);
    halvings += a.halvings;
    iterations += a.newton_iterations;
    worst = std::max(worst, (cholmod.positions() - simplicial.positions()).cwiseAbs().maxCoeff());
    motion = std::max(motion, (simplicial.positions() - pair.fine.V).cwiseAbs().maxCoeff());
  }
  CHECK(halvings > 0);
  CHECK(motion > 0.05);
  // the same steps to the factorizations' round-off (amplified by the halved steps' unconverged
  // solves: 1e-15 m where no step is halved, ~1e-9 m here; a wrong solve would be millimetres off)
  CHECK(worst <= 1e-7 * motion);
  MESSAGE("CHOLMOD vs LDLT over 6 frames (" << iterations << " Newton iterations, " << halvings << " halvings): " << worst << " m apart of " << motion << " m motion");
#else
  SIMSR_MISSING("CHOLMOD: configure with -DSIMSR_WITH_CHOLMOD=ON (apt-get install libsuitesparse-dev) to test ClothSimulator with physics::CholmodCholesky");
#endif
}

TEST_CASE("ClothSimulator on DISK (reduced: 37 vertices): the cloth drapes over the table and the wind pushes it downwind; the centre stays") {
  const ClothPair pair = cloth_pair(ClothDataset::disk, {3, 0});
  REQUIRE(pair.coarse.V.rows() == 37);
  DiskSequence windy;
  windy.speed = 8;
  windy.heading = 0.3;
  windy.gust = 0;
  ClothSimulator<physics::RoundedCylinder<>> calm(pair.coarse, pair.pinned, disk_table()), blown(pair.coarse, pair.pinned, disk_table());
  double deepest = 0;
  for (Index f = 0; f < 30; ++f) {
    calm.advance(exec::seq);
    blown.set_air(windy.air_at(blown.time()));
    deepest = std::min(deepest, blown.advance(exec::omp).deepest);
  }
  CHECK(calm.positions().col(2).minCoeff() < -0.2);  // the rim hangs over the table's edge
  CHECK(deepest > -0.01);
  CHECK((calm.positions().row(0) - pair.coarse.V.row(0)).norm() == 0);
  const Vec3<> downwind(std::cos(0.3), std::sin(0.3), 0);
  const double shift = (blown.positions() - calm.positions()).colwise().mean() * downwind;
  CHECK(shift > 0.01);
  MESSAGE("DISK 37: rim at " << calm.positions().col(2).minCoeff() << " m; the 8 m/s wind moves the cloth " << shift << " m downwind on average");
  // bad input
  CHECK_THROWS_AS(ClothSimulator<physics::RoundedCylinder<>>(pair.coarse, (IndexVector(1) << 99).finished(), disk_table()), MeshError);
  ClothOptions o;
  o.substeps = 0;
  CHECK_THROWS_AS(ClothSimulator<physics::RoundedCylinder<>>(pair.coarse, pair.pinned, disk_table(), {}, o), ArgumentError);
  CHECK(parse_cloth_stepping("converged") == ClothStepping::converged);
  CHECK(parse_cloth_stepping("inexact") == ClothStepping::inexact);
  CHECK(cloth_newton_options(ClothStepping::inexact).max_iterations == 3);
  CHECK(cloth_newton_options(ClothStepping::converged, 7).max_iterations == 7);
  CHECK_THROWS_AS(cloth_newton_options(ClothStepping::inexact, -1), ArgumentError);
  CHECK_THROWS_WITH_AS(parse_cloth_stepping("exact"), doctest::Contains("'exact'"), ArgumentError);
}

}  // namespace shell_test_cloth
