// The run-file helpers (io/run_file.hpp) and whole-file reads (io/text_file.hpp): a fingerprint
// survives an npz round trip and is "" when absent; named arrays come back as written, and a
// missing, misshapen or non-scalar array is a typed error naming the file and the array.
#include <doctest/doctest.h>

#include <simsr/io/atomic_file.hpp>
#include <simsr/io/run_file.hpp>
#include <simsr/io/text_file.hpp>

#include <random>

#include "../support/error_of.hpp"
#include "../support/scratch_dir.hpp"

namespace io_test_run_file {

using namespace simsr;

TEST_CASE("io::run_file: fingerprints and named arrays through an npz file; bad arrays named") {
  test::ScratchDir dir("simsr_test_run_file");
  std::filesystem::create_directories(dir.path);
  const auto file = dir.path / "run.npz";
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  Points<> x(7, 3);
  for (Index i = 0; i < x.size(); ++i) x.data()[i] = u(rng);
  const double h = u(rng);
  io::NpzArrays z;
  CHECK(io::fingerprint_of(z).empty());
  z["x"] = io::make_npy(x);
  z["h"] = io::make_npy<double>({}, &h);
  io::set_fingerprint(z, "0123456789abcdef");
  io::write_npz(file, z);
  const io::NpzArrays back = io::read_npz(file);
  CHECK(io::fingerprint_of(back) == "0123456789abcdef");
  CHECK(io::points_of(back, "x", 7, file.string()) == x);
  CHECK(io::scalar_of(back, "h", file.string()) == h);
  CHECK(test::typed_error_of<ArgumentError>([&] { io::points_of(back, "y", 7, file.string()); }).find("'y'") != std::string::npos);
  const std::string shape = test::typed_error_of<ShapeError>([&] { io::points_of(back, "x", 8, file.string()); });
  CHECK(shape.find("run.npz") != std::string::npos);
  CHECK(test::typed_error_of<ArgumentError>([&] { io::scalar_of(back, "x", file.string()); }).find("not a scalar") != std::string::npos);
  CHECK(test::typed_error_of<ArgumentError>([&] { io::scalar_of(back, "g", file.string()); }).find("no 'g'") != std::string::npos);
}

TEST_CASE("io::read_text_file: the bytes as written; a missing file is a ParseError naming it and what it should be") {
  test::ScratchDir dir("simsr_test_text_file");
  std::filesystem::create_directories(dir.path);
  std::string bytes = "{\"a\": 1}\n";
  bytes.push_back('\0');
  bytes += "tail\r\n";
  io::write_file_atomic(dir.path / "t.json", bytes);
  CHECK(io::read_text_file(dir.path / "t.json") == bytes);
  const std::string e = test::typed_error_of<ParseError>([&] { io::read_text_file(dir.path / "none.json", "a summary"); });
  CHECK(e.find("none.json") != std::string::npos);
  CHECK(e.find("a summary") != std::string::npos);
}

}  // namespace io_test_run_file
