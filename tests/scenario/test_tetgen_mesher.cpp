// The tetgen program as the HR mesher: a box with a box-shaped cavity, against its exact volume
// and boundary; a missing program and self-intersecting facets are named errors.
#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/quality.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/volume.hpp>
#include <simsr/scenario/tetgen_mesher.hpp>

#include "kit_fixture.hpp"

#include <cstdlib>
#include <filesystem>

using namespace simsr;

namespace {

/// The boundary of an axis-aligned box [lo, hi], 2 triangles per side (8 vertices).
TriMesh<> box_surface(const Vec3<>& lo, const Vec3<>& hi) { return boundary_surface(box_tet_mesh<double>(1, 1, 1, lo, hi)); }

double area(const TriMesh<>& s, const Tris& F) {
  double a = 0;
  for (Index f = 0; f < F.rows(); ++f)
    a += 0.5 * (s.V.row(F(f, 1)) - s.V.row(F(f, 0))).cross(s.V.row(F(f, 2)) - s.V.row(F(f, 0))).norm();
  return a;
}

}  // namespace

TEST_CASE("tetgen_mesh: a box with a cavity, its volume and boundary exact, input vertices first and unmoved") {
  if (!test::have_tetgen()) {
    SIMSR_MISSING("the tetgen program (apt-get install tetgen)");
    return;
  }
  const TriMesh<> outer = box_surface(Vec3<>(0, 0, 0), Vec3<>(4, 3, 2)), inner = box_surface(Vec3<>(1, 1, 0.5), Vec3<>(2.5, 2, 1.5));
  TriMesh<> plc;
  plc.V.resize(outer.V.rows() + inner.V.rows(), 3);
  plc.V << outer.V, inner.V;
  plc.F.resize(outer.F.rows() + inner.F.rows(), 3);
  plc.F << outer.F, (inner.F.array() + VIndex(outer.V.rows())).matrix();
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "tetgen_box";
  const TetMesh<> m = scenario::tetgen_mesh(plc, {Vec3<>(1.7, 1.5, 1.0)}, {.max_volume = 0.05, .radius_edge = 1.5}, dir);
  CHECK(m.V.topRows(plc.V.rows()) == plc.V);
  const VecX<> vol = signed_volumes(exec::seq, m.V, m.T);
  CHECK(vol.minCoeff() > 0);
  CHECK(vol.maxCoeff() <= 0.05 * (1 + 1e-9));
  CHECK(vol.sum() == doctest::Approx(24.0 - 1.5).epsilon(1e-12));
  const Tris B = boundary_faces(m.T);
  CHECK(area(TriMesh<>{m.V, B}, B) == doctest::Approx(2 * (12 + 8 + 6) + 2 * (1.5 + 1.5 + 1.0)).epsilon(1e-12));
  MESSAGE("tetgen: " << m.V.rows() << " nodes, " << m.T.rows() << " tets; files in " << dir);
}

TEST_CASE("tetgen_mesh: a missing program and self-intersecting facets are named errors") {
  if (!test::have_tetgen()) {
    SIMSR_MISSING("the tetgen program (apt-get install tetgen)");
    return;
  }
  const TriMesh<> box = box_surface(Vec3<>(0, 0, 0), Vec3<>(1, 1, 1));
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "tetgen_errors";
  ::setenv("SIMSR_TETGEN", "/nonexistent/tetgen", 1);
  CHECK_THROWS_WITH_AS(scenario::tetgen_mesh(box, {}, {}, dir), doctest::Contains("cannot run '/nonexistent/tetgen'"), ArgumentError);
  ::unsetenv("SIMSR_TETGEN");
  // two boxes overlapping: their facets cross
  const TriMesh<> other = box_surface(Vec3<>(0.5, 0.5, 0.5), Vec3<>(1.5, 1.5, 1.5));
  TriMesh<> plc;
  plc.V.resize(16, 3);
  plc.V << box.V, other.V;
  plc.F.resize(box.F.rows() + other.F.rows(), 3);
  plc.F << box.F, (other.F.array() + 8).matrix();
  CHECK_THROWS_WITH_AS(scenario::tetgen_mesh(plc, {}, {}, dir), doctest::Contains("failed"), Error);
  CHECK_THROWS_AS(scenario::tetgen_mesh(TriMesh<>{}, {}, {}, dir), ArgumentError);
}
