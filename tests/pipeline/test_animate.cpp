// pipeline::animate_face (simsr animate) on the coarse face model: a controls file played live,
// pipelined and unpipelined; the LR frames are the live source's, the HR frames the network
// applied to them by hand; the files it promises; the same network from a saved model file; a
// model of another mesh and bad options refused with errors that say so.
#include <simsr/io/npz.hpp>
#include <simsr/io/vtu.hpp>
#include <simsr/pipeline/animate.hpp>

#include <doctest/doctest.h>
#include "../scenario/face_fixture.hpp"
#include "../support/require.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

using namespace simsr;

namespace pipeline_animate {

std::filesystem::path write_controls(const std::filesystem::path& dir, Index frames) {
  std::filesystem::create_directories(dir);
  io::NpzArrays z;
  z["names"] = io::make_npy(std::vector<std::string>{"jawOpen", "mouthSmile_L", "mouthSmile_R"});
  Eigen::MatrixXd w(frames, 3);
  for (Index f = 0; f < frames; ++f) w.row(f) << 0.1 + 0.1 * double(f), 0.3 * double(f), 0.2 * double(f);
  z["weights"] = io::make_npy(w);
  const auto file = dir / "smile_controls.npz";
  io::write_npz(file, z);
  return file;
}

TEST_CASE("pipeline::animate_face: live frames on the coarse face, pipelined = unpipelined = the network by hand; a model file; another mesh refused") {
  SIMSR_REQUIRE_FACE_INPUTS();
  const auto& face = test::coarse_face();
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "pipeline_animate";
  std::filesystem::remove_all(dir);
  const Index frames = 2;
  pipeline::AnimateOptions o;
  o.kit = test::ict_kit_dir;
  o.model = test::coarse_face_options();
  o.untrained = true;
  o.recipe.seed = 4;
  o.neighborhood_k = 10;
  o.controls = {write_controls(dir, frames)};
  o.out = dir / "untrained";
  o.vtk_every = 2;
  const auto report = pipeline::animate_face(exec::omp, o);

  REQUIRE(report["performances"].size() == 1);
  const auto& p = report["performances"][0];
  CHECK(p["name"] == "smile");
  CHECK(p["frames"] == frames);
  for (const char* mode : {"pipelined", "unpipelined"}) {
    CAPTURE(mode);
    CHECK(p[mode]["frames"] == frames);
    CHECK(p[mode]["end_to_end_fps"].get<double>() > 0);
    CHECK(p[mode]["lr_simulation_fps"].get<double>() > 0);
    CHECK(p[mode]["inference_fps"].get<double>() > 0);
  }
  CHECK(p["pipelined_vs_unpipelined_max_difference_m"].get<double>() <= 1e-9);
  CHECK(report["lr"]["vertices"] == face.lr.num_vertices());
  CHECK(std::filesystem::exists(o.out / "animate.json"));

  // the LR frames: the live source's; the HR frames: the same network (same recipe and seed)
  // applied to them here
  const auto written = data::read_paired_frames(o.out / "smile.npz", face.lr.num_vertices(), face.surface.num_vertices());
  REQUIRE(written.num_frames() == frames);
  auto recipe = o.recipe;
  recipe.displacement_scale = 1;
  interp::Learned<> net(recipe.config(), recipe.seed);
  interp::UpsamplingProblem<> problem{face.lr, face.surface, {}, {}};
  interp::prepare(exec::omp, net, problem, o.neighborhood_k);
  scenario::FaceLrSource<> source(exec::omp, face, scenario::read_controls(o.controls[0], "smile"));
  Points<> lr, hr_disp(face.surface.num_vertices(), 3);
  for (Index f = 0; f < frames; ++f) {
    source.next(exec::omp, lr);
    CHECK((written.lr(f) - lr).cwiseAbs().maxCoeff() <= 1e-12);
    net.apply(exec::omp, Points<>(lr - face.lr.V), hr_disp);
    CHECK((written.hr(f) - (face.surface.V + hr_disp)).cwiseAbs().maxCoeff() <= 1e-9);
  }
  CHECK((written.lr(frames - 1) - face.lr.V).cwiseAbs().maxCoeff() > 1e-4);  // the face moved
  // VTU every 2nd frame: frame 0 only
  {
    std::ifstream in(o.out / "vtk" / "smile" / "hr_skin.pvd");
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    Index listed = 0;
    for (auto at = text.find("<DataSet"); at != std::string::npos; at = text.find("<DataSet", at + 1)) ++listed;
    CHECK(listed == 1);
  }

  // the same network from its model file; a model of another mesh refused (checked on the face
  // model changed here: building another one costs a minute under ASan)
  {
    net.save(dir / "model.npz");
    auto m = o;
    m.untrained = false;
    m.network = dir / "model.npz";
    const auto loaded = pipeline::detail::animate_network(exec::omp, m, face);
    Points<> a(face.surface.num_vertices(), 3), b(face.surface.num_vertices(), 3);
    const Points<> lr_disp = written.lr(frames - 1) - face.lr.V;
    loaded.apply(exec::omp, lr_disp, a);
    net.apply(exec::omp, lr_disp, b);
    CHECK(a == b);
    auto moved = face;
    moved.lr.V(3, 1) += 1e-3;
    CHECK_THROWS_WITH_AS(pipeline::detail::animate_network(exec::omp, m, moved), doctest::Contains("another LR mesh"), ArgumentError);
    moved = face;
    moved.surface.V(7, 0) -= 1e-3;
    CHECK_THROWS_WITH_AS(pipeline::detail::animate_network(exec::omp, m, moved), doctest::Contains("another HR surface"), ArgumentError);
    moved = face;
    moved.lr.V.conservativeResize(moved.lr.V.rows() - 1, 3);
    CHECK_THROWS_WITH_AS(pipeline::detail::animate_network(exec::omp, m, moved), doctest::Contains("another LR mesh"), ArgumentError);
  }
  // bad options are named, before anything is built
  {
    auto b = o;
    b.controls.clear();
    CHECK_THROWS_WITH_AS(pipeline::animate_face(exec::omp, b), doctest::Contains("controls"), ArgumentError);
    b = o;
    b.network = dir / "model.npz";
    CHECK_THROWS_WITH_AS(pipeline::animate_face(exec::omp, b), doctest::Contains("pick one"), ArgumentError);
    b.untrained = false;
    b.network = dir / "missing.npz";
    CHECK_THROWS_AS(pipeline::animate_face(exec::omp, b), ParseError);
    b = o;
    b.method = "embedded";
    CHECK_THROWS_WITH_AS(pipeline::animate_face(exec::omp, b), doctest::Contains("embedded takes no model"), ArgumentError);
    b.method = "spline";
    CHECK_THROWS_WITH_AS(pipeline::animate_face(exec::omp, b), doctest::Contains("network or embedded"), ArgumentError);
    b = o;
    b.controls = {o.controls[0], o.controls[0]};
    CHECK_THROWS_WITH_AS(pipeline::animate_face(exec::omp, b), doctest::Contains("two controls files"), ArgumentError);
  }
}

}  // namespace pipeline_animate
