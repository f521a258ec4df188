#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <simsr/io/npz.hpp>
#include <simsr/io/vtu.hpp>

namespace io_test_vtu {

namespace {

namespace io = simsr::io;

std::filesystem::path tmp_dir() {
  const auto d = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "vtu";
  std::filesystem::create_directories(d);
  return d;
}

bool have_meshio() {
  static const bool ok = std::system("/usr/bin/python3 -c 'import meshio, numpy' >/dev/null 2>&1") == 0;
  return ok;
}

/// Two tets sharing face (1,2,3) and two boundary triangles, with data of every supported kind.
struct Sample {
  simsr::Points<double> V{5, 3};
  simsr::Tets T{2, 4};
  simsr::Tris F{2, 3};
  Eigen::VectorXd err{5};
  simsr::Points<double> disp{5, 3};
  Eigen::VectorXi id{5};
  Eigen::VectorXf vol{4};
  Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1> label{4};
  Sample() {
    V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1.0 / 3, 1.0 / 3, 1.0 / 3 + 0.7;
    T << 0, 1, 2, 3, 1, 2, 3, 4;
    F << 0, 2, 1, 0, 1, 3;
    err << 0.1, 0.2, 1e-17, -3.5, 12345.678901234567;
    disp = V * 0.25;
    disp(4, 2) = -1.0 / 3;
    id << 7, -8, 9, 10, 2147483647;
    vol << 1.0f / 6, 0.1f, 0.5f, 0.5f;
    label << 1, 2, -3, 4000000000LL;
  }
  io::VtuGrid grid() const {
    io::VtuGrid g;
    g.set_points(V).set_tets(T).set_triangles(F);
    g.add_point_data("err", err).add_point_data("disp", disp).add_point_data("id", id);
    g.add_cell_data("vol", vol).add_cell_data("label <&>", label);
    return g;
  }
};

/// The decoded payload (after the UInt64 byte count) of the binary DataArray called `name`.
std::vector<unsigned char> binary_payload(const std::string& xml, const std::string& name) {
  const std::regex re("Name=\"" + name + "\"[^>]*format=\"binary\">\\s*([A-Za-z0-9+/=]+)\\s*<");
  std::smatch m;
  REQUIRE(std::regex_search(xml, m, re));
  const std::string b = m[1];
  const auto head = io::detail::base64_decode(b.substr(0, 12));
  REQUIRE(head);
  REQUIRE(head->size() == 8);
  std::uint64_t n;
  std::memcpy(&n, head->data(), 8);
  const auto data = io::detail::base64_decode(b.substr(12));
  REQUIRE(data);
  REQUIRE(data->size() == n);
  return *data;
}

}  // namespace

TEST_CASE("vtu: base64 matches RFC 4648 and decodes strictly") {
  const std::pair<const char*, const char*> v[] = {{"", ""},         {"f", "Zg=="},         {"fo", "Zm8="},
                                                   {"foo", "Zm9v"},  {"foob", "Zm9vYg=="},  {"fooba", "Zm9vYmE="},
                                                   {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, enc] : v) {
    CHECK(io::detail::base64_encode(plain, std::strlen(plain)) == enc);
    const auto d = io::detail::base64_decode(enc);
    REQUIRE(d);
    CHECK(std::string(d->begin(), d->end()) == plain);
  }
  CHECK(!io::detail::base64_decode("Zg="));
  CHECK(!io::detail::base64_decode("Z=g="));
  CHECK(!io::detail::base64_decode("Zm9v!m9v"));
}

TEST_CASE("vtu: binary and ascii documents hold the grid exactly") {
  const Sample s;
  const auto g = s.grid();
  CHECK(g.num_cells() == 4);
  const std::string xml = g.to_string(io::VtuFormat::Binary);
  CHECK(xml.find("NumberOfPoints=\"5\" NumberOfCells=\"4\"") != std::string::npos);
  CHECK(xml.find("Name=\"label &lt;&amp;&gt;\"") != std::string::npos);
  const auto pts = binary_payload(xml, "Points");
  REQUIRE(pts.size() == 15 * sizeof(double));
  CHECK(std::memcmp(pts.data(), s.V.data(), pts.size()) == 0);
  const auto conn = binary_payload(xml, "connectivity");
  const std::int32_t want_conn[14] = {0, 1, 2, 3, 1, 2, 3, 4, 0, 2, 1, 0, 1, 3};  // Int32: every index fits
  REQUIRE(conn.size() == sizeof want_conn);
  CHECK(std::memcmp(conn.data(), want_conn, sizeof want_conn) == 0);
  const auto off = binary_payload(xml, "offsets");
  const std::int32_t want_off[4] = {4, 8, 11, 14};
  REQUIRE(off.size() == sizeof want_off);
  CHECK(std::memcmp(off.data(), want_off, sizeof want_off) == 0);
  CHECK(binary_payload(xml, "types") == std::vector<unsigned char>{10, 10, 5, 5});
  CHECK(xml.find("type=\"Int32\" Name=\"connectivity\"") != std::string::npos);
  const auto id = binary_payload(xml, "id");
  CHECK(id.size() == 5 * 4);
  CHECK(xml.find("type=\"Int32\" Name=\"id\"") != std::string::npos);
  CHECK(xml.find("type=\"Float32\" Name=\"vol\"") != std::string::npos);
  CHECK(xml.find("type=\"Int64\" Name=\"label &lt;&amp;&gt;\"") != std::string::npos);
  CHECK(xml.find("Name=\"disp\" NumberOfComponents=\"3\"") != std::string::npos);

  const std::string ascii = g.to_string(io::VtuFormat::Ascii);
  CHECK(ascii.find("format=\"binary\"") == std::string::npos);
  CHECK(ascii.find("12345.678901234567") != std::string::npos);
  CHECK(ascii.find("4000000000") != std::string::npos);
  CHECK(ascii.find("10 10 5 5") != std::string::npos);

  // Float32 points stay Float32; meshes construct grids directly.
  simsr::TetMesh<float> tm;
  tm.V = s.V.cast<float>();
  tm.T = s.T;
  const auto xf = io::VtuGrid(tm).to_string();
  CHECK(xf.find("type=\"Float32\" Name=\"Points\"") != std::string::npos);
  CHECK(binary_payload(xf, "Points").size() == 15 * sizeof(float));
  simsr::TriMesh<double> sm{s.V, s.F};
  CHECK(io::VtuGrid(sm).num_cells() == 2);
}

TEST_CASE("vtu: invalid grids are refused") {
  const Sample s;
  auto g = s.grid();
  g.add_point_data("short", Eigen::VectorXd::Zero(4));
  CHECK_THROWS_AS(g.to_string(), simsr::ShapeError);
  g = s.grid();
  g.add_cell_data("vol", Eigen::VectorXd::Zero(4));
  CHECK_THROWS_AS(g.to_string(), simsr::ArgumentError);
  g = s.grid();
  simsr::Tets bad = s.T;
  bad(1, 3) = 5;
  g.set_tets(bad);
  CHECK_THROWS_AS(g.to_string(), simsr::MeshError);
  CHECK_THROWS_AS(g.set_points(Eigen::MatrixXd::Zero(3, 2)), simsr::ShapeError);
  CHECK_THROWS_AS(g.add_point_data("wide", Eigen::MatrixXd::Zero(5, 10)), simsr::ArgumentError);
  CHECK_THROWS_AS(io::write_vtu(tmp_dir() / "no_such_dir" / "x.vtu", s.grid()), simsr::ParseError);
}

TEST_CASE("vtu: meshio reads back points, cells and every data array; pvd series") {
  const auto dir = tmp_dir();
  const Sample s;
  io::write_vtu(dir / "bin.vtu", s.grid(), io::VtuFormat::Binary);
  io::write_vtu(dir / "ascii.vtu", s.grid(), io::VtuFormat::Ascii);
  io::PvdWriter series(dir / "series.pvd");
  for (int f = 0; f < 3; ++f) {
    io::VtuGrid g;
    g.set_points(s.V * (1.0 + f)).set_tets(s.T);
    g.add_point_data("err", s.err * static_cast<double>(f));
    series.add(0.5 * f, g);
  }
  CHECK(series.size() == 3);
  std::ifstream pvd_in(dir / "series.pvd");
  const std::string pvd((std::istreambuf_iterator<char>(pvd_in)), std::istreambuf_iterator<char>());
  CHECK(pvd.find("type=\"Collection\"") != std::string::npos);
  CHECK(pvd.find("timestep=\"1\" group=\"\" part=\"0\" file=\"series/series_000002.vtu\"") != std::string::npos);
  CHECK(std::filesystem::exists(dir / "series" / "series_000002.vtu"));

  if (!have_meshio()) {
    SIMSR_MISSING("meshio check: /usr/bin/python3 with meshio (python3-meshio) not available");
    return;
  }
  // meshio reads each file and saves what it saw to an .npz, which we compare here.
  const std::string script =
      "import sys, numpy as np, meshio, re\n"
      "def dump(src, dst):\n"
      "    m = meshio.read(src)\n"
      "    out = {'points': m.points}\n"
      "    for b in m.cells: out['cells_' + b.type] = b.data\n"
      "    for k, v in m.point_data.items(): out['pd_' + k] = v\n"
      "    for k, v in m.cell_data.items(): out['cd_' + k] = np.concatenate(v)\n"
      "    np.savez(dst, **out)\n"
      "d = sys.argv[1]\n"
      "dump(d + '/bin.vtu', d + '/bin_meshio.npz')\n"
      "dump(d + '/ascii.vtu', d + '/ascii_meshio.npz')\n"
      "files = re.findall(r'file=\"([^\"]+)\"', open(d + '/series.pvd').read())\n"
      "assert len(files) == 3, files\n"
      "for i, f in enumerate(files): dump(d + '/' + f, d + '/series_%d_meshio.npz' % i)\n";
  std::ofstream(dir / "read_meshio.py") << script;
  REQUIRE(std::system(("/usr/bin/python3 " + (dir / "read_meshio.py").string() + " " + dir.string()).c_str()) == 0);
  for (const char* name : {"bin_meshio.npz", "ascii_meshio.npz"}) {
    CAPTURE(name);
    const auto z = io::read_npz(dir / name);
    CHECK(z.at("points").to_points<double>() == s.V);
    CHECK(z.at("cells_tetra").to_matrix<int>() == s.T.cast<int>());
    CHECK(z.at("cells_triangle").to_matrix<int>() == s.F.cast<int>());
    CHECK(z.at("pd_err").to_matrix<double>().col(0) == s.err);
    CHECK(z.at("pd_disp").to_points<double>() == s.disp);
    CHECK(z.at("pd_id").dtype.name() == "int32");
    CHECK(z.at("pd_id").to_matrix<int>().col(0) == s.id);
    CHECK(z.at("cd_vol").dtype.name() == "float32");
    CHECK(z.at("cd_vol").to_matrix<float>().col(0) == s.vol);
    CHECK(z.at("cd_label <&>").to_matrix<std::int64_t>().col(0) == s.label);
  }
  for (int f = 0; f < 3; ++f) {
    const auto z = io::read_npz(dir / ("series_" + std::to_string(f) + "_meshio.npz"));
    CHECK(z.at("points").to_points<double>() == s.V * (1.0 + f));
    CHECK(z.at("pd_err").to_matrix<double>().col(0) == s.err * static_cast<double>(f));
  }
}

}  // namespace io_test_vtu
