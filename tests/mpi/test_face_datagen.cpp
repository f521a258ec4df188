// The face's data over MPI ranks (mpi/face_datagen.hpp), on the coarse model of the scenario
// suite with two one-frame performances from controls: 2 ranks, one performance each, write the
// single process's files bitwise and the same summary figures (timings aside).
#include <doctest/doctest.h>

#include <simsr/io/npz.hpp>
#include <simsr/mpi/face_datagen.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "../scenario/face_fixture.hpp"
#include "../support/require.hpp"
#include "../support/same_arrays.hpp"

namespace mpi_test_face_datagen {

using namespace simsr;
namespace fs = std::filesystem;

/// A controls file of F frames rising to `peak` of the named expressions.
fs::path write_controls(const fs::path& dir, const std::string& name, const std::vector<std::string>& names, double peak, Index F) {
  Eigen::MatrixXd w(F, Index(names.size()));
  for (Index f = 0; f < F; ++f) w.row(f).setConstant(peak * double(f + 1) / double(F));
  io::NpzArrays z;
  z["names"] = io::make_npy(names);
  z["weights"] = io::make_npy(w);
  const fs::path file = dir / (name + "_controls.npz");
  io::write_npz(file, z);
  return file;
}

TEST_CASE("mpi::generate_face_dataset: 2 ranks, a performance each, write the single process's files bitwise") {
  SIMSR_REQUIRE_FACE_INPUTS();
  const mpi::Communicator world = mpi::Communicator::world();
  REQUIRE(world.size() == 2);
  const fs::path root = fs::path(SIMSR_TEST_TMP_DIR) / "mpi_face", controls = root / "controls", ranks = root / "ranks", single = root / "single";
  if (world.is_root()) {
    fs::remove_all(root);
    fs::create_directories(controls);
  }
  world.barrier();
  scenario::FaceDatasetOptions o;
  o.kit = test::ict_kit_dir;
  o.model = test::coarse_face_options();
  o.performances.clear();
  o.controls = {root / "controls" / "smile_controls.npz", root / "controls" / "jaw_controls.npz"};
  if (world.is_root()) {
    write_controls(controls, "smile", {"mouthSmile_L", "mouthSmile_R"}, 0.6, 1);  // one frame each: the HR solves are the cost
    write_controls(controls, "jaw", {"jawOpen"}, 0.3, 1);
  }
  o.vtk_every = 0;
  o.unseen_forces = false;
  world.barrier();

  std::vector<std::string> lines;
  const auto j = mpi::generate_face_dataset(exec::omp, world, o, ranks, [&](const std::string& l) { lines.push_back(l); });
  // rank 0 simulates smile, rank 1 jaw: each reports its own frames only
  const std::string mine = world.rank() == 0 ? "smile" : "jaw", theirs = world.rank() == 0 ? "jaw" : "smile";
  const auto frame_lines_of = [&](const std::string& name) {
    return std::count_if(lines.begin(), lines.end(), [&](const std::string& l) { return l.find("datagen: " + name) == 0 && l.find(" frame ") != std::string::npos; });
  };
  CHECK(frame_lines_of(mine) == 1);
  CHECK(frame_lines_of(theirs) == 0);
  CHECK(j["ranks"] == 2);
  REQUIRE(j["performances"].size() == 2);
  for (const auto& p : j["performances"]) {
    CHECK(p["simulated"] == 1);  // the simulating rank's figures
    CHECK(p["reused"] == false);
    CHECK(p.contains("hr_seconds_per_frame"));
  }
  CHECK(fs::exists(ranks / "face_data.json"));

  // Each rank then simulates the other rank's performance in a single process of its own (a
  // performance's file depends on the model, the settled neutral and its controls only, so this
  // is the single-process run's file; both ranks at once: each HR frame is ~20 s at one thread).
  // It starts from the ranks' settled neutral (the same model: the fingerprint matches, so it is
  // read, not solved again).
  const fs::path alone = single / ("rank_" + std::to_string(world.rank()));
  fs::create_directories(alone / ".state");
  fs::copy_file(ranks / ".state" / "neutral.npz", alone / ".state" / "neutral.npz");
  scenario::FaceDatasetOptions other = o;
  other.controls = {root / "controls" / (theirs + "_controls.npz")};
  const auto s = scenario::generate_face_dataset(exec::omp, other, alone);
  for (const std::string& name : {theirs + ".npz", theirs + "_controls.npz", std::string("hr_lips.npz")})
    test::check_same_arrays(ranks / name, alone / name, {});
  for (const char* f : {"lr_rest.msh", "hr_rest.obj", "hr_volume.msh"})
    CHECK(io::detail::read_text_file(ranks / f) == io::detail::read_text_file(alone / f));
  const std::size_t p = world.rank() == 0 ? 1 : 0;  // the other performance's entry in the ranks' summary
  REQUIRE(s["performances"].size() == 1);
  for (const char* key : {"name", "frames", "embedded_lr_to_hr_mean_distance_m", "hr_mean_skin_displacement_m", "hr_frames_with_intersecting_lips"})
    CHECK(j["performances"][p][key] == s["performances"][0][key]);
}

}  // namespace mpi_test_face_datagen
