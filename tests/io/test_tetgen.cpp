#include <doctest/doctest.h>

#include "io_test_support.hpp"

#include <Eigen/Geometry>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <simsr/io/msh.hpp>
#include <simsr/io/tetgen.hpp>
#include <string>

namespace io_test_tetgen {

namespace {

namespace fs = std::filesystem;
const fs::path data_dir = simsr::test::io_data_dir;
using simsr::test::expected;

using simsr::test::expect_parse_error;

double signed_volume(const simsr::Points<>& V, const Eigen::RowVector4i& t) {
  const Eigen::RowVector3d a = V.row(t[0]), b = V.row(t[1]), c = V.row(t[2]), d = V.row(t[3]);
  return (b - a).dot((c - a).cross(d - a)) / 6;
}

void check_against_peer(const std::string& file, const simsr::io::TetgenMesh<>& m) {
  INFO(file);
  CHECK(m.V.rows() == expected(file, "nodes"));
  CHECK(m.T.rows() == expected(file, "tets"));
  double total = 0;
  simsr::Index positive = 0;
  for (simsr::Index t = 0; t < m.T.rows(); ++t) {
    const double v = signed_volume(m.V, m.T.row(t));
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

TEST_CASE("tetgen: files from tetgen and meshio match the peer; orientation as documented") {
  for (const char* p : {"cube.1.node", "cube.1.ele", "cube.1.face", "cube.1"}) {
    const auto m = simsr::io::read_tetgen(data_dir / p);
    CHECK(m.first_index == 1);
    CHECK(m.has_faces);
    CHECK(m.T.rows() == 153);
  }
  const auto m = simsr::io::read_tetgen(data_dir / "cube.1.ele");
  check_against_peer("cube.1.node", m);
  // TetGen's boundary faces point inward; tetgen_faces_outward flips them.
  REQUIRE(m.F.rows() == 144);
  CHECK(m.face_markers.size() == 144);
  const Eigen::RowVector3d centre(0.5, 0.5, 0.5);
  const simsr::Tris out = simsr::io::tetgen_faces_outward(m);
  for (simsr::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::RowVector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    CHECK((b - a).cross(c - a).dot((a + b + c) / 3 - centre) < 0);
    const Eigen::RowVector3d p = m.V.row(out(f, 1)), q = m.V.row(out(f, 2));
    CHECK((p - a).cross(q - a).dot((a + p + q) / 3 - centre) > 0);
  }

  // 0-based, 10-node tets and 6-node faces (tetgen -pza0.2o2)
  const auto z = simsr::io::read_tetgen(data_dir / "cubez.1.node");
  CHECK(z.first_index == 0);
  CHECK(z.tet_edge_nodes.cols() == 6);
  CHECK(expected("cubez.1.node", "nodes_per_tet") == 10);
  check_against_peer("cubez.1.node", z);
  CHECK(z.F.rows() == expected("cubez.1.node", "tris"));
  // each mid-edge node sits at the midpoint of its corners (TetGen's edge order 01 12 20 30 31 32... checked loosely)
  for (simsr::Index t = 0; t < z.T.rows(); ++t)
    for (int k = 0; k < 6; ++k) {
      const Eigen::RowVector3d p = z.V.row(z.tet_edge_nodes(t, k));
      bool midpoint = false;
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) midpoint |= (p - (z.V.row(z.T(t, a)) + z.V.row(z.T(t, b))) / 2).norm() < 1e-12;
      CHECK(midpoint);
    }

  // meshio wrote the gmsh cube 0-based: identical to the .msh reading
  const auto mio = simsr::io::read_tetgen(data_dir / "cube_meshio.node");
  check_against_peer("cube_meshio.node", mio);
  CHECK_FALSE(mio.has_faces);
  CHECK(mio.first_index == 0);
  const auto msh = simsr::io::read_msh(data_dir / "cube_msh22.msh");
  CHECK(mio.V == msh.V);
  CHECK(mio.T == msh.T);
}

TEST_CASE("tetgen: writer round trips attributes, markers, 10-node tets and both bases") {
  auto m = simsr::io::read_tetgen(data_dir / "cubez.1.node");
  m.node_attributes.setRandom(m.V.rows(), 2);
  m.node_markers.assign(static_cast<std::size_t>(m.V.rows()), 7);
  m.tet_attributes.setRandom(m.T.rows(), 1);
  for (int base : {0, 1}) {
    m.first_index = base;
    const auto t = simsr::io::format_tetgen(m);
    const auto r = simsr::io::read_tetgen(t.node, t.ele, t.face, "mem");
    CHECK(r.first_index == base);
    CHECK(r.V == m.V);
    CHECK(r.T == m.T);
    CHECK(r.tet_edge_nodes == m.tet_edge_nodes);
    CHECK(r.F == m.F);
    CHECK(r.face_markers == m.face_markers);
    CHECK(r.node_attributes == m.node_attributes);
    CHECK(r.node_markers == m.node_markers);
    CHECK(r.tet_attributes == m.tet_attributes);
  }
  fs::create_directories(SIMSR_TEST_TMP_DIR);
  const fs::path stem = fs::path(SIMSR_TEST_TMP_DIR) / "written";
  fs::remove(fs::path(stem) += ".face");
  simsr::io::write_tetgen(fs::path(stem) += ".ele", m.tet_mesh());
  const auto back = simsr::io::read_tetgen(stem);
  CHECK(back.V == m.V);
  CHECK(back.T == m.T);
  CHECK_FALSE(back.has_faces);
  CHECK(back.first_index == 1);
}

TEST_CASE("tetgen: hostile input is a ParseError naming file and line") {
  using simsr::io::read_tetgen;
  const std::string node = "# c\n4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";  // nodes on lines 3..6
  const std::string ele = "1 4 0\n1 1 2 3 4\n";
  auto rd = [](std::string n, std::string e, std::optional<std::string> f = std::nullopt) {
    return [=] { read_tetgen(n, e, f ? std::optional<std::string_view>(*f) : std::nullopt, "mem"); };
  };
  CHECK(read_tetgen(node, ele, std::nullopt, "mem").T.row(0) == Eigen::RowVector4i(0, 1, 2, 3));
  CHECK(read_tetgen(node, "1 4 0\n1 1 2 3 4", std::nullopt, "mem").T.rows() == 1);  // no final newline
  expect_parse_error(rd(node, "1 4 0\n1 1 2 3 5\n"), "mem.ele", 2, "out of range");
  expect_parse_error(rd(node, "1 4 0\n1 0 2 3 4\n"), "mem.ele", 2, "out of range");
  expect_parse_error(rd(node, "2 4 0\n1 1 2 3 4\n"), "mem.ele", 1, "truncated");
  expect_parse_error(rd(node, "2 4 0\n1 1 2 3 4\n2 1 2 3 4\n3 1 2 3 4\n"), "mem.ele", 4, "unexpected content");
  expect_parse_error(rd(node, "1 4 0\n1 1 2 3      \n"), "mem.ele", 2, "needs 5 numbers");
  expect_parse_error(rd(node, "1 8 0\n1 1 2 3 4\n"), "mem.ele", 1, "4 or 10");
  expect_parse_error(rd(node, "-1 4 0\n"), "mem.ele", 1, "negative");
  expect_parse_error(rd(node, "1 4 0\n7 1 2 3 4\n"), "mem.ele", 2, "consecutive");
  expect_parse_error(rd(node, "1 4 99999999999\n1 1 2 3 4\n"), "mem.ele", 1, "absurd");
  expect_parse_error(rd("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1e400\n", ele), "mem.node", 5, "non-finite");
  expect_parse_error(rd("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 -nan\n", ele), "mem.node", 5, "non-finite");
  expect_parse_error(rd("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1,5\n", ele), "mem.node", 5, "malformed");
  expect_parse_error(rd("4 3 0 0\n2 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", ele), "mem.node", 2, "0 or 1");
  expect_parse_error(rd("4 3 0 0\n1 0 0 0\n3 1 0 0\n3 0 1 0\n4 0 0 1\n", ele), "mem.node", 3, "consecutive");
  expect_parse_error(rd("4 3 0 0\n1 0 0 0\n3 1 0 0\n", ele), "mem.node", 1, "truncated");
  expect_parse_error(rd("4 2 0 0\n", ele), "mem.node", 1, "3-D");
  expect_parse_error(rd("4 3 0 2\n", ele), "mem.node", 1, "marker flag");
  expect_parse_error(rd("4 3 0 0 9\n", ele), "mem.node", 1, "at most 4");
  expect_parse_error(rd("9223372036854775807 3 0 0\n1 0 0 0\n", ele), "mem.node", 1, "absurd");
  expect_parse_error(rd("1 3 9223372036854775807 0\n1 0 0 0\n", ele), "mem.node", 1, "absurd");
  expect_parse_error(rd("", ele), "mem.node", 1, "end of file");
  expect_parse_error(rd(node, ele, "1 1\n1 1 2 3\n"), "mem.face", 2, "face line needs");
  expect_parse_error(rd(node, ele, "1 1\n1 1 2 9 0\n"), "mem.face", 2, "out of range");
  expect_parse_error(rd(node, ele, "2 0\n1 1 2 3\n2 1 2 3 4 5 6 7\n"), "mem.face", 3, "earlier lines had");
  expect_parse_error(rd(node, ele, "1 1\n1 1 2 3 0 1 5\n"), "mem.face", 2, "adjacent tet 5");
  CHECK(read_tetgen(node, ele, "1 1\n1 1 2 3 0 1 -1\n", "mem").F.rows() == 1);  // tetgen -nn
  CHECK_THROWS_AS(simsr::io::read_tetgen(fs::path("/nonexistent/a.node")), simsr::ParseError);
}

}  // namespace io_test_tetgen
