#include <doctest/doctest.h>

#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/prism_shell.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/volume.hpp>

#include <random>

namespace mesh_test_prism_shell {

using namespace simsr;

/// Enclosed volume of a closed, outward-oriented triangle surface (divergence theorem).
double enclosed(const Points<>& V, const Tris& F) {
  double v = 0;
  for (Index f = 0; f < F.rows(); ++f) v += V.row(F(f, 0)).dot(V.row(F(f, 1)).cross(V.row(F(f, 2)))) / 6;
  return v;
}

TEST_CASE("prism_shell: nested spheres of one topology give a conforming, positive shell of the exact polyhedral volume") {
  const auto outer = icosphere<double>(2, 1.0);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(0.95, 1.05);
  // wraps: the sphere and two inner copies, radii jittered per vertex (not concentric copies)
  std::vector<Points<>> wraps{outer.V, outer.V, outer.V};
  for (Index i = 0; i < outer.V.rows(); ++i) {
    wraps[1].row(i) *= 0.8 * u(rng);
    wraps[2].row(i) *= 0.5 * u(rng);
  }
  const auto shell = prism_shell(exec::omp, outer.F, wraps);
  CHECK(shell.mesh.num_tets() == 3 * 2 * outer.F.rows());
  CHECK(shell.wrap_vertices == outer.V.rows());
  CHECK(signed_volumes(exec::seq, shell.mesh.V, shell.mesh.T).minCoeff() > 0);
  CHECK(total_volume(exec::seq, shell.mesh.V, shell.mesh.T) ==
        doctest::Approx(enclosed(wraps[0], outer.F) - enclosed(wraps[2], outer.F)).epsilon(1e-12));
  // conforming: the only boundary faces are the outer and the innermost wrap's triangles
  CHECK(boundary_faces(shell.mesh.T).rows() == 2 * outer.F.rows());
  for (Index t = 0; t < shell.mesh.num_tets(); ++t) CHECK(shell.tet_layer[t] == (t < 3 * outer.F.rows() ? 0 : 1));
  // seq == omp
  const auto again = prism_shell(exec::seq, outer.F, wraps);
  CHECK(again.mesh.T == shell.mesh.T);
}

TEST_CASE("prism_shell: a folded prism is named; folded_prisms lists exactly the triangles around the fold") {
  const auto outer = icosphere<double>(1, 1.0);
  std::vector<Points<>> wraps{outer.V, 0.6 * outer.V};
  const auto none = folded_prisms(exec::seq, outer.F, wraps);
  CHECK(std::count(none.begin(), none.end(), 1) == 0);
  wraps[1].row(5) = 1.3 * outer.V.row(5);  // inner vertex 5 pushed outside the outer wrap
  const auto bad = folded_prisms(exec::omp, outer.F, wraps);
  for (Index f = 0; f < outer.F.rows(); ++f) {
    const bool at5 = outer.F(f, 0) == 5 || outer.F(f, 1) == 5 || outer.F(f, 2) == 5;
    CHECK(bool(bad[std::size_t(f)]) == at5);
  }
  CHECK_THROWS_WITH_AS(prism_shell(exec::seq, outer.F, wraps), doctest::Contains("is folded"), MeshError);
  CHECK_THROWS_AS(prism_shell(exec::seq, outer.F, std::vector<Points<>>{outer.V}), ArgumentError);
  CHECK_THROWS_AS(prism_shell(exec::seq, outer.F, std::vector<Points<>>{outer.V, outer.V.topRows(3)}), ShapeError);
}

}  // namespace mesh_test_prism_shell
