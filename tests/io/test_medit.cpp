#include <doctest/doctest.h>

#include "io_test_support.hpp"

#include <Eigen/Geometry>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <simsr/io/medit.hpp>
#include <simsr/io/msh.hpp>
#include <simsr/io/obj.hpp>
#include <simsr/io/tetgen.hpp>
#include <string>

namespace io_test_medit {

namespace {

namespace fs = std::filesystem;
const fs::path data_dir = simsr::test::io_data_dir;
using simsr::test::expected;

/// expect_parse_error for the in-memory reader, whose source is named "mem.mesh".
void expect_parse_error(const std::function<void()>& f, std::int64_t line, const std::string& part) {
  simsr::test::expect_parse_error(f, "mem.mesh", line, part);
}

void check_against_peer(const std::string& file, const simsr::io::MeditMesh<>& m) {
  INFO(file);
  CHECK(m.V.rows() == expected(file, "nodes"));
  CHECK(m.T.rows() == expected(file, "tets"));
  CHECK(m.F.rows() == expected(file, "tris"));
  double total = 0;
  simsr::Index positive = 0;
  for (simsr::Index t = 0; t < m.T.rows(); ++t) {
    const Eigen::RowVector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)), d = m.V.row(m.T(t, 3));
    const double v = (b - a).dot((c - a).cross(d - a)) / 6;
    total += v;
    positive += v > 0;
  }
  CHECK(total == doctest::Approx(expected(file, "volume")).epsilon(1e-12));
  CHECK(positive == expected(file, "positive_tets"));
  for (int k = 0; k < 3; ++k) {
    CHECK(m.V.col(k).minCoeff() == expected(file, "bbox_min", k));
    CHECK(m.V.col(k).maxCoeff() == expected(file, "bbox_max", k));
  }
}

}  // namespace

TEST_CASE("medit: meshio's and gmsh's files match the peer and the .msh/.node readings") {
  const auto a = simsr::io::read_medit(data_dir / "cube_meshio.mesh");
  const auto b = simsr::io::read_medit(data_dir / "cube_gmsh.mesh");
  check_against_peer("cube_meshio.mesh", a);
  check_against_peer("cube_gmsh.mesh", b);
  CHECK(a.version == 2);
  CHECK(a.skipped.empty());
  // one mesh in five files: msh22, msh41, meshio medit, gmsh medit, meshio tetgen
  const auto m22 = simsr::io::read_msh(data_dir / "cube_msh22.msh");
  const auto m41 = simsr::io::read_msh(data_dir / "cube_msh41.msh");
  const auto tg = simsr::io::read_tetgen(data_dir / "cube_meshio.node");
  for (const auto* m : {&a, &b}) {
    CHECK(m->T == m22.T);
    CHECK(m->F == m22.F);
  }
  CHECK(a.V == m22.V);  // meshio writes 17 significant digits
  CHECK((b.V - m22.V).cwiseAbs().maxCoeff() < 1e-13);  // gmsh's MEDIT writer: 14 digits
  CHECK((b.V - m22.V).cwiseAbs().maxCoeff() > 0);
  CHECK(m41.V == a.V);
  CHECK(tg.V == a.V);
  CHECK(tg.T == a.T);
  CHECK(a.tet_refs == m22.tet_physical);  // meshio keeps gmsh:physical as refs
  CHECK(a.tri_refs == m22.tri_physical);
  CHECK(b.tri_refs == m22.tri_entity);    // gmsh writes the elementary tag
  for (int i = 0; i < 8; ++i) CHECK(b.vertex_refs[static_cast<std::size_t>(i)] == i + 1);  // gmsh: the 8 geometry points
}

TEST_CASE("medit: writer round trips; free format, comments and skipped sections read") {
  auto m = simsr::io::read_medit(data_dir / "cube_gmsh.mesh");
  m.V(0, 0) = 0.1 + 0.2;
  const auto r = simsr::io::read_medit(simsr::io::format_medit(m), "mem.mesh");
  CHECK(r.V == m.V);
  CHECK(r.F == m.F);
  CHECK(r.T == m.T);
  CHECK(r.vertex_refs == m.vertex_refs);
  CHECK(r.tri_refs == m.tri_refs);
  CHECK(r.tet_refs == m.tet_refs);

  fs::create_directories(SIMSR_TEST_TMP_DIR);
  const fs::path file = fs::path(SIMSR_TEST_TMP_DIR) / "w.mesh";
  simsr::io::write_medit(file, m.tet_mesh());
  const auto t = simsr::io::read_medit_tets(file);
  CHECK(t.T == m.T);
  CHECK(t.V == m.V);

  const std::string text =
      "# comment\nMeshVersionFormatted 1\nDimension\n3\nVertices 4\n0 0 0 1  1 0 0 1\n0 1 0 2\n0 0 1 3 # trailing\n"
      "Edges\n1\n1 2 5\nCorners 2 1 2\nNormals\n1\n0 0 1\nTetrahedra\n1\n1 2 3 4 9\nEnd\n";
  const auto s = simsr::io::read_medit<float>(text, "mem.mesh");
  CHECK(s.version == 1);
  CHECK(s.V.rows() == 4);
  CHECK(s.V(3, 2) == 1.0f);
  CHECK(s.vertex_refs == std::vector<int>{1, 1, 2, 3});
  CHECK(s.T.row(0) == Eigen::RowVector4i(0, 1, 2, 3));
  CHECK(s.tet_refs == std::vector<int>{9});
  CHECK(s.skipped.at("Edges") == 1);
  CHECK(s.skipped.at("Corners") == 2);
  CHECK(s.skipped.at("Normals") == 1);
}

TEST_CASE("medit: hostile input is a ParseError at the right line") {
  auto rd = [](std::string s) { return [s] { simsr::io::read_medit(s, "mem.mesh"); }; };
  const std::string head = "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n";  // lines 1..8
  CHECK(simsr::io::read_medit(head + "Tetrahedra\n1\n1 2 3 4 0\nEnd\n", "mem.mesh").T.rows() == 1);
  expect_parse_error(rd(head + "Tetrahedra\n1\n1 2 3 5 0\nEnd\n"), 11, "out of range");
  expect_parse_error(rd(head + "Tetrahedra\n1\n1 2 3 0 0\nEnd\n"), 11, "out of range");
  expect_parse_error(rd(head + "Tetrahedra\n1\n1 2 3 4 0\n"), 11, "End");                  // truncated
  expect_parse_error(rd(head + "Tetrahedra\n2\n1 2 3 4 0\nEnd\n"), 10, "absurd count");      // wrong count
  expect_parse_error(rd(head + "Tetrahedra\n2\n1 2 3 4\n1 2 3 4 0\nEnd\n"), 12, "out of range");  // a missing number shifts the rest
  expect_parse_error(rd(head + "Tetrahedra\n-3\n"), 10, "negative");
  expect_parse_error(rd(head + "Tetrahedra\n123456789012\n"), 10, "absurd count");
  expect_parse_error(rd(head + "Tetrahedra\n1\n1 2 3 4 99999999999\nEnd\n"), 11, "out-of-range reference");
  expect_parse_error(rd(head + "Prisms\n1\n1 2 3 4 1 2 x\nEnd\n"), 11, "malformed");
  expect_parse_error(rd(head + "Bogus\n1\nEnd\n"), 9, "unknown");
  expect_parse_error(rd("MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 nan 0 0\nEnd\n"), 5, "non-finite");
  expect_parse_error(rd("MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 -inf 0 0\nEnd\n"), 5, "non-finite");
  expect_parse_error(rd("MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 1e5e5 0 0\nEnd\n"), 5, "malformed");
  expect_parse_error(rd("MeshVersionFormatted 2\nDimension 2\n"), 2, "only 3-D");
  expect_parse_error(rd("MeshVersionFormatted 2\nDimension 3\nTriangles\n0\nEnd\n"), 3, "before Vertices");
  expect_parse_error(rd("Dimension 3\n"), 1, "MeshVersionFormatted first");
  expect_parse_error(rd(""), 1, "End");
  expect_parse_error(rd(std::string("\x00\x01\x02\x03", 4)), 1, "NUL");
  expect_parse_error(rd(head + "Vertices\n0\nEnd\n"), 9, "second Vertices");
}

}  // namespace io_test_medit
