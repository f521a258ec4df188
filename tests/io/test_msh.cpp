#include <doctest/doctest.h>

#include "io_test_support.hpp"

#include <Eigen/Geometry>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <simsr/io/detail/text_reader.hpp>
#include <simsr/io/msh.hpp>
#include <string>

namespace io_test_msh {

namespace {

namespace fs = std::filesystem;
using simsr::io::MshVersion;

const fs::path data_dir = simsr::test::io_data_dir;
using simsr::test::expected;

/// expect_parse_error for the in-memory reader, whose source is named "any file".
void expect_parse_error(const std::function<void()>& f, std::int64_t line, const std::string& part) {
  simsr::test::expect_parse_error(f, "", line, part);
}

template <class S>
double total_volume(const simsr::Points<S>& V, const simsr::Tets& T, simsr::Index* positive = nullptr) {
  double total = 0;
  if (positive) *positive = 0;
  for (simsr::Index t = 0; t < T.rows(); ++t) {
    const Eigen::RowVector3d a = V.row(T(t, 0)).template cast<double>(), b = V.row(T(t, 1)).template cast<double>(),
                             c = V.row(T(t, 2)).template cast<double>(), d = V.row(T(t, 3)).template cast<double>();
    const double v = (b - a).dot((c - a).cross(d - a)) / 6;
    total += v;
    if (positive && v > 0) ++*positive;
  }
  return total;
}

/// Compares a reader's result with meshio's numbers for `file`.
template <class S>
void check_against_peer(const std::string& file, const simsr::Points<S>& V, const simsr::Tets& T, simsr::Index tris) {
  INFO(file);
  CHECK(V.rows() == expected(file, "nodes"));
  CHECK(T.rows() == expected(file, "tets"));
  if (tris >= 0) CHECK(tris == expected(file, "tris"));
  for (int k = 0; k < 3; ++k) {
    CHECK(V.col(k).minCoeff() == doctest::Approx(expected(file, "bbox_min", k)));
    CHECK(V.col(k).maxCoeff() == doctest::Approx(expected(file, "bbox_max", k)));
  }
  simsr::Index positive = 0;
  CHECK(total_volume(V, T, &positive) == doctest::Approx(expected(file, "volume")).epsilon(1e-12));
  CHECK(positive == expected(file, "positive_tets"));
}

std::string msh22(const std::string& nodes, const std::string& elements) {
  return "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" + nodes + "$EndNodes\n$Elements\n" + elements + "$EndElements\n";
}

}  // namespace

TEST_CASE("msh: gmsh 2.2 and 4.1 files agree with meshio and with each other") {
  const auto a = simsr::io::read_msh(data_dir / "cube_msh22.msh");
  const auto b = simsr::io::read_msh(data_dir / "cube_msh41.msh");
  CHECK(a.version == MshVersion::v22);
  CHECK(b.version == MshVersion::v41);
  check_against_peer("cube_msh22.msh", a.V, a.T, a.F.rows());
  check_against_peer("cube_msh41.msh", b.V, b.T, b.F.rows());
  CHECK(a.V == b.V);
  CHECK(a.T == b.T);
  CHECK(a.F == b.F);
  CHECK(a.node_tags == b.node_tags);
  CHECK(a.num_skipped() == 0);
  CHECK(b.num_skipped() == 0);
  // physical groups of cube.geo: volume "solid" 10, "bottom" 1, "sides" 2
  REQUIRE(b.physical_names.size() == 3);
  CHECK(b.physical_names[2] == simsr::io::MshPhysicalName{3, 10, "solid"});
  CHECK(a.physical_names == b.physical_names);
  CHECK(std::all_of(a.tet_physical.begin(), a.tet_physical.end(), [](int p) { return p == 10; }));
  CHECK(a.tet_physical == b.tet_physical);
  CHECK(a.tet_entity == b.tet_entity);
  CHECK(a.tri_physical == b.tri_physical);
  CHECK(a.tri_entity == b.tri_entity);
  // the bottom (z = 0) triangles are exactly those of physical group 1
  for (simsr::Index f = 0; f < a.F.rows(); ++f) {
    const bool bottom = a.V(a.F(f, 0), 2) == 0 && a.V(a.F(f, 1), 2) == 0 && a.V(a.F(f, 2), 2) == 0;
    CHECK(bottom == (a.tri_physical[f] == 1));
  }
  const auto t = simsr::io::read_msh_tets<float>(data_dir / "cube_msh41.msh");
  CHECK(t.T == a.T);
  CHECK(t.V.cast<double>().isApprox(a.V, 1e-6));
}

TEST_CASE("msh: other element types are skipped and counted, parametric nodes read") {
  const auto all41 = simsr::io::read_msh(data_dir / "cube_msh41_all.msh");
  const auto all22 = simsr::io::read_msh(data_dir / "cube_msh22_all.msh");
  const std::string f = "cube_msh41_all.msh";
  for (const auto* m : {&all41, &all22}) {
    CHECK(m->V.rows() == expected(f, "nodes"));
    CHECK(m->T.rows() == expected(f, "element_types/4"));
    CHECK(m->F.rows() == expected(f, "element_types/2"));
    CHECK(m->skipped.size() == 2);
    CHECK(m->skipped.at(1) == expected(f, "element_types/1"));
    CHECK(m->skipped.at(15) == expected(f, "element_types/15"));
  }
  check_against_peer("cube_msh22_all.msh", all22.V, all22.T, all22.F.rows());
  CHECK(all41.T == all22.T);
  // without physical groups saved, elements without one get physical 0 in 4.1 (-save_all)
  CHECK(std::count(all41.tri_physical.begin(), all41.tri_physical.end(), 0) == 0);

  const auto param = simsr::io::read_msh(data_dir / "cube_msh41_param.msh");
  const auto plain = simsr::io::read_msh(data_dir / "cube_msh41.msh");
  CHECK(param.V == plain.V);
  CHECK(param.T == plain.T);

  const auto o2 = simsr::io::read_msh(data_dir / "cube_o2_msh41.msh");
  CHECK(o2.V.rows() == expected("cube_o2_msh41.msh", "nodes"));
  CHECK(o2.T.rows() == 0);
  CHECK(o2.skipped.at(11) == expected("cube_o2_msh41.msh", "element_types/tetra10"));
  CHECK(o2.skipped.at(9) == expected("cube_o2_msh41.msh", "element_types/triangle6"));

  expect_parse_error([] { simsr::io::read_msh(data_dir / "cube_bin.msh"); }, 2, "binary .msh is not supported");
}

TEST_CASE("msh: writers round trip both versions exactly") {
  auto m = simsr::io::read_msh(data_dir / "cube_msh41.msh");
  // non-contiguous, huge node tags survive
  for (std::size_t i = 0; i < m.node_tags.size(); ++i) m.node_tags[i] = 1000000000000LL + 7 * static_cast<std::int64_t>(i);
  m.V(3, 0) = 1.0 / 3.0;
  for (auto v : {MshVersion::v22, MshVersion::v41}) {
    const auto r = simsr::io::read_msh(simsr::io::format_msh(m, v), "mem.msh");
    CHECK(r.version == v);
    CHECK(r.V == m.V);
    CHECK(r.T == m.T);
    CHECK(r.F == m.F);
    CHECK(r.node_tags == m.node_tags);
    CHECK(r.tet_physical == m.tet_physical);
    CHECK(r.tri_physical == m.tri_physical);
    CHECK(r.tri_entity == m.tri_entity);
    CHECK(r.physical_names == m.physical_names);
  }
  fs::create_directories(SIMSR_TEST_TMP_DIR);
  const fs::path file = fs::path(SIMSR_TEST_TMP_DIR) / "tets.msh";
  simsr::TetMesh<> tm{m.V, m.T};
  simsr::io::write_msh(file, tm, MshVersion::v22, &m.F);
  const auto back = simsr::io::read_msh(file);
  CHECK(back.T == m.T);
  CHECK(back.F == m.F);
  CHECK(std::all_of(back.tet_entity.begin(), back.tet_entity.end(), [](int e) { return e == 1; }));

  auto bad = m;
  bad.tet_physical[5] = 99;  // one entity, two physical tags: not expressible in 4.1
  CHECK_THROWS_AS(simsr::io::format_msh(bad, MshVersion::v41), simsr::MeshError);
  CHECK_NOTHROW(simsr::io::format_msh(bad, MshVersion::v22));
  bad = m;
  bad.node_tags[1] = bad.node_tags[0];
  CHECK_THROWS_AS(simsr::io::format_msh(bad), simsr::ArgumentError);
  bad = m;
  bad.T(0, 0) = static_cast<simsr::VIndex>(m.V.rows());
  CHECK_THROWS_AS(simsr::io::format_msh(bad), simsr::MeshError);
}

TEST_CASE("msh: hostile input is a ParseError at the right line") {
  using simsr::io::read_msh;
  auto rd = [](std::string s) { return [s] { read_msh(s, "mem.msh"); }; };
  const std::string nodes = "4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n10 0 0 1\n";  // lines 5..9 (count at 5)
  const std::string tet = "1\n1 4 2 7 1 1 2 3 10\n";  // lines 12..13 ($EndNodes 10, $Elements 11)
  CHECK(read_msh(msh22(nodes, tet), "mem.msh").T.row(0) == Eigen::RowVector4i(0, 1, 2, 3));

  expect_parse_error(rd(msh22(nodes, "1\n1 4 2 7 1 1 2 3 11\n")), 13, "undefined node tag 11");
  expect_parse_error(rd(msh22(nodes, "1\n1 4 2 7 1 1 2 3\n")), 13, "needs 4 nodes");
  expect_parse_error(rd(msh22(nodes, "1\n1 4 6 7 1 1 2 3\n")), 13, "declares 6 tags");
  expect_parse_error(rd(msh22(nodes, "1\n1 4 2 3000000000 1 1 2 3 10\n")), 13, "out-of-range");
  expect_parse_error(rd(msh22(nodes, "2\n1 4 2 7 1 1 2 3 10\n")), 14, "element line needs");  // wrong count
  expect_parse_error(rd(msh22(nodes, "-1\n")), 12, "negative count");
  expect_parse_error(rd(msh22("999999999999\n", "0\n")), 5, "truncated file or absurd count");
  expect_parse_error(rd(msh22("5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n10 0 0 1\n", tet)), 10, "node line needs");
  expect_parse_error(rd(msh22("4\n1 0 0 0\n2 1 nan 0\n3 0 1 0\n10 0 0 1\n", tet)), 7, "non-finite");
  expect_parse_error(rd(msh22("4\n1 0 0 0\n2 1 1.0.0 0\n3 0 1 0\n10 0 0 1\n", tet)), 7, "malformed");
  expect_parse_error(rd(msh22("4\n1 0 0 0\n2 1 0 0\n2 0 1 0\n10 0 0 1\n", tet)), 9, "defined twice");
  expect_parse_error(rd(msh22("1\n99999999999999999999 0 0 0\n", "0\n")), 6, "node tag");
  expect_parse_error(rd(msh22("1\n0 0 0 0\n", "0\n")), 6, "not positive");
  // a huge but valid tag takes the hashed path
  const auto huge = read_msh(msh22("2\n9223372036854775807 0 0 0\n1 1 0 0\n", "1\n1 1 2 0 1 1 9223372036854775807\n"), "mem.msh");
  CHECK(huge.node_tags[0] == 9223372036854775807LL);
  CHECK(huge.skipped.at(1) == 1);

  const std::string full = msh22(nodes, tet);
  expect_parse_error(rd(full.substr(0, full.find("3 0 1 0"))), 5, "truncated file");  // the count check fires first
  expect_parse_error(rd(full.substr(0, full.find("$EndNodes"))), 9, "unexpected end of file");
  expect_parse_error(rd(full.substr(0, full.find("$EndElements"))), 13, "$EndElements");
  expect_parse_error(rd("$Nodes\n0\n$EndNodes\n"), 1, "$MeshFormat");
  expect_parse_error(rd("$MeshFormat\n4 0 8\n$EndMeshFormat\n"), 2, "unsupported .msh version");
  expect_parse_error(rd("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$NodeData\n1\n"), 4, "no $EndNodeData");
  expect_parse_error(rd("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"), 3, "$Nodes");
  expect_parse_error(rd("hello\n"), 1, "section header");
  expect_parse_error(rd("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 solid\n$EndPhysicalNames\n"), 6, "double quotes");

  // 4.1 block structure
  const std::string head = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  const std::string n41 = "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n";  // lines 4..15
  CHECK(read_msh(head + n41 + "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n", "mem.msh").T.rows() == 1);
  expect_parse_error(rd(head + n41 + "$Elements\n1 1 1 1\n2 1 4 1\n1 1 2 3 4\n$EndElements\n"), 18, "dimension 3, block says 2");
  expect_parse_error(rd(head + n41 + "$Elements\n1 2 1 2\n3 1 4 1\n1 1 2 3 4\n$EndElements\n"), 19, "header declares 2");
  expect_parse_error(rd(head + n41 + "$Elements\n1 1 1 1\n3 1 4 2\n1 1 2 3 4\n$EndElements\n"), 18, "more than the declared");
  expect_parse_error(rd(head + "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0 7\n0 0 1\n$EndNodes\n"), 13, "need 3 numbers");
  expect_parse_error(rd(head + "$Nodes\n1 4 1 4\n3 1 0 5\n1\n2\n3\n4\n5\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"), 6, "more than the declared");
  expect_parse_error(rd(head + "$Nodes\n1 400000000 1 4\n"), 5, "absurd count");
  expect_parse_error(rd(head + "$Entities\n0 0 0 1\n1 0 0 0 1 1 1 2 5\n$EndEntities\n"), 6, "physical tags");
}

}  // namespace io_test_msh
