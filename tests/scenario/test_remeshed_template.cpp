// The SoftDECA template at one surface resolution (remeshed_wrap.hpp, CGAL): the remeshed wrap
// lies on the kit and keeps its parts, its skin follows the kit's expressions exactly (a
// displaced vertex stays on the displaced kit surface), its edges are uniform where the kit's
// span two orders of magnitude, the template is valid, and Newton settles a stiff-bending sample
// that stalls on the kit's own triangles (README, "SoftDECA"). Built in test_cgal.
#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/volume.hpp>
#include <simsr/neighbors/surface_distance.hpp>
#include <simsr/scenario/softdeca/remeshed_wrap.hpp>
#include <simsr/scenario/softdeca/softdeca_simulator.hpp>
#if defined(SIMSR_HAVE_CHOLMOD)
#include <simsr/physics/linear_solvers/cholmod_cholesky.hpp>
#endif

#include <algorithm>
#include <random>
#include <vector>

#include "kit_fixture.hpp"

namespace scenario_test_remeshed_template {

using namespace simsr;

/// The 5th and 95th percentile of the edge lengths of triangles F over V.
std::pair<double, double> edge_percentiles(const Points<>& V, const Tris& F) {
  const Edges e = unique_edges(F);
  std::vector<double> len;
  for (Index k = 0; k < e.rows(); ++k) len.push_back((V.row(e(k, 0)) - V.row(e(k, 1))).norm());
  std::sort(len.begin(), len.end());
  return {len[len.size() / 20], len[len.size() * 19 / 20]};
}

TEST_CASE("remeshed_outer_wrap: on the kit, parts kept, expressions carried exactly, uniform edges") {
  if (!test::have_ict_kit()) {
    SIMSR_MISSING("ICT kit not found in " << test::ict_kit_dir);
    return;
  }
  const auto& kit = test::ict_kit();
  const double edge = 1.0;  // cm
  const scenario::IctOuterWrap source = scenario::ict_outer_wrap(exec::omp, kit);
  const scenario::IctOuterWrap wrap = scenario::remeshed_outer_wrap(exec::omp, kit, edge);
  const Index nv = wrap.mesh.num_vertices();
  MESSAGE("outer wrap: kit " << source.mesh.num_vertices() << " vertices, remeshed to " << edge << " cm: " << nv);
  REQUIRE(Index(wrap.part.size()) == wrap.mesh.F.rows());
  // one open border (the neck), every part still there
  CHECK(boundary_loops(wrap.mesh.F).size() == 1);
  for (auto part : {scenario::HeadPart::skin, scenario::HeadPart::mouth_socket, scenario::HeadPart::eye_socket})
    CHECK(std::count(wrap.part.begin(), wrap.part.end(), part) > 0);

  // uniform edges where the kit's spread (p95/p5 of the skin triangles' edges)
  const auto [k05, k95] = edge_percentiles(source.mesh.V, source.mesh.F);
  const auto [r05, r95] = edge_percentiles(wrap.mesh.V, wrap.mesh.F);
  MESSAGE("edge p5/p95 (cm): kit " << k05 << " / " << k95 << ", remeshed " << r05 << " / " << r95);
  CHECK(r05 > 0.4 * edge);
  CHECK(r95 / r05 < 0.5 * k95 / k05);

  // each vertex on the kit's surface, and displaced with the kit: at random expression weights the
  // displaced vertex lies on the displaced kit wrap (distances by brute-force-free closest point,
  // checked on a sample of vertices)
  const neighbors::SurfaceDistance<> neutral(source.mesh);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  VecX<> w(Index(kit.expression_names.size()));
  for (Index e = 0; e < w.size(); ++e) w[e] = u(rng) < 0.1 ? u(rng) : 0;
  Points<> kit_moved = kit.neutral.V;
  for (Index e = 0; e < w.size(); ++e)
    if (w[e] != 0) kit_moved += w[e] * kit.expression(kit.expression_names[std::size_t(e)]);
  TriMesh<> source_moved = source.mesh;
  for (Index i = 0; i < source.mesh.num_vertices(); ++i) source_moved.V.row(i) = kit_moved.row(source.kit_corners(i, 0));
  const neighbors::SurfaceDistance<> moved(source_moved);
  std::uniform_int_distribution<Index> pick(0, nv - 1);
  for (int s = 0; s < 300; ++s) {
    const Index i = pick(rng);
    CAPTURE(i);
    CHECK(neutral.closest(wrap.mesh.V.row(i).transpose()).distance < 1e-9);
    Vec3<> x = Vec3<>::Zero();
    for (int c = 0; c < 3; ++c) x += wrap.kit_weights(i, c) * kit_moved.row(wrap.kit_corners(i, c)).transpose();
    CHECK(moved.closest(x).distance < 1e-9);
  }
  // the template's expression deltas are these displacements (in metres)
  const scenario::IctTemplate tpl = scenario::softdeca_template(exec::omp, kit, wrap, {});
  const Points<> skin = tpl.expression(w);
  for (int s = 0; s < 300; ++s) {
    const Index k = Index(std::uniform_int_distribution<Index>(0, tpl.skin.size() - 1)(rng));
    CHECK(moved.closest(100.0 * skin.row(k).transpose()).distance < 1e-9);
  }
  CHECK(signed_volumes(exec::omp, tpl.head.mesh.V, tpl.head.mesh.T).minCoeff() > 0);
  CHECK(tpl.head.count(scenario::Bone::cranium) > 0);
  CHECK(tpl.head.count(scenario::Bone::jaw) > 0);

  // a wrap whose arrays disagree or whose kit places are no barycentric points is refused
  scenario::IctOuterWrap bad = wrap;
  bad.part.pop_back();
  CHECK_THROWS_AS(scenario::softdeca_template(exec::omp, kit, bad, {}), ShapeError);
  bad = wrap;
  bad.kit_weights(5, 0) += 0.5;
  CHECK_THROWS_AS(scenario::softdeca_template(exec::omp, kit, bad, {}), ArgumentError);
  bad = wrap;
  bad.kit_corners(7, 2) = VIndex(kit.neutral.num_vertices());
  CHECK_THROWS_AS(scenario::softdeca_template(exec::omp, kit, bad, {}), ArgumentError);
  bad = wrap;
  bad.kit_weights.conservativeResize(nv - 1, 3);
  CHECK_THROWS_AS(scenario::softdeca_template(exec::omp, kit, bad, {}), ShapeError);
}

TEST_CASE("remeshed template: Newton settles a sample whose bending stalls on the kit's triangles, and local-global agrees") {
  if (!test::have_ict_kit()) {
    SIMSR_MISSING("ICT kit not found in " << test::ict_kit_dir);
    return;
  }
  const auto& kit = test::ict_kit();
  const scenario::IctTemplate tpl = scenario::softdeca_template(exec::omp, kit, scenario::remeshed_outer_wrap(exec::omp, kit, 1.2), {});
#if defined(SIMSR_HAVE_CHOLMOD)
  scenario::BasicSoftDecaSimulator<physics::CholmodCholesky<>> sim(tpl);
#else
  scenario::SoftDecaSimulator sim(tpl);
#endif
  // sample 0 of seed 1: bending weight 39.6 (the range's top decade), the skull as in the template
  scenario::SoftDecaParameters p = scenario::sample_softdeca_parameters(1, 0);
  p.cranium_scale = p.jaw_scale = Vec3<>::Ones();
  REQUIRE(p.w_bending > 30);
  sim.prepare(p);
  Points<> x;
  const Index its = sim.settle(exec::omp, x, {.solver = scenario::SoftDecaSolver::newton});
  MESSAGE("remeshed at 1.2 cm: " << tpl.head.mesh.num_vertices() << " vertices, " << tpl.head.mesh.num_tets() << " tets; Newton settled in " << its << " iterations");
  CHECK(its <= 30);
  // the same problem by local-global reaches Newton's equilibrium (both to their gradient
  // tolerance, 1e-6 of the forces): the skins agree to a micrometre
  Points<> y;
  const Index lg_its = sim.settle(exec::omp, y, {.solver = scenario::SoftDecaSolver::local_global});
  double gap = 0;
  for (Index k = 0; k < tpl.skin.size(); ++k) gap = std::max(gap, (x.row(tpl.skin[k]) - y.row(tpl.skin[k])).norm());
  MESSAGE("local-global settled in " << lg_its << " iterations; largest skin difference to Newton " << gap << " m");
  CHECK(gap < 1e-6);
}

}  // namespace scenario_test_remeshed_template
