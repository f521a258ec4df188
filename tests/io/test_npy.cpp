#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <simsr/io/npy.hpp>

namespace io_test_npy {

namespace {

namespace io = simsr::io;
const std::filesystem::path fixtures = std::filesystem::path(SIMSR_TEST_DATA_DIR) / "npy";

std::filesystem::path tmp_dir() {
  const auto d = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "npy";
  std::filesystem::create_directories(d);
  return d;
}

bool have_numpy() {
  static const bool ok = std::system("/usr/bin/python3 -c 'import numpy' >/dev/null 2>&1") == 0;
  return ok;
}

std::vector<unsigned char> slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// A .npy with an arbitrary header dict and payload (version 1 unless `major` says otherwise).
std::vector<unsigned char> craft(const std::string& dict, std::size_t data_bytes, int major = 1) {
  std::string h = "\x93NUMPY";
  h += static_cast<char>(major);
  h += '\0';
  const std::size_t len = dict.size();
  h += static_cast<char>(len & 0xff);
  h += static_cast<char>((len >> 8) & 0xff);
  if (major > 1) h += std::string("\0\0", 2);
  h += dict;
  std::vector<unsigned char> out(h.begin(), h.end());
  for (std::size_t i = 0; i < data_bytes; ++i) out.push_back(static_cast<unsigned char>(i));
  return out;
}

std::string parse_error_of(const std::vector<unsigned char>& b) {
  try {
    io::read_npy_buffer(b.data(), b.size(), "crafted.npy");
  } catch (const simsr::ParseError& e) {
    CHECK(e.file() == "crafted.npy");
    CHECK(e.line() == 0);
    return e.message();
  }
  return "no error";
}

}  // namespace

TEST_CASE("npy: float64 in C, Fortran and big-endian order, versions 1, 2, 3") {
  for (const char* name : {"f8_c.npy", "f8_f.npy", "f8_be.npy", "v2.npy", "v3.npy"}) {
    CAPTURE(name);
    const auto a = io::read_npy(fixtures / name);
    CHECK(a.dtype.kind == io::NpyKind::Float);
    CHECK(a.dtype.itemsize == 8);
    REQUIRE(a.shape == std::vector<std::int64_t>{3, 4});
    const auto m = a.to_matrix<double>();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) CHECK(m(i, j) == 0.5 * (4 * i + j));
    const auto x = a.to_xtensor<double, 2>();
    CHECK(x(2, 1) == 4.5);
    const auto v = a.to_vector<float>();
    CHECK(v[7] == 3.5f);
  }
  CHECK(io::read_npy(fixtures / "f8_f.npy").fortran_order);
  CHECK(io::read_npy(fixtures / "f8_be.npy").dtype.big_endian);
  CHECK_THROWS_AS(io::read_npy(fixtures / "f8_c.npy").to_vector<std::int64_t>(), simsr::ArgumentError);
  CHECK_THROWS_AS((io::read_npy(fixtures / "f8_c.npy").to_xtensor<double, 3>()), simsr::ShapeError);
}

TEST_CASE("npy: integer dtypes, extremes and checked conversions") {
  const auto i8 = io::read_npy(fixtures / "i8.npy").to_vector<std::int64_t>();
  CHECK(i8 == std::vector<std::int64_t>{std::numeric_limits<std::int64_t>::min(),
                                        std::numeric_limits<std::int64_t>::max(), 0, -1});
  CHECK(io::read_npy(fixtures / "i1.npy").to_vector<int>() == std::vector<int>{-128, 127, 0, -1});
  CHECK(io::read_npy(fixtures / "i2.npy").to_vector<int>() == std::vector<int>{-32768, 32767, 0, -1});
  CHECK(io::read_npy(fixtures / "i4.npy").to_vector<std::int64_t>() ==
        std::vector<std::int64_t>{-2147483648LL, 2147483647LL, 0, -1});
  CHECK(io::read_npy(fixtures / "u1.npy").to_vector<int>() == std::vector<int>{0, 255, 1, 2});
  CHECK(io::read_npy(fixtures / "u2.npy").to_vector<int>() == std::vector<int>{0, 65535, 1, 2});
  CHECK(io::read_npy(fixtures / "u4.npy").to_vector<std::uint32_t>() == std::vector<std::uint32_t>{0, 4294967295u, 1, 2});
  for (const char* name : {"u8.npy", "u8_be.npy"}) {
    const auto a = io::read_npy(fixtures / name);
    CHECK(a.to_vector<std::uint64_t>() == std::vector<std::uint64_t>{0, ~std::uint64_t{0}, 1, 2});
    CHECK_THROWS_AS(a.to_vector<std::int64_t>(), simsr::ArgumentError);  // 2^64-1 out of range
  }
  // Out-of-range narrowing throws, in-range narrowing works.
  CHECK_THROWS_AS(io::read_npy(fixtures / "i2.npy").to_vector<std::int8_t>(), simsr::ArgumentError);
  CHECK_THROWS_AS(io::read_npy(fixtures / "i1.npy").to_vector<std::uint8_t>(), simsr::ArgumentError);
  // int64 extremes: -2^63 is a double exactly, 2^63-1 is not.
  CHECK_THROWS_AS(io::read_npy(fixtures / "i8.npy").to_vector<double>(), simsr::ArgumentError);
  CHECK(io::read_npy(fixtures / "i4.npy").to_vector<double>()[0] == -2147483648.0);
  CHECK_THROWS_AS(io::read_npy(fixtures / "i4.npy").to_vector<float>(), simsr::ArgumentError);  // 2^31-1 inexact

  const auto be = io::read_npy(fixtures / "i4_be_f.npy");
  CHECK(be.fortran_order);
  const auto m = be.to_matrix<int>();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) CHECK(m(i, j) == 4 * i + j - 6);

  const auto t = io::read_npy(fixtures / "i2_3d_f.npy").to_xtensor<int, 3>();
  REQUIRE(t.shape()[0] == 2);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 4; ++k) CHECK(t(i, j, k) == 12 * i + 4 * j + k - 12);
  const auto x = io::read_npy(fixtures / "i2_3d_f.npy").to_xarray<double>();
  CHECK(x.dimension() == 3);
  CHECK(x(1, 2, 3) == 11.0);
}

TEST_CASE("npy: float32, bool, 0-d and empty arrays") {
  const auto f = io::read_npy(fixtures / "f4_le.npy");
  CHECK(f.dtype == io::NpyDType::of<float>());
  CHECK(f.to_vector<double>()[5] == 1.25);
  const auto b = io::read_npy(fixtures / "b1.npy");
  CHECK(b.dtype.kind == io::NpyKind::Bool);
  CHECK(b.to_vector<bool>() == std::vector<bool>{true, false, false, true});
  CHECK(b.to_vector<int>() == std::vector<int>{1, 0, 0, 1});
  CHECK(io::read_npy(fixtures / "u1.npy").to_vector<std::int16_t>()[1] == 255);
  CHECK_THROWS_AS(io::read_npy(fixtures / "u1.npy").to_vector<bool>(), simsr::ArgumentError);  // 255
  CHECK_THROWS_AS(f.to_vector<bool>(), simsr::ArgumentError);

  const auto s = io::read_npy(fixtures / "scalar_0d.npy");
  CHECK(s.ndim() == 0);
  CHECK(s.size() == 1);
  CHECK(s.item<double>() == 3.25);
  CHECK(s.to_xarray<double>().dimension() == 0);
  CHECK(s.to_xarray<double>()() == 3.25);
  CHECK_THROWS_AS(s.item<int>(), simsr::ArgumentError);

  const auto e = io::read_npy(fixtures / "empty_0x3.npy");
  CHECK(e.shape == std::vector<std::int64_t>{0, 3});
  CHECK(e.bytes.empty());
  CHECK(e.to_points<double>().rows() == 0);
  CHECK(e.to_xarray<int>().size() == 0);
}

TEST_CASE("npy: unicode strings, little and big endian") {
  const auto u = io::read_npy(fixtures / "unicode.npy");
  CHECK(u.dtype.descr() == "<U5");
  CHECK(u.to_strings() == std::vector<std::string>{"a", "h\xC3\xA9llo", "\xE6\x97\xA5\xE6\x9C\xAC\xE8\xAA\x9E",
                                                   "\xF0\x9F\x98\x80", ""});
  CHECK_THROWS_AS(u.to_vector<double>(), simsr::ArgumentError);
  const auto be = io::read_npy(fixtures / "unicode_be_2d.npy");
  CHECK(be.dtype.descr() == ">U3");
  CHECK(be.to_strings() == std::vector<std::string>{"ab", "c", "", "xyz"});
  // An invalid code point (a surrogate) is reported, not turned into garbage.
  auto bad = io::make_npy(std::vector<std::string>{"ab"});
  const std::uint32_t surrogate = 0xD800;
  std::memcpy(bad.bytes.data() + 4, &surrogate, 4);
  CHECK_THROWS_AS(bad.to_strings(), simsr::ParseError);
  CHECK_THROWS_AS(io::make_npy(std::vector<std::string>{"\xC3"}), simsr::ArgumentError);
}

TEST_CASE("npy: writer reproduces numpy's bytes and round-trips every kind of source") {
  // Same header layout as numpy: a file we write from the read array is byte-identical.
  for (const char* name : {"f8_c.npy", "f8_f.npy", "f8_be.npy", "i2_3d_f.npy", "b1.npy", "scalar_0d.npy",
                           "empty_0x3.npy", "unicode.npy", "u8_be.npy"}) {
    CAPTURE(name);
    const auto raw = slurp(fixtures / name);
    const auto bytes = io::npy_bytes(io::read_npy(fixtures / name));
    REQUIRE(bytes.size() == raw.size());
    CHECK(std::memcmp(bytes.data(), raw.data(), raw.size()) == 0);
  }
  const auto dir = tmp_dir();
  // xtensor expression
  xt::xarray<std::int16_t> x = {{1, -2, 3}, {4, 5, -6}};
  io::write_npy(dir / "x.npy", x);
  const auto rx = io::read_npy(dir / "x.npy");
  CHECK(rx.dtype.name() == "int16");
  CHECK(rx.to_xarray<std::int16_t>() == x);
  io::write_npy(dir / "xe.npy", 0.5 * x + 1.0);  // an unevaluated expression of doubles
  const auto re = io::read_npy(dir / "xe.npy");
  CHECK(re.dtype.name() == "float64");
  CHECK(re.to_xarray<double>() == xt::xarray<double>{{1.5, 0.0, 2.5}, {3.0, 3.5, -2.0}});
  // Eigen: column-major storage, written row-major; vectors become 1-d.
  Eigen::MatrixXf m(2, 3);
  m << 1, 2, 3, 4, 5, 6;
  const auto rm = io::read_npy_buffer(io::npy_bytes(io::make_npy(m)));
  CHECK(rm.shape == std::vector<std::int64_t>{2, 3});
  CHECK(!rm.fortran_order);
  CHECK(rm.to_matrix<float>() == m);
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(5, 0, 1);
  const auto rv = io::read_npy_buffer(io::npy_bytes(io::make_npy(v)));
  CHECK(rv.shape == std::vector<std::int64_t>{5});
  CHECK(rv.to_matrix<double>().col(0) == v);
  // Raw Fortran-order data.
  const std::uint8_t raw[6] = {1, 2, 3, 4, 5, 6};  // 2×3 Fortran: rows (1,3,5) (2,4,6)
  const auto rf = io::read_npy_buffer(io::npy_bytes(io::make_npy<std::uint8_t>({2, 3}, raw, true)));
  CHECK(rf.to_vector<int>() == std::vector<int>{1, 3, 5, 2, 4, 6});
  // Frames of points.
  simsr::Points<double> p0(2, 3), p1(2, 3);
  p0 << 0, 1, 2, 3, 4, 5;
  p1 = p0 * 2;
  const auto fr = io::read_npy_buffer(io::npy_bytes(io::make_npy_frames<double>({p0, p1})));
  CHECK(fr.num_frames() == 2);
  CHECK(fr.frame_points<double>(1) == p1);
  CHECK(fr.frame_points<float>(0) == p0.cast<float>());
  CHECK_THROWS_AS(fr.frame_points<double>(2), simsr::ArgumentError);
  // Strings.
  const std::vector<std::string> names = {"jawOpen", "\xC3\xA9t\xC3\xA9", ""};
  io::write_npy(dir / "s.npy", names);
  CHECK(io::read_npy(dir / "s.npy").to_strings() == names);
  // Inconsistent arrays are refused by the writer.
  auto broken = io::make_npy(m);
  broken.bytes.pop_back();
  CHECK_THROWS_AS(io::npy_bytes(broken), simsr::ArgumentError);
}

TEST_CASE("npy: hostile input gives ParseError with the byte offset") {
  const auto good = slurp(fixtures / "f8_c.npy");
  // Every truncation of a valid file, and of a v2 one.
  for (const char* name : {"f8_c.npy", "v2.npy", "unicode.npy"}) {
    const auto full = slurp(fixtures / name);
    for (std::size_t n = 0; n < full.size(); ++n) {
      const std::vector<unsigned char> cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
      CAPTURE(n);
      CHECK(parse_error_of(cut).find("byte ") == 0);
    }
  }
  // Bad magic / version.
  auto bad = good;
  bad[1] = 'X';
  CHECK(parse_error_of(bad).find("bad magic") != std::string::npos);
  bad = good;
  bad[6] = 4;
  CHECK(parse_error_of(bad).find("version 4.0") != std::string::npos);
  // Header length larger than the file / absurd for v2.
  bad = good;
  bad[8] = 0xff;
  bad[9] = 0xff;
  CHECK(parse_error_of(bad).find("truncated file") != std::string::npos);
  auto v2 = slurp(fixtures / "v2.npy");
  v2[11] = 0x7f;
  CHECK(parse_error_of(v2).find("exceeds the limit") != std::string::npos);
  // Trailing bytes are not silently ignored.
  bad = good;
  bad.push_back(0);
  CHECK(parse_error_of(bad).find("trailing") != std::string::npos);

  const std::string ok_tail = "'fortran_order': False, 'shape': (2,), }\n";
  // Malformed dicts.
  for (const std::string& dict : {std::string("{'descr': '<f8', 'fortran_order': False, 'shape': (2,) \n"),
                                  std::string("'descr': '<f8', 'fortran_order': False, 'shape': (2,), }\n"),
                                  std::string("{'descr': '<f8', 'fortran_order': Maybe, 'shape': (2,), }\n"),
                                  std::string("{'descr': '<f8', 'fortran_order': False, 'shape': (2), }\n"),
                                  std::string("{'descr': '<f8', 'fortran_order': False, 'shape': (-2,), }\n"),
                                  std::string("{'descr': '<f8', 'fortran_order': False, 'shape': (2,,), }\n"),
                                  std::string("{'descr': '<f8, 'fortran_order': False, 'shape': (2,), }\n"),
                                  std::string("{'descr': '<f8', 'fortran_order': False, }\n"),
                                  std::string("{'descr': '<f8', 'descr': '<f8', " + ok_tail),
                                  std::string("{'descr': '<f8', 'extra': 1, " + ok_tail),
                                  std::string("{'descr': '<f8', " + ok_tail + "x"),
                                  std::string("{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999999999999,), }\n"),
                                  std::string("{'descr': '<f8', 'fortran_order': False, 'shape': (1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1), }\n"),
                                  std::string("{'descr': '<f8', 'fortran_order': False, 'shape': (2,), }\xff\n"),
                                  std::string("")}) {
    CAPTURE(dict);
    const auto msg = parse_error_of(craft(dict, 16));
    CHECK(msg.find("malformed .npy header") != std::string::npos);
    CHECK(msg.find("byte ") == 0);
  }
  // Unsupported dtypes.
  for (const std::string d : {"<f2", "|O", "<c16", "|S4", "<M8[ns]", "<i3", "|f8", "V8", "<U0"}) {
    CAPTURE(d);
    CHECK(parse_error_of(craft("{'descr': '" + d + "', " + ok_tail, 16)).find("unsupported dtype") != std::string::npos);
  }
  CHECK(parse_error_of(craft("{'descr': [('a', '<f8')], " + ok_tail, 16)).find("structured") != std::string::npos);
  // Shapes whose element or byte count overflows, or that exceed the data at hand (no allocation).
  CHECK(parse_error_of(craft("{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 4294967296, 4294967296), }\n", 0))
            .find("overflows") != std::string::npos);
  CHECK(parse_error_of(craft("{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 1073741824), }\n", 0))
            .find("overflows") != std::string::npos);
  CHECK(parse_error_of(craft("{'descr': '<f8', 'fortran_order': False, 'shape': (100000, 100000, 3), }\n", 64))
            .find("truncated data") != std::string::npos);
  CHECK(parse_error_of(craft("{'descr': '<U16777216', 'fortran_order': False, 'shape': (1000,), }\n", 64))
            .find("needs 67108864000 bytes") != std::string::npos);
  // Zero-sized arrays need no data even with absurd other dimensions.
  const auto zb = craft("{'descr': '<f8', 'fortran_order': False, 'shape': (0, 1000000000000), }\n", 0);
  CHECK(io::read_npy_buffer(zb.data(), zb.size()).size() == 0);
  // Python 2 long dimensions and double quotes are accepted (numpy accepts them too).
  const auto pb = craft("{\"descr\": \"<i2\", \"fortran_order\": True, \"shape\": (2L, 1L)}", 4);
  const auto py2 = io::read_npy_buffer(pb.data(), pb.size());
  CHECK(py2.shape == std::vector<std::int64_t>{2, 1});
  // Missing files.
  CHECK_THROWS_AS(io::read_npy(fixtures / "does_not_exist.npy"), simsr::ParseError);
}

TEST_CASE("npy: round trips through numpy") {
  if (!have_numpy()) {
    SIMSR_MISSING("numpy round trip: /usr/bin/python3 with numpy (python3-numpy) not available");
    return;
  }
  const auto dir = tmp_dir();
  xt::xarray<double> a = xt::xarray<double>::from_shape({2, 3, 4});
  for (std::size_t k = 0; k < a.size(); ++k) a.data()[k] = 0.1 * static_cast<double>(k) - 1.0;
  io::write_npy(dir / "cpp_f8.npy", a);
  Eigen::Matrix<std::int64_t, 3, 2> mi;
  mi << -1, 2, -3, 4, -5, std::numeric_limits<std::int64_t>::max();
  io::write_npy(dir / "cpp_i8.npy", mi);
  io::write_npy(dir / "cpp_u.npy", std::vector<std::string>{"jawOpen", "\xC3\xA9", "\xF0\x9F\x98\x80"});
  const bool b[3] = {true, false, true};
  io::write_npy(dir / "cpp_b.npy", io::make_npy<bool>({3}, b));
  const std::string script =
      "import numpy as np, sys\n"
      "d = sys.argv[1]\n"
      "a = np.load(d + '/cpp_f8.npy'); assert a.shape == (2, 3, 4) and a.dtype == np.float64\n"
      "assert np.array_equal(a, (0.1 * np.arange(24) - 1.0).reshape(2, 3, 4))\n"
      "m = np.load(d + '/cpp_i8.npy'); assert np.array_equal(m, [[-1, 2], [-3, 4], [-5, 2**63 - 1]])\n"
      "assert list(np.load(d + '/cpp_u.npy')) == ['jawOpen', '\\u00e9', '\\U0001F600']\n"
      "assert np.load(d + '/cpp_b.npy').tolist() == [True, False, True]\n"
      "rng = np.random.default_rng(5)\n"
      "np.save(d + '/py_f4_f.npy', np.asfortranarray(rng.standard_normal((7, 5, 3)).astype('>f4')))\n"
      "np.save(d + '/py_u2.npy', rng.integers(0, 65535, (4, 9)).astype('<u2'))\n"
      "np.savetxt(d + '/py_expect.txt', np.concatenate([np.load(d + '/py_f4_f.npy').astype(np.float64).ravel(),\n"
      "           np.load(d + '/py_u2.npy').astype(np.float64).ravel()]), fmt='%.17g')\n";
  std::ofstream(dir / "roundtrip.py") << script;
  REQUIRE(std::system(("/usr/bin/python3 " + (dir / "roundtrip.py").string() + " " + dir.string()).c_str()) == 0);
  std::ifstream expect(dir / "py_expect.txt");
  std::vector<double> want;
  for (double v; expect >> v;) want.push_back(v);
  const auto f = io::read_npy(dir / "py_f4_f.npy");
  CHECK(f.fortran_order);
  CHECK(f.dtype.big_endian);
  std::vector<double> got = f.to_vector<double>();
  const auto u = io::read_npy(dir / "py_u2.npy").to_vector<double>();
  got.insert(got.end(), u.begin(), u.end());
  CHECK(got == want);
}

}  // namespace io_test_npy
