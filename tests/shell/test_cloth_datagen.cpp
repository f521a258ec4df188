// The SHEET / DISK datagen (issue #14 item 3) at a reduced size: files, split, a killed run
// resuming bitwise, another run's checkpoint refused, a finished file reused.
#include <doctest/doctest.h>

#include <simsr/shell/cloth_data.hpp>
#include <simsr/shell/cloth_datagen.hpp>

#include <fstream>
#include <stdexcept>

#include "../support/error_of.hpp"
#include "../support/scratch_dir.hpp"

namespace shell_test_cloth_datagen {

using namespace simsr;
using namespace simsr::shell;

ClothDatagenOptions small_sheet() {
  ClothDatagenOptions o;
  o.size = {3, 1};  // 16 / 49 vertices
  o.sequences = 5;  // the 5th held out
  o.extra_seconds = 0;
  o.settle_frames = 5;
  o.checkpoint_every = 4;
  o.simulation.frame_time = 0.1;
  return o;
}

TEST_CASE("cloth datagen (SHEET, reduced): every sequence at both resolutions, the 5th held out; a killed run resumes bitwise; another run is refused") {
  test::ScratchDir whole("simsr_test_cloth_whole"), resumed("simsr_test_cloth_resumed");
  ClothDatagenOptions opt = small_sheet();
  opt.sequences = 2;
  const auto stats = generate_cloth_data(exec::omp, ClothDataset::sheet, whole.path, opt);
  REQUIRE(stats.size() == 2);
  for (const auto& s : stats) {
    CHECK_FALSE(s.reused);
    CHECK(s.simulated == s.frames);
    CHECK(s.frames >= 15);  // 1.9-3.9 s at 10 frames per second
    CHECK(s.fine_iterations >= s.frames);
    CHECK(s.deepest > -0.01);
    CHECK(s.subdivided_rmse > 0);
    CHECK_FALSE(s.test);
    const auto p = data::read_paired_frames(whole.path / (s.name + ".npz"), 16, 49);
    CHECK(p.num_frames() == s.frames);
    CHECK(p.lowres.allFinite());
    CHECK(p.highres.allFinite());
  }
  CHECK(std::filesystem::exists(whole.path / "coarse_rest.obj"));
  CHECK(std::filesystem::exists(whole.path / "fine_rest.obj"));
  const auto json = nlohmann::json::parse(std::ifstream(whole.path / "cloth_data.json"));
  CHECK(json["coarse"]["vertices"] == 16);
  CHECK(json["fine"]["vertices"] == 49);
  CHECK(json["sequences"].size() == 2);
  CHECK(json["substeps"] == 8);  // ClothOptions' default: inexact steps, 8 per frame
  CHECK(json["newton"]["max_iterations"] == 3);
  CHECK(json["newton"]["accept_at_max_iterations"] == true);
  CHECK(json["newton"]["hessian"] == "projected");
  // each sequence's parameters, as sheet_sequences drew them (the fingerprint's values, named)
  const auto drawn = sheet_sequences(2, opt.seed);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& scene = json["sequences"][k]["scene"];
    CHECK(scene.size() == 9);
    CHECK(scene["pole"].get<double>() == double(drawn[k].pole));
    CHECK(scene["radius_m"].get<double>() == drawn[k].radius);
    CHECK(scene["heading_rad"].get<double>() == drawn[k].heading);
    CHECK(scene["centre_z_m"].get<double>() == drawn[k].centre.z());
    CHECK(scene["hold_s"].get<double>() == drawn[k].hold_time);
  }
  CHECK(json["sequences"][0]["scene"]["pole"] == 1);  // sequence 0 is the pole
  CHECK(cloth_sequence_is_test(4));
  CHECK_FALSE(cloth_sequence_is_test(3));

  // killed at frame 6 of the second sequence (checkpointed at 4), resumed: bitwise the same
  Index kill_at = 6, simulated = 0;
  std::string killed_in = cloth_sequence_name(ClothDataset::sheet, 1);
  ClothDatagenOptions k = opt;
  k.on_frame = [&](const std::string& seq, Index f, Index, const ClothFrameReport&, const ClothFrameReport&, double, double) {
    ++simulated;
    if (seq == killed_in && f == kill_at) throw std::runtime_error("killed");
  };
  CHECK_THROWS_AS(generate_cloth_data(exec::omp, ClothDataset::sheet, resumed.path, k), std::runtime_error);
  CHECK(std::filesystem::exists(resumed.path / ".state" / (killed_in + ".npz")));
  ClothDatagenOptions other = k;
  other.material.stretch *= 2;
  CHECK(test::error_of([&] { generate_cloth_data(exec::omp, ClothDataset::sheet, resumed.path, other); }).find("another run") != std::string::npos);
  kill_at = -1;
  simulated = 0;
  const auto again = generate_cloth_data(exec::omp, ClothDataset::sheet, resumed.path, k);
  CHECK(again[0].reused);  // the first sequence was finished before the kill
  CHECK(simulated == stats[1].frames - 4);
  for (const auto& s : stats) {
    const auto a = data::read_paired_frames(whole.path / (s.name + ".npz")), b = data::read_paired_frames(resumed.path / (s.name + ".npz"));
    CHECK(a.lowres == b.lowres);
    CHECK(a.highres == b.highres);
  }
  CHECK_FALSE(std::filesystem::exists(resumed.path / ".state" / (killed_in + ".npz")));
  CHECK(again[1].subdivided_rmse == stats[1].subdivided_rmse);
  CHECK_THROWS_AS(generate_cloth_data(exec::omp, ClothDataset::sheet, resumed.path, [] { auto o = small_sheet(); o.checkpoint_every = 0; return o; }()), ArgumentError);
}

TEST_CASE("cloth datagen (DISK, reduced): the wind's sequences, the draped start shared") {
  test::ScratchDir dir("simsr_test_cloth_disk");
  ClothDatagenOptions opt;
  opt.size = {2, 1};  // 19 / 61 vertices
  opt.sequences = 2;
  opt.settle_frames = 10;
  opt.simulation.frame_time = 0.2;
  const auto stats = generate_cloth_data(exec::omp, ClothDataset::disk, dir.path, opt);
  REQUIRE(stats.size() == 2);
  CHECK(stats[0].frames == 20);  // 4 s at 5 frames per second
  const auto a = data::read_paired_frames(dir.path / "disk_000.npz"), b = data::read_paired_frames(dir.path / "disk_001.npz");
  // both start from the same draped state and the stronger wind moves the cloth further
  const double moved_a = (a.hr(a.num_frames() - 1) - a.hr(0)).rowwise().norm().mean(), moved_b = (b.hr(b.num_frames() - 1) - b.hr(0)).rowwise().norm().mean();
  MESSAGE("DISK 19/61: mean fine-vertex motion over the sequence, 1 m/s wind " << moved_a << " m, 8 m/s " << moved_b << " m");
  CHECK(moved_b > moved_a);
  CHECK(stats[0].deepest > -0.01);
  // the step count and each sequence's wind in the summary
  const auto json = nlohmann::json::parse(std::ifstream(dir.path / "cloth_data.json"));
  CHECK(json["substeps"] == 8);
  CHECK(json["sequences"][1]["scene"]["wind_m_per_s"].get<double>() == doctest::Approx(8));
  CHECK(json["sequences"][0]["scene"]["heading_rad"].get<double>() == disk_sequences(2, opt.seed)[0].heading);
  // another step count is another run (a copy of the first file is not reused) with other frames
  {
    test::ScratchDir four_dir("simsr_test_cloth_disk_four");
    std::filesystem::create_directories(four_dir.path);
    std::filesystem::copy_file(dir.path / "disk_000.npz", four_dir.path / "disk_000.npz");
    ClothDatagenOptions four = opt;
    four.sequences = 1;
    four.simulation.substeps = 4;
    const auto other = generate_cloth_data(exec::omp, ClothDataset::disk, four_dir.path, four);
    CHECK_FALSE(other[0].reused);
    CHECK(nlohmann::json::parse(std::ifstream(four_dir.path / "cloth_data.json"))["substeps"] == 4);
    const auto c = data::read_paired_frames(four_dir.path / "disk_000.npz");
    CHECK((c.hr(c.num_frames() - 1) - a.hr(a.num_frames() - 1)).cwiseAbs().maxCoeff() > 0);
    // steps solved to convergence are another run too
    std::filesystem::copy_file(dir.path / "disk_000.npz", four_dir.path / "disk_000.npz", std::filesystem::copy_options::overwrite_existing);
    ClothDatagenOptions converged = four;
    converged.simulation.substeps = opt.simulation.substeps;
    converged.simulation.newton = cloth_newton_options(ClothStepping::converged);
    CHECK_FALSE(generate_cloth_data(exec::omp, ClothDataset::disk, four_dir.path, converged)[0].reused);
    CHECK(nlohmann::json::parse(std::ifstream(four_dir.path / "cloth_data.json"))["newton"]["hessian"] == "regularized");
    ClothDatagenOptions none = four;
    none.simulation.substeps = 0;
    CHECK(test::typed_error_of<ArgumentError>([&] { generate_cloth_data(exec::seq, ClothDataset::disk, four_dir.path, none); }).find("substeps") !=
          std::string::npos);
    // a C² contact (an onset depth) is another run too, and a negative one is refused by name
    ClothDatagenOptions smooth = four;
    smooth.simulation.contact_onset = 2e-3;
    CHECK_FALSE(generate_cloth_data(exec::omp, ClothDataset::disk, four_dir.path, smooth)[0].reused);
    CHECK(generate_cloth_data(exec::omp, ClothDataset::disk, four_dir.path, smooth)[0].reused);
    smooth.simulation.contact_onset = -1e-3;
    CHECK(test::typed_error_of<ArgumentError>([&] { generate_cloth_data(exec::seq, ClothDataset::disk, four_dir.path, smooth); }).find("onset") !=
          std::string::npos);
  }
  // three sequences spread the speeds 1, 4.5, 8 m/s: the first file is the same sequence and is
  // reused, the second (8 m/s before) is another one and is simulated again
  opt.sequences = 3;
  const auto again = generate_cloth_data(exec::omp, ClothDataset::disk, dir.path, opt);
  REQUIRE(again.size() == 3);
  CHECK(again[0].reused);
  CHECK_FALSE(again[1].reused);
  CHECK_FALSE(again[2].reused);
}

TEST_CASE("cloth datagen: sequences side by side are bitwise the sequences one at a time; a failed sequence ends the run, the others' kept") {
  test::ScratchDir one("simsr_test_cloth_one"), three("simsr_test_cloth_three"), failing("simsr_test_cloth_failing");
  ClothDatagenOptions opt = small_sheet();
  opt.sequences = 3;
  opt.sequence_workers = 1;
  const auto a = generate_cloth_data(exec::omp, ClothDataset::sheet, one.path, opt);
  opt.sequence_workers = 3;
  Index calls = 0, settle_calls = 0;
  opt.on_frame = [&](const std::string&, Index, Index, const ClothFrameReport&, const ClothFrameReport&, double, double) { ++calls; };
  // the shared start's settling reports its frames too, through its own callback
  opt.on_settle_frame = [&](const std::string& name, Index f, Index F, const ClothFrameReport& c, const ClothFrameReport& fi, double sc, double sf) {
    CHECK(name == "settle");
    CHECK(f == settle_calls);
    CHECK(F == opt.settle_frames);
    CHECK(c.newton_iterations >= 1);
    CHECK(fi.newton_iterations >= 1);
    CHECK(sc >= 0);
    CHECK(sf >= 0);
    ++settle_calls;
  };
  const auto b = generate_cloth_data(exec::omp, ClothDataset::sheet, three.path, opt);
  CHECK(settle_calls == opt.settle_frames);
  // a settled start read from its file calls nothing (the finished sequences are reused)
  generate_cloth_data(exec::omp, ClothDataset::sheet, three.path, opt);
  CHECK(settle_calls == opt.settle_frames);
  opt.on_settle_frame = nullptr;
  REQUIRE(a.size() == 3);
  REQUIRE(b.size() == 3);
  Index frames = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(a[k].name == b[k].name);  // in sequence order, whichever worker finished first
    CHECK(a[k].frames == b[k].frames);
    CHECK(a[k].fine_iterations == b[k].fine_iterations);
    CHECK(a[k].subdivided_rmse == b[k].subdivided_rmse);
    frames += b[k].frames;
    const auto p = data::read_paired_frames(one.path / (a[k].name + ".npz")), q = data::read_paired_frames(three.path / (b[k].name + ".npz"));
    CHECK(p.lowres == q.lowres);
    CHECK(p.highres == q.highres);
  }
  CHECK(calls == frames);  // every frame reported (not again when reused), the counter never raced (calls are serialized)

  // the first sequence fails at its 3rd frame: its error ends the run after the second sequence,
  // which another worker had, is finished and written
  opt.sequence_workers = 2;
  opt.on_frame = [&](const std::string& seq, Index f, Index, const ClothFrameReport&, const ClothFrameReport&, double, double) {
    if (seq == a[0].name && f == 2) throw std::runtime_error("sequence 0 failed at frame 2");
  };
  CHECK(test::typed_error_of<std::runtime_error>([&] { generate_cloth_data(exec::omp, ClothDataset::sheet, failing.path, opt); }) == "sequence 0 failed at frame 2");
  CHECK_FALSE(std::filesystem::exists(failing.path / (a[0].name + ".npz")));
  CHECK(std::filesystem::exists(failing.path / (a[1].name + ".npz")));

  // several workers need exec::omp; a negative count is refused, both before anything is written
  opt.on_frame = nullptr;
  test::ScratchDir refused("simsr_test_cloth_refused");
  CHECK(test::error_of([&] { generate_cloth_data(exec::seq, ClothDataset::sheet, refused.path / "d", opt); }).find("exec::seq") != std::string::npos);
  opt.sequence_workers = -1;
  CHECK_THROWS_AS(generate_cloth_data(exec::omp, ClothDataset::sheet, refused.path / "d", opt), ArgumentError);
  CHECK_FALSE(std::filesystem::exists(refused.path / "d"));
}

TEST_CASE("cloth datagen, a coarse sheet of other cells beside the same fine sheet: the fine frames taken from that dataset are bitwise the fine cloth simulated again; another simulation's refused") {
  test::ScratchDir standard("simsr_test_cloth_fine_standard"), taken("simsr_test_cloth_fine_taken"), again("simsr_test_cloth_fine_again"),
      refused("simsr_test_cloth_fine_refused");
  ClothDatagenOptions opt = small_sheet();
  opt.sequences = 2;
  const auto a = generate_cloth_data(exec::omp, ClothDataset::sheet, standard.path, opt);  // 3 cells, Loop once: 16 / 49
  ClothDatagenOptions coarser = opt;
  coarser.size = {2, 1, 3};  // a 2-cell coarse sheet (9 vertices), the same 49-vertex fine one
  coarser.fine_frames_from = standard.path;
  Index fine_newton = 0;
  coarser.on_frame = [&](const std::string&, Index, Index, const ClothFrameReport&, const ClothFrameReport& f, double, double) { fine_newton += f.newton_iterations; };
  const auto b = generate_cloth_data(exec::omp, ClothDataset::sheet, taken.path, coarser);
  CHECK(fine_newton == 0);  // the fine cloth never stepped
  coarser.fine_frames_from.clear();
  const auto c = generate_cloth_data(exec::omp, ClothDataset::sheet, again.path, coarser);  // both simulated
  CHECK(fine_newton > 0);
  REQUIRE(b.size() == 2);
  REQUIRE(c.size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    CHECK(b[k].fine_reused);
    CHECK_FALSE(c[k].fine_reused);
    CHECK(b[k].fine_iterations == 0);
    CHECK(c[k].fine_iterations == a[k].fine_iterations);
    const auto p = data::read_paired_frames(standard.path / (a[k].name + ".npz"), 16, 49);
    const auto q = data::read_paired_frames(taken.path / (b[k].name + ".npz"), 9, 49);
    const auto r = data::read_paired_frames(again.path / (c[k].name + ".npz"), 9, 49);
    CHECK(q.highres == p.highres);  // taken
    CHECK(r.highres == p.highres);  // simulated again: the same simulation, bitwise
    CHECK(r.lowres == q.lowres);
    CHECK(b[k].subdivided_rmse == c[k].subdivided_rmse);
    CHECK(b[k].subdivided_rmse > 0);
  }
  const auto json = nlohmann::json::parse(std::ifstream(taken.path / "cloth_data.json"));
  CHECK(json["coarse_cells"] == 2);
  CHECK(json["fine"]["cells"] == 3);
  CHECK(json["coarse"]["vertices"] == 9);
  CHECK(json["fine_frames_from"] == standard.path.string());
  CHECK(json["sequences"][0]["fine_reused"] == true);
  CHECK_FALSE(nlohmann::json::parse(std::ifstream(again.path / "cloth_data.json")).contains("fine_frames_from"));
  // read back: the pair rebuilt with its fine cloth of its own
  const ClothData d = read_cloth_data(taken.path);
  CHECK(d.size.fine_cells == 3);
  CHECK(d.num_coarse() == 9);
  CHECK(d.num_fine() == 49);

  // refused before anything is simulated, each naming the file: another seed's fine cloth, a
  // sequence the source lacks, a file without the fine fingerprint, the output folder itself
  ClothDatagenOptions other = coarser;
  other.fine_frames_from = standard.path;
  other.seed = opt.seed + 1;
  const std::string file0 = (standard.path / "sheet_000.npz").string();
  std::string e = test::typed_error_of<ArgumentError>([&] { generate_cloth_data(exec::omp, ClothDataset::sheet, refused.path / "seed", other); });
  CHECK(e.find(file0) != std::string::npos);
  CHECK(e.find("another simulation's") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(refused.path / "seed"));
  other.seed = opt.seed;
  other.sequences = 3;
  e = test::typed_error_of<ArgumentError>([&] { generate_cloth_data(exec::omp, ClothDataset::sheet, refused.path / "count", other); });
  CHECK(e.find("sheet_002.npz: no such file") != std::string::npos);
  other.sequences = 2;
  other.fine_frames_from = taken.path;  // its fine frames are the same simulation: taken again is fine ...
  CHECK(generate_cloth_data(exec::omp, ClothDataset::sheet, refused.path / "chain", other)[1].fine_reused);
  {  // ... but not from a file written before fine fingerprints
    std::filesystem::create_directories(refused.path / "old");
    io::NpzArrays z = io::read_npz(standard.path / "sheet_000.npz"), old;
    for (const auto& [name, array] : z)
      if (name != "fine_fingerprint") old[name] = array;
    io::write_npz(refused.path / "old" / "sheet_000.npz", old);
    std::filesystem::copy_file(standard.path / "sheet_001.npz", refused.path / "old" / "sheet_001.npz");
    other.fine_frames_from = refused.path / "old";
    CHECK(test::typed_error_of<ArgumentError>([&] { generate_cloth_data(exec::omp, ClothDataset::sheet, refused.path / "from_old", other); })
              .find("no fine-cloth fingerprint") != std::string::npos);
  }
  other.fine_frames_from = taken.path;
  CHECK(test::typed_error_of<ArgumentError>([&] { generate_cloth_data(exec::omp, ClothDataset::sheet, taken.path, other); }).find("output folder") !=
        std::string::npos);
  // a fine cloth of its own for DISK is refused (its vase is the first ring)
  ClothDatagenOptions disk;
  disk.size = {3, 1, 4};
  CHECK(test::typed_error_of<ArgumentError>([&] { generate_cloth_data(exec::omp, ClothDataset::disk, refused.path / "disk", disk); }).find("first ring") !=
        std::string::npos);
}

}  // namespace shell_test_cloth_datagen
