#include <doctest/doctest.h>
#include "../support/require.hpp"

#include "io_test_support.hpp"

#include <Eigen/Geometry>
#include <filesystem>
#include <functional>
#include <simsr/io/obj.hpp>
#include <string>

namespace io_test_obj {

namespace {

namespace fs = std::filesystem;

/// expect_parse_error for the in-memory reader, whose source is named "mem.obj".
void expect_parse_error(const std::function<void()>& f, std::int64_t line, const std::string& part) {
  simsr::test::expect_parse_error(f, "mem.obj", line, part);
}

template <class S>
S signed_volume(const simsr::TetMesh<S>& m, simsr::Index t) {
  const auto a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)), d = m.V.row(m.T(t, 3));
  return (b - a).dot((c - a).cross(d - a)) / 6;
}

fs::path tmp_dir() {
  fs::path p(SIMSR_TEST_TMP_DIR);
  fs::create_directories(p);
  return p;
}

}  // namespace

TEST_CASE("obj: vertices, all face corner forms, relative indices, ignored statements, CRLF") {
  const std::string text =
      "# header\r\n"
      "mtllib a.mtl\r\n"
      "o thing\r\n"
      "v 0 0 0\r\n"
      "v 1 0 0 1.0\r\n"
      "v 1 1 0 0.5 0.5 0.5\r\n"
      "v 0 1 +0e0\n"
      "vt 0 0\nvn 0 0 1\ng grp\ns off\nusemtl m\n"
      "f 1 2 3 4\n"
      "f 1/1 2/1 3/1\n"
      "f 1/1/1 2/1/1 3/1/1   # trailing comment\n"
      "f 1//1 3//1 4//1\n"
      "f -4 -3 -2\n"
      "\n   \n";
  const auto m = simsr::io::read_obj(text, "mem.obj");
  REQUIRE(m.num_vertices() == 4);
  REQUIRE(m.num_faces() == 5);
  CHECK(m.V(2, 1) == 1.0);
  CHECK(m.V(3, 2) == 0.0);
  CHECK(m.face_size(0) == 4);
  CHECK(std::vector<simsr::VIndex>(m.indices.begin() + 13, m.indices.end()) == std::vector<simsr::VIndex>{0, 1, 2});
  CHECK(m.indices[10] == 0);
  CHECK(m.indices[12] == 3);

  const auto tri = simsr::io::read_obj_triangles(text, "mem.obj");
  CHECK(tri.num_faces() == 6);  // the quad fans into 2
  CHECK(tri.F.row(0) == Eigen::RowVector3i(0, 1, 2));
  CHECK(tri.F.row(1) == Eigen::RowVector3i(0, 2, 3));
  CHECK_FALSE(simsr::io::is_tet_soup(m));

  const auto f = simsr::io::read_obj<float>(text, "mem.obj");
  CHECK(f.V(1, 0) == 1.0f);
}

TEST_CASE("obj: polygon and triangle writers round trip exactly") {
  simsr::PolyMesh<> p;
  p.V.resize(5, 3);
  p.V << 0.1, 0.2, 0.3, 1e-300, -2.5e17, 3.0, 1.0 / 3.0, 2.0 / 3.0, 0.7, -0.0, 5, 6, 7, 8, 9;
  p.add_face(std::vector<int>{0, 1, 2, 3});
  p.add_face(std::vector<int>{4, 3, 2});
  const auto q = simsr::io::read_obj(simsr::io::format_obj(p), "mem.obj");
  CHECK(q.V == p.V);
  CHECK(q.indices == p.indices);
  CHECK(q.offsets == p.offsets);

  const auto file = tmp_dir() / "tri.obj";
  simsr::io::write_obj(file, simsr::triangulate(p));
  const auto t = simsr::io::read_obj_triangles(file);
  CHECK(t.V == p.V);
  CHECK(t.F == simsr::triangulate(p).F);

  p.V(2, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(simsr::io::format_obj(p), simsr::MeshError);
}

TEST_CASE("obj: malformed input is a ParseError at the offending line") {
  using simsr::io::read_obj;
  auto rd = [](std::string s) { return [s] { read_obj(s, "mem.obj"); }; };
  expect_parse_error(rd("v 0 0 0\nv 1 2\n"), 2, "3 coordinates");          // truncated vertex
  expect_parse_error(rd("v 0 0 0\nv 1 2 nan\n"), 2, "non-finite");          // NaN
  expect_parse_error(rd("v 0 0 0\nv 1 2 inf\n"), 2, "non-finite");          // inf
  expect_parse_error(rd("v 0 0 0\nv 1 2 1e999\n"), 2, "non-finite");        // overflow
  expect_parse_error(rd("v 0 0 0\nv 1 2 3x\n"), 2, "malformed");            // trailing junk
  expect_parse_error(rd("v 0 0 0\nv 1 2 0x1p3\n"), 2, "malformed");         // hex float
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), 4, "not defined");
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n"), 4, "index 0");
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n"), 4, "before the first vertex");
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"), 4, "at least 3");
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n"), 4, "out-of-range");
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/\n"), 4, "ends with");
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/1/1/1\n"), 4, "more than three");
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/x\n"), 4, "malformed");
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3//0\n"), 4, "index 0");
  expect_parse_error(rd("v 0 0 0\nv 1 0 0\nl 1 2\n"), 3, "unsupported");
  expect_parse_error(rd(std::string("v 0 0 0\nv 1 0\0 0\n", 18)), 2, "NUL");
  CHECK_THROWS_AS(simsr::io::read_obj(fs::path("/nonexistent/x.obj")), simsr::ParseError);
}

TEST_CASE("obj: tet soups read, write and detect") {
  // Two positively oriented tets sharing a face.
  simsr::TetMesh<> m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1;
  m.T.resize(2, 4);
  m.T << 0, 1, 2, 3, 1, 2, 3, 4;
  REQUIRE(signed_volume(m, 0) > 0);
  REQUIRE(signed_volume(m, 1) > 0);
  const std::string text = simsr::io::format_obj_tets(m);
  const auto poly = simsr::io::read_obj(text, "mem.obj");
  CHECK(poly.num_faces() == 8);
  CHECK(simsr::io::is_tet_soup(poly));
  // every written face is outward: its normal points away from the tet's fourth vertex
  for (simsr::Index f = 0; f < 8; ++f) {
    const simsr::VIndex* c = poly.indices.data() + 3 * f;
    const auto t = f / 4;
    simsr::VIndex o = -1;
    for (int k = 0; k < 4; ++k)
      if (m.T(t, k) != c[0] && m.T(t, k) != c[1] && m.T(t, k) != c[2]) o = m.T(t, k);
    const auto a = poly.V.row(c[0]);
    const Eigen::RowVector3d n = (poly.V.row(c[1]) - a).cross(poly.V.row(c[2]) - a);
    CHECK(n.dot(poly.V.row(o) - a) < 0);
  }
  const auto back = simsr::io::read_obj_tets(text, "mem.obj");
  CHECK(back.V == m.V);
  CHECK(back.T == m.T);

  const auto file = tmp_dir() / "tets.obj";
  simsr::io::write_obj_tets(file, m);
  CHECK(simsr::io::read_obj_tets(file).T == m.T);

  // Swapping the 2nd and 3rd face of a group (as the bunny file does for some tets) reads the same.
  std::string swapped = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 4 3\nf 1 2 4\nf 2 3 4\n";
  CHECK(simsr::io::read_obj_tets(swapped, "mem.obj").T.row(0) == Eigen::RowVector4i(0, 1, 2, 3));

  simsr::TetMesh<> bad = m;
  bad.T(1, 2) = bad.T(1, 0);
  CHECK_THROWS_AS(simsr::io::format_obj_tets(bad), simsr::MeshError);
  bad.T(1, 2) = 5;
  CHECK_THROWS_AS(simsr::io::format_obj_tets(bad), simsr::MeshError);
}

TEST_CASE("obj: files not in the tet-soup convention name the first bad group's line") {
  const std::string head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\n";  // lines 1..5
  const std::string good = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";           // lines 6..9
  auto rd = [](std::string s) { return [s] { simsr::io::read_obj_tets(s, "mem.obj"); }; };
  // a 5th vertex in group 2 (lines 10..13)
  expect_parse_error(rd(head + good + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 5\n"), 10, "4 distinct");
  // a face inverted: inconsistent orientation
  expect_parse_error(rd(head + good + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 4 3\n"), 10, "consistently oriented");
  // a face repeated
  expect_parse_error(rd(head + good + "f 1 3 2\nf 1 3 2\nf 1 4 3\nf 2 3 4\n"), 10, "consistently oriented");
  // 6 triangles
  expect_parse_error(rd(head + good + "f 1 3 2\nf 1 2 4\n"), 10, "multiple of 4");
  // a quad
  expect_parse_error(rd(head + good + "f 1 3 2 5\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"), 10, "not 3");
  // no faces at all
  expect_parse_error(rd(head), 1, "no faces");
}

TEST_CASE("obj: the official bunny rest shape is a positively oriented tet soup") {
  const fs::path dir = fs::path(SIMSR_DATA_DIR) / "bunny";
  if (!fs::exists(dir / "lrestshape.obj")) {
    SIMSR_MISSING("bunny data not found in " << dir);
    return;
  }
  const auto poly = simsr::io::read_obj(dir / "lrestshape.obj");
  CHECK(poly.num_vertices() == 1747);
  CHECK(poly.num_faces() == 19584);
  CHECK(simsr::io::is_tet_soup(poly));
  const auto m = simsr::io::read_obj_tets(dir / "lrestshape.obj");
  REQUIRE(m.num_tets() == 4896);
  double total = 0;
  simsr::Index positive = 0;
  for (simsr::Index t = 0; t < m.num_tets(); ++t) {
    const double v = signed_volume(m, t);
    positive += v > 0;
    total += v;
  }
  CHECK(positive == 4896);
  CHECK(total == doctest::Approx(0.0011852977629307282).epsilon(1e-12));  // numpy, from the raw file
  // writing in the convention reproduces the file's faces up to the order of faces 2 and 3
  const auto again = simsr::io::read_obj(simsr::io::format_obj_tets(m), "mem.obj");
  CHECK(again.V == poly.V);
  CHECK(simsr::io::read_obj_tets(simsr::io::format_obj_tets(m), "mem.obj").T == m.T);

  const auto hr = simsr::io::read_obj_triangles(dir / "hrestshape.obj");
  CHECK(hr.num_vertices() == 2503);
  CHECK(hr.num_faces() == 4968);
  CHECK_FALSE(simsr::io::is_tet_soup(simsr::io::read_obj(dir / "hrestshape.obj")));

  // simulated frames share the rest shape's tets
  const auto frame = simsr::io::read_obj_tets(dir / "train_obj_sample" / "lowres_000.obj");
  CHECK(frame.T == m.T);
  CHECK(frame.V.rows() == m.V.rows());

  const fs::path face = fs::path(SIMSR_DATA_DIR) / "ict_face" / "neutral_face_head.obj";
  if (fs::exists(face)) {
    const auto f = simsr::io::read_obj(face);
    CHECK(f.num_vertices() == 11248);
    CHECK(f.num_faces() == 11144);
    CHECK(simsr::triangulate(f).num_faces() == static_cast<simsr::Index>(f.indices.size()) - 2 * f.num_faces());
  } else {
    SIMSR_MISSING("ICT face OBJ not found: " << face);
  }
}

}  // namespace io_test_obj
