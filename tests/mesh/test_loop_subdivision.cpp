#include <doctest/doctest.h>

#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/loop_subdivision.hpp>
#include <simsr/mesh/normals.hpp>
#include <simsr/mesh/topology.hpp>

#include <cmath>
#include <numbers>

namespace mesh_test_loop_subdivision {

using namespace simsr;

TEST_CASE("loop_subdivision: the 81-vertex sheet to 4,225 vertices and 8,192 triangles, flat, corners kept, rows summing to 1") {
  const TriMesh<> sheet = square_sheet(1.0, 8);
  const LoopSubdivision sub = loop_subdivision(sheet.V, sheet.F, 3);
  CHECK(sub.S.rows() == 4225);
  CHECK(sub.S.cols() == 81);
  CHECK(sub.F.rows() == 8192);
  const Points<> fine = sub.S * sheet.V;
  CHECK(fine.col(2).cwiseAbs().maxCoeff() == 0.0);
  CHECK(fine.leftCols(2).minCoeff() >= 0.0);
  CHECK(fine.leftCols(2).maxCoeff() <= 1.0);
  for (const Index corner : {0, 8, 72, 80}) CHECK((fine.row(corner) - sheet.V.row(corner)).norm() == 0.0);
  const Eigen::VectorXd sums = sub.S * Eigen::VectorXd::Ones(81);
  CHECK((sums.array() - 1).abs().maxCoeff() < 1e-14);
  CHECK(boundary_loops(sub.F).size() == 1);
  for (Index f = 0; f < sub.F.rows(); ++f) {  // orientation kept: every fine triangle counter-clockwise from +z
    const Vec3<> p = fine.row(sub.F(f, 0)), q = fine.row(sub.F(f, 1)), r = fine.row(sub.F(f, 2));
    CHECK((q - p).cross(r - p)[2] > 0);
  }
  // without corners the boundary is smoothed: the corner moves inward
  const LoopSubdivision round = loop_subdivision(sheet.V, sheet.F, 1, {.corner_degrees = 180});
  const Points<> r1 = round.S * sheet.V;
  CHECK(r1.row(0).norm() > 0.0);
}

TEST_CASE("loop_subdivision: closed icosphere: counts, the stencils of valence 5 and 6, outward orientation kept") {
  const TriMesh<> ico = icosphere(1, 1.0);  // valence 5 (the 12 originals) and 6
  const Index E = unique_edges(ico.F).rows();
  const LoopSubdivision sub = loop_subdivision(ico.V, ico.F, 1);
  CHECK(sub.S.rows() == ico.V.rows() + E);
  CHECK(sub.F.rows() == 4 * ico.F.rows());
  const Adjacency A = vertex_adjacency(ico.F, ico.V.rows());
  for (Index v = 0; v < ico.V.rows(); ++v) {
    const double k = double(A.degree(v));
    const double beta = (5.0 / 8.0 - std::pow(3.0 / 8.0 + std::cos(2 * std::numbers::pi / k) / 4.0, 2)) / k;
    CHECK(sub.S.coeff(v, v) == doctest::Approx(1 - k * beta).epsilon(1e-14));
    for (const VIndex w : A[v]) CHECK(sub.S.coeff(v, w) == doctest::Approx(beta).epsilon(1e-14));
    if (k == 6) CHECK(sub.S.coeff(v, v) == doctest::Approx(10.0 / 16.0).epsilon(1e-14));
  }
  const Points<> fine = sub.S * ico.V;
  const Points<> N = face_normals(exec::seq, fine, sub.F);
  for (Index f = 0; f < sub.F.rows(); ++f) {
    const Vec3<> c = (fine.row(sub.F(f, 0)) + fine.row(sub.F(f, 1)) + fine.row(sub.F(f, 2))) / 3.0;
    CHECK(N.row(f).dot(c) > 0);  // outward on a convex surface around the origin
  }
}

TEST_CASE("loop_subdivision: bad input is a typed error") {
  const TriMesh<> sheet = square_sheet(1.0, 2);
  CHECK_THROWS_AS(loop_subdivision(sheet.V, sheet.F, -1), ArgumentError);
  Tris fin(3, 3);  // three triangles on one edge
  fin << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  Points<> V = Points<>::Random(5, 3);
  CHECK_THROWS_AS(loop_subdivision(V, fin, 1), MeshError);
  Tris out_of_range = sheet.F;
  out_of_range(0, 0) = 99;
  CHECK_THROWS_AS(loop_subdivision(sheet.V, out_of_range, 1), MeshError);
}

}  // namespace mesh_test_loop_subdivision
