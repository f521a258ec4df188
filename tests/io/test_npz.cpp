#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include <xtensor/xbuilder.hpp>

#include <simsr/io/npz.hpp>

namespace io_test_npz {

namespace {

namespace io = simsr::io;
const std::filesystem::path fixtures = std::filesystem::path(SIMSR_TEST_DATA_DIR) / "npy";
const std::filesystem::path shared = SIMSR_DATA_DIR;

std::filesystem::path tmp_dir() {
  const auto d = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "npz";
  std::filesystem::create_directories(d);
  return d;
}

bool have_numpy() {
  static const bool ok = std::system("/usr/bin/python3 -c 'import numpy' >/dev/null 2>&1") == 0;
  return ok;
}

std::vector<std::byte> slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::vector<char> c{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::vector<std::byte> b(c.size());
  if (!c.empty()) std::memcpy(b.data(), c.data(), c.size());
  return b;
}

std::string parse_error_of(const std::vector<std::byte>& b) {
  try {
    io::NpzReader z(b.data(), b.size(), "crafted.npz");
    z.read_all();
  } catch (const simsr::ParseError& e) {
    CHECK(e.file().rfind("crafted.npz", 0) == 0);
    return e.file() + ": " + e.message();
  }
  return "no error";
}

/// Offsets of every occurrence of a 4-byte zip signature.
std::vector<std::size_t> find_sig(const std::vector<std::byte>& b, const char* sig) {
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i + 4 <= b.size(); ++i)
    if (std::memcmp(b.data() + i, sig, 4) == 0) at.push_back(i);
  return at;
}

void put_u32(std::vector<std::byte>& b, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b[at + static_cast<std::size_t>(k)] = static_cast<std::byte>((v >> (8 * k)) & 0xff);
}

/// Sets the uncompressed size of the first member in both its local and central headers.
void set_uncompressed_size(std::vector<std::byte>& b, std::uint32_t v) {
  put_u32(b, find_sig(b, "PK\x03\x04").at(0) + 22, v);
  put_u32(b, find_sig(b, "PK\x01\x02").at(0) + 24, v);
}

io::NpzArrays sample() {
  io::NpzArrays a;
  Eigen::MatrixXd m(3, 2);
  m << 1, 2, 3, 4, 5, 6;
  a["m"] = io::make_npy(m);
  a["names"] = io::make_npy(std::vector<std::string>{"jawOpen", "smile"});
  xt::xarray<std::int32_t> x = xt::arange<std::int32_t>(0, 1000);
  a["x"] = io::make_npy(x);
  const float e = 0;
  a["empty"] = io::make_npy<float>({0}, &e);
  return a;
}

void check_sample(const io::NpzArrays& r) {
  CHECK(r.names() == std::vector<std::string>{"m", "names", "x", "empty"});
  CHECK(r.at("m").to_matrix<double>()(2, 1) == 6.0);
  CHECK(r.at("names").to_strings() == std::vector<std::string>{"jawOpen", "smile"});
  const auto x = r.at("x").to_vector<int>();
  REQUIRE(x.size() == 1000);
  CHECK(x[999] == 999);
  CHECK(r.at("empty").shape == std::vector<std::int64_t>{0});
}

}  // namespace

TEST_CASE("npz: numpy's savez and savez_compressed, from a path and from memory") {
  for (const char* name : {"stored.npz", "compressed.npz"}) {
    CAPTURE(name);
    const auto bytes = slurp(fixtures / name);
    for (int from_memory = 0; from_memory < 2; ++from_memory) {
      const io::NpzArrays z = from_memory ? io::read_npz_buffer(bytes.data(), bytes.size()) : io::read_npz(fixtures / name);
      const auto names = z.names();
      REQUIRE(names.size() >= 3);
      CHECK(names[0] == "frames");
      CHECK(names[1] == "names");
      CHECK(names[2] == "scalar");
      const auto& f = z.at("frames");
      CHECK(f.num_frames() == 2);
      const auto p1 = f.frame_points<double>(1);
      for (int i = 0; i < 5; ++i)
        for (int c = 0; c < 3; ++c) CHECK(p1(i, c) == (15 + 3 * i + c) / 8.0);
      CHECK(z.at("names").to_strings() == std::vector<std::string>{"jawOpen", "smile"});
      CHECK(z.at("scalar").ndim() == 0);
      CHECK(z.at("scalar").item<std::int64_t>() == 7);
      CHECK(z.contains("frames"));
      CHECK(!z.contains("frames.npy"));
      CHECK_THROWS_AS(z.at("nope"), simsr::ArgumentError);
    }
  }
  const auto c = io::read_npz(fixtures / "compressed.npz");
  REQUIRE(c.size() == 4);
  CHECK(c.at("empty").shape == std::vector<std::int64_t>{0});
  CHECK(c.at("empty").dtype == io::NpyDType::of<float>());
}

TEST_CASE("npz: the bunny training frames, read lazily") {
  const auto path = shared / "bunny" / "train_frames.npz";
  if (!std::filesystem::exists(path)) {
    SIMSR_MISSING(path << " not found");
    return;
  }
  io::NpzReader z(path);
  CHECK(z.names() == std::vector<std::string>{"lowres", "highres", "frame"});
  const auto frame = z.read("frame");
  CHECK(frame.dtype.name() == "int64");
  std::vector<std::int64_t> want(256);
  std::iota(want.begin(), want.end(), 0);
  CHECK(frame.to_vector<std::int64_t>() == want);
  const auto low = z.read("lowres");
  CHECK(low.shape == std::vector<std::int64_t>{256, 1747, 3});
  const auto p17 = low.frame_points<double>(17);
  CHECK(p17(100, 0) == -0.09837274998426437);
  CHECK(p17(100, 1) == 0.15045106410980225);
  CHECK(p17(100, 2) == 0.012302855961024761);
  const auto all = low.to_vector<double>();
  CHECK(std::accumulate(all.begin(), all.end(), 0.0) == doctest::Approx(34836.24979929999).epsilon(1e-12));
  const auto high = z.read("highres");
  CHECK(high.shape == std::vector<std::int64_t>{256, 2503, 3});
  const auto h = high.frame_points<double>(255);
  CHECK(h(2502, 0) == -0.054061293601989746);
  CHECK(h(2502, 2) == 0.0178581103682518);
  CHECK_THROWS_AS(low.to_vector<std::int64_t>(), simsr::ArgumentError);
}

TEST_CASE("npz: the ICT face expressions (float32 deltas and <U16 names)") {
  const auto path = shared / "ict_face" / "expressions.npz";
  if (!std::filesystem::exists(path)) {
    SIMSR_MISSING(path << " not found");
    return;
  }
  const auto bytes = slurp(path);
  io::NpzReader z(bytes.data(), bytes.size(), "expressions.npz");
  const auto names = z.read("names");
  CHECK(names.dtype.descr() == "<U16");
  const auto n = names.to_strings();
  REQUIRE(n.size() == 57);
  CHECK(n[0] == "PupilDilate_L");
  CHECK(n[1] == "PupilDilate_R");
  CHECK(n[2] == "browDown_L");
  CHECK(n[56] == "noseSneer_R");
  const auto d = z.read("deltas");
  CHECK(d.dtype.name() == "float32");
  CHECK(d.shape == std::vector<std::int64_t>{57, 11248, 3});
  const auto f = d.frame_points<float>(30);
  CHECK(f(5000, 0) == 0.03197000175714493f);
  CHECK(f(5000, 1) == -0.07806699723005295f);
  CHECK(d.frame_points<double>(30)(5000, 2) == -0.019999999552965164);
  const auto all = d.to_vector<double>();
  CHECK(std::accumulate(all.begin(), all.end(), 0.0) == doctest::Approx(11179.182349788798).epsilon(1e-10));
}

TEST_CASE("npz: write stored and compressed, to a file and to memory") {
  const auto dir = tmp_dir();
  const auto arrays = sample();
  for (auto c : {io::NpzCompression::Stored, io::NpzCompression::Deflate}) {
    const auto file = dir / (c == io::NpzCompression::Stored ? "s.npz" : "c.npz");
    io::write_npz(file, arrays, c);
    check_sample(io::read_npz(file));
    const auto mem = io::npz_bytes(arrays, c);
    check_sample(io::read_npz_buffer(mem.data(), mem.size()));
    if (c == io::NpzCompression::Deflate)
      CHECK(mem.size() < std::filesystem::file_size(dir / "s.npz"));  // 1000 small int32s compress well
  }
  // A writer round trip of numpy's own archive keeps names, order, dtypes and bytes.
  const auto numpy = io::read_npz(fixtures / "compressed.npz");
  const auto back = io::read_npz_buffer(io::npz_bytes(numpy).data(), io::npz_bytes(numpy).size());
  REQUIRE(back.names() == numpy.names());
  for (const auto& [name, a] : numpy) {
    CHECK(back.at(name).bytes == a.bytes);
    CHECK(back.at(name).shape == a.shape);
    CHECK(back.at(name).dtype == a.dtype);
  }
  io::NpzArrays bad;
  bad[""] = io::make_npy(std::vector<std::string>{"x"});
  CHECK_THROWS_AS(io::npz_bytes(bad), simsr::ArgumentError);

  if (!have_numpy()) {
    SIMSR_MISSING("numpy check: /usr/bin/python3 with numpy (python3-numpy) not available");
    return;
  }
  const std::string script =
      "import numpy as np, sys\n"
      "for f in sys.argv[1:]:\n"
      "    z = np.load(f)\n"
      "    assert z.files == ['m', 'names', 'x', 'empty'], z.files\n"
      "    assert np.array_equal(z['m'], [[1, 2], [3, 4], [5, 6]]) and z['m'].dtype == np.float64\n"
      "    assert list(z['names']) == ['jawOpen', 'smile']\n"
      "    assert np.array_equal(z['x'], np.arange(1000, dtype=np.int32)) and z['x'].dtype == np.int32\n"
      "    assert z['empty'].shape == (0,) and z['empty'].dtype == np.float32\n";
  std::ofstream(dir / "check.py") << script;
  CHECK(std::system(("/usr/bin/python3 " + (dir / "check.py").string() + " " + (dir / "s.npz").string() + " " +
                     (dir / "c.npz").string())
                        .c_str()) == 0);
}

TEST_CASE("npz: corrupt archives give ParseError naming the archive or member") {
  // Not a zip, empty, every truncation of a small archive.
  CHECK(parse_error_of({}).find("cannot open zip archive") != std::string::npos);
  std::vector<std::byte> junk(300, std::byte{0x41});
  CHECK(parse_error_of(junk).find("cannot open zip archive") != std::string::npos);
  const auto stored = io::npz_bytes(sample(), io::NpzCompression::Stored);
  const auto deflated = io::npz_bytes(sample(), io::NpzCompression::Deflate);
  for (const auto* full : {&stored, &deflated})
    for (std::size_t n = 0; n < full->size(); n += 7) {
      CAPTURE(n);
      const std::vector<std::byte> cut(full->begin(), full->begin() + static_cast<std::ptrdiff_t>(n));
      CHECK(parse_error_of(cut) != "no error");
    }
  // A flipped data byte: the CRC check catches it, and the message names the member.
  {
    auto b = stored;
    const auto local = find_sig(b, "PK\x03\x04").at(2);  // member "x.npy"
    b[local + 30 + 5 + 128 + 40] ^= std::byte{0x01};
    const auto msg = parse_error_of(b);
    CAPTURE(msg);
    CHECK(msg.find("x.npy") != std::string::npos);
    CHECK(msg.find("CRC") != std::string::npos);
  }
  {
    auto b = deflated;
    const auto local = find_sig(b, "PK\x03\x04").at(2);
    b[local + 30 + 5 + 20] ^= std::byte{0x10};
    const auto msg = parse_error_of(b);
    CAPTURE(msg);
    CHECK(msg.find("x.npy") != std::string::npos);
  }
  // Declared sizes that lie: huge (would allocate gigabytes), larger or smaller than the member.
  for (std::uint32_t lie : {0xfffffff0u, 0x7fffffffu, 4128u + 64u, 100u}) {
    for (const auto* full : {&stored, &deflated}) {
      auto b = *full;
      set_uncompressed_size(b, lie);
      const auto msg = parse_error_of(b);
      CAPTURE(lie);
      CAPTURE(msg);
      CHECK(msg != "no error");
    }
  }
  {
    auto b = deflated;
    set_uncompressed_size(b, 0xfffffff0u);
    CHECK(parse_error_of(b).find("impossible") != std::string::npos);
  }
  // A well-formed zip whose member is not a valid .npy: the npy error carries the member name.
  {
    io::NpzArrays a;
    a["fine"] = io::make_npy(std::vector<std::string>{"ok"});
    const std::int16_t none = 0;
    a["bad"] = io::make_npy<std::int16_t>({0}, &none);
    auto b = io::npz_bytes(a);
    // "'shape': (0,)" becomes "(9,)": the .npy parser refuses it before libzip reaches the CRC.
    const std::string needle = "'shape': (0,)";
    bool patched = false;
    for (std::size_t i = find_sig(b, "PK\x03\x04").at(1); i + needle.size() < b.size(); ++i)
      if (std::memcmp(b.data() + i, needle.data(), needle.size()) == 0) {
        b[i + 10] = std::byte{'9'};
        patched = true;
        break;
      }
    REQUIRE(patched);
    const auto msg = parse_error_of(b);
    CAPTURE(msg);
    CHECK(msg.find("bad.npy") != std::string::npos);
  }
  CHECK_THROWS_AS(io::read_npz(fixtures / "missing.npz"), simsr::ParseError);
  CHECK_THROWS_AS(io::read_npz(fixtures / "f8_c.npy"), simsr::ParseError);
  io::NpzReader ok(fixtures / "stored.npz");
  CHECK_THROWS_AS(ok.read("missing"), simsr::ArgumentError);
  // A cap on the uncompressed member size.
  ok.set_max_member_bytes(200);
  CHECK(ok.read("scalar").item<int>() == 7);
  try {
    ok.read("frames");
    FAIL("no error");
  } catch (const simsr::ParseError& e) {
    CHECK(e.file() == (fixtures / "stored.npz").string() + ":frames.npy");
    CHECK(e.message().find("exceeds the limit of 200 bytes") != std::string::npos);
  }
}

}  // namespace io_test_npz
