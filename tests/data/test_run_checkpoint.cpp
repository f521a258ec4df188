// The resumable runs' file helpers (data/run_checkpoint.hpp): a checkpoint's frames come back
// exactly, and a bad one is an error naming the file.
#include <doctest/doctest.h>

#include <simsr/data/run_checkpoint.hpp>

#include <unistd.h>

#include <filesystem>
#include <string>

namespace data_test_run_checkpoint {

using namespace simsr;

data::PairedFrames<> frames_of(Index F, Index N, Index M, double seed) {
  data::PairedFrames<> p;
  p.lowres = data::FrameMatrix<double>::Random(F, 3 * N) + data::FrameMatrix<double>::Constant(F, 3 * N, seed);
  p.highres = data::FrameMatrix<double>::Random(F, 3 * M);
  return p;
}

TEST_CASE("run checkpoint: the frames so far and the fingerprint round-trip; bad counts, shapes and missing arrays are named") {
  const data::PairedFrames<> run = frames_of(6, 4, 9, 0.5);
  io::NpzArrays z = data::frames_checkpoint(run, 4, "abc123");
  CHECK(io::fingerprint_of(z) == "abc123");
  data::PairedFrames<> resumed = frames_of(6, 4, 9, 7.0);  // sized for the whole sequence
  CHECK(data::resume_frames(z, "x.npz", resumed) == 4);
  CHECK(resumed.lowres.topRows(4) == run.lowres.topRows(4));
  CHECK(resumed.highres.topRows(4) == run.highres.topRows(4));
  // an npz round trip keeps them bitwise
  const auto file = std::filesystem::temp_directory_path() / ("simsr_test_run_checkpoint_" + std::to_string(::getpid()) + ".npz");
  io::write_npz(file, z);
  const io::NpzArrays back = io::read_npz(file);
  std::filesystem::remove(file);
  CHECK(io::fingerprint_of(back) == "abc123");
  data::PairedFrames<> again = frames_of(6, 4, 9, 3.0);
  CHECK(data::resume_frames(back, "x.npz", again) == 4);
  CHECK(again.lowres.topRows(4) == run.lowres.topRows(4));
  // points and scalars
  const Points<> p = Points<>::Random(5, 3);
  z["p"] = io::make_npy(p);
  const double h = 0.25;
  z["h"] = io::make_npy<double>({}, &h);
  CHECK(io::points_of(z, "p", 5, "x.npz") == p);
  CHECK(io::scalar_of(z, "h", "x.npz") == 0.25);
  CHECK_THROWS_AS(io::points_of(z, "p", 6, "x.npz"), ShapeError);
  CHECK_THROWS_WITH_AS(io::points_of(z, "q", 5, "x.npz"), doctest::Contains("x.npz: no 'q'"), ArgumentError);
  CHECK_THROWS_AS(io::scalar_of(z, "p", "x.npz"), ArgumentError);
  CHECK(io::fingerprint_of(io::NpzArrays{}).empty());
  // a count past the sequence, frames of other meshes
  data::PairedFrames<> shorter = frames_of(3, 4, 9, 0);
  CHECK_THROWS_WITH_AS(data::resume_frames(z, "x.npz", shorter), doctest::Contains("frames_done 4 outside [1, 3]"), ArgumentError);
  data::PairedFrames<> other = frames_of(6, 5, 9, 0);
  CHECK_THROWS_WITH_AS(data::resume_frames(z, "x.npz", other), doctest::Contains("do not match"), ArgumentError);
  CHECK_THROWS_AS(data::resume_frames(io::NpzArrays{}, "x.npz", other), ArgumentError);
}

}  // namespace data_test_run_checkpoint
