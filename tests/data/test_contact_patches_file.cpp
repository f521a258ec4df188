// data::write_contact_patches / read_contact_patches (DIR/hr_lips.npz of the face data): a round
// trip of random patches, and every malformed file named.
#include <simsr/data/contact_patches_file.hpp>

#include <doctest/doctest.h>

#include <filesystem>
#include <random>

using namespace simsr;

namespace {
std::filesystem::path tmp_file(const std::string& name) {
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "contact_patches";
  std::filesystem::create_directories(dir);
  return dir / name;
}
}  // namespace

TEST_CASE("data::contact patches file: random patches read back equal") {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 10; ++trial) {
    const Index M = 30 + 10 * trial;
    std::uniform_int_distribution<int> ta(1, 12), tb(1, 12), va(0, int(M / 2) - 1), vb(int(M / 2), int(M) - 1);
    ContactPatches p;
    p.a.resize(ta(rng), 3);
    p.b.resize(tb(rng), 3);
    for (Index i = 0; i < p.a.size(); ++i) p.a.data()[i] = VIndex(va(rng));
    for (Index i = 0; i < p.b.size(); ++i) p.b.data()[i] = VIndex(vb(rng));
    const auto file = tmp_file("round_trip.npz");
    data::write_contact_patches(file, p, M);
    const ContactPatches q = data::read_contact_patches(file, M);
    CHECK(q.a == p.a);
    CHECK(q.b == p.b);
    CHECK(q.fingerprint() == p.fingerprint());
  }
}

TEST_CASE("data::contact patches file: a missing array, a wrong shape, a bad index and a shared vertex are named") {
  const auto file = tmp_file("bad.npz");
  ContactPatches p;
  p.a = Tris(1, 3);
  p.a << 0, 1, 2;
  p.b = Tris(1, 3);
  p.b << 3, 4, 5;
  CHECK_THROWS_WITH_AS(data::write_contact_patches(file, p, 5), doctest::Contains("patch b triangle 0 has vertex 5 outside [0, 5)"), ArgumentError);
  data::write_contact_patches(file, p, 6);
  CHECK_THROWS_WITH_AS(data::read_contact_patches(file, 5), doctest::Contains("bad.npz: patch b triangle 0 has vertex 5"), ArgumentError);
  {
    io::NpzArrays z;
    z["a"] = io::make_npy(p.a);
    io::write_npz(file, z);
    CHECK_THROWS_WITH_AS(data::read_contact_patches(file, 6), doctest::Contains("no array 'b'"), ArgumentError);
  }
  {
    io::NpzArrays z;
    z["a"] = io::make_npy(p.a);
    const Eigen::Matrix<std::int32_t, 2, 2, Eigen::RowMajor> two = Eigen::Matrix<std::int32_t, 2, 2, Eigen::RowMajor>::Zero();
    z["b"] = io::make_npy(two);
    io::write_npz(file, z);
    CHECK_THROWS_WITH_AS(data::read_contact_patches(file, 6), doctest::Contains("b (triangles)"), ShapeError);
  }
  {
    ContactPatches shared = p;
    shared.b(0, 0) = 2;
    CHECK_THROWS_WITH_AS(data::write_contact_patches(file, shared, 6), doctest::Contains("vertex 2 belongs to both"), ArgumentError);
    ContactPatches empty = p;
    empty.b.resize(0, 3);
    CHECK_THROWS_WITH_AS(data::write_contact_patches(file, empty, 6), doctest::Contains("at least one triangle"), ArgumentError);
  }
}
