// The ICT kit as bundled (../shared/data/ict_face): parts, skin topology, expressions, and the jaw
// hinge read from jawOpen (data README: lower teeth rigid to 0.02 cm, 25.3° about left–right).
#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/triangulate.hpp>
#include <simsr/mesh/volume.hpp>
#include <simsr/scenario/scenario.hpp>

#include "kit_fixture.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

using namespace simsr;

using simsr::test::have_ict_kit;
using simsr::test::ict_kit_dir;

TEST_CASE("ICT kit: parts tile the vertices; the skin is one quad surface with four holes (eyes, mouth, neck)") {
  if (!have_ict_kit()) {
    SIMSR_MISSING("ICT kit not found in " << ict_kit_dir);
    return;
  }
  const auto& kit = simsr::test::ict_kit();
  CHECK(kit.num_vertices() == 24591);
  CHECK(kit.regions.size() == 10);
  CHECK(kit.region("face").first == 0);
  CHECK(kit.region("head_and_neck").last == 11247);
  CHECK(kit.expression_names.size() == 57);
  CHECK(kit.deltas.rows() == 57);
  CHECK_THROWS_WITH_AS(kit.region("ears"), doctest::Contains("regions: eye_socket_left"), ArgumentError);
  CHECK_THROWS_AS(kit.expression_index("frown"), ArgumentError);

  const PolyMesh<> skin = kit.faces_within({"face", "head_and_neck"});
  CHECK(skin.num_faces() == 11144);
  for (Index f = 0; f < skin.num_faces(); ++f) REQUIRE(skin.face_size(f) == 4);
  const TriMesh<> tri = triangulate(skin);
  auto loops = boundary_loops(tri.F);
  REQUIRE(loops.size() == 4);
  std::sort(loops.begin(), loops.end(), [](const auto& a, const auto& b) { return a.size() < b.size(); });
  CHECK(loops[0].size() == 42);  // the eyes
  CHECK(loops[1].size() == 42);
  CHECK(loops[2].size() == 54);  // the neck
  CHECK(loops[3].size() == 74);  // the mouth
  // the mouth loop lies between the lips: centred left–right, below the eyes, in front
  Vec3<> c = Vec3<>::Zero();
  for (auto v : loops[3]) c += tri.V.row(v).transpose();
  c /= double(loops[3].size());
  CHECK(std::abs(c.x()) < 0.1);
  CHECK(c.z() > 9);

  // expressions move the skin; the first 11,248 vertices are neutral_face_head.obj's
  if (std::filesystem::exists(ict_kit_dir / "neutral_face_head.obj")) {
    const auto head = io::read_obj<Scalar>(ict_kit_dir / "neutral_face_head.obj");
    REQUIRE(head.num_vertices() == 11248);
    CHECK((head.V - kit.neutral.V.topRows(11248)).cwiseAbs().maxCoeff() == 0.0);
  }
  const Points<> smile = kit.expression("mouthSmile_L");
  CHECK(smile.topRows(11248).rowwise().norm().maxCoeff() > 0.5);
  // the mouth socket closes the mouth hole and the eye sockets the eyes: with them the skin's only
  // hole is the neck
  const TriMesh<> closed = triangulate(kit.faces_within({"face", "head_and_neck", "mouth_socket", "eye_socket_left", "eye_socket_right"}));
  const auto closed_loops = boundary_loops(closed.F);
  CHECK(closed_loops.size() >= 1);
  std::size_t with_neck = 0;
  for (const auto& l : closed_loops)
    if (std::find(l.begin(), l.end(), loops[2][0]) != l.end()) ++with_neck;
  CHECK(with_neck == 1);
  MESSAGE("skin + mouth and eye sockets: " << closed_loops.size() << " boundary loops");
}

TEST_CASE("ICT kit: malformed kits are refused naming the file and what is wrong") {
  if (!have_ict_kit()) {
    SIMSR_MISSING("ICT kit not found in " << ict_kit_dir);
    return;
  }
  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "ict_kit_bad";
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(ict_kit_dir / "full_neutral.obj", dir / "full_neutral.obj", std::filesystem::copy_options::overwrite_existing);
  std::filesystem::copy_file(ict_kit_dir / "expressions_full.npz", dir / "expressions_full.npz", std::filesystem::copy_options::overwrite_existing);
  auto write_regions = [&](const std::string& text) { std::ofstream(dir / "regions.json") << text; };
  write_regions(R"({"vertex_ranges_inclusive": {"a": [0, 100], "b": [102, 24590]}})");
  CHECK_THROWS_WITH_AS(scenario::read_ict_kit(dir), doctest::Contains("region 'b' starts at vertex 102, expected 101"), ArgumentError);
  write_regions(R"({"vertex_ranges_inclusive": {"a": [0, 30000]}})");
  CHECK_THROWS_WITH_AS(scenario::read_ict_kit(dir), doctest::Contains("not within the mesh's 24591 vertices"), ArgumentError);
  write_regions(R"({"vertex_ranges_inclusive": {"a": [0, 11247], "b": [11248, 24589]}})");
  CHECK_THROWS_WITH_AS(scenario::read_ict_kit(dir), doctest::Contains("the regions end at vertex 24589"), ArgumentError);
  write_regions(R"({"vertex_ranges_inclusive": {"a": [0, "x"]}})");
  CHECK_THROWS_WITH_AS(scenario::read_ict_kit(dir), doctest::Contains("must be [first, last]"), ArgumentError);
  write_regions("{ not json");
  CHECK_THROWS_AS(scenario::read_ict_kit(dir), ParseError);
}

TEST_CASE("jaw from the kit: jawOpen turns the lower teeth 25.3° about the left–right axis; seq and omp agree") {
  if (!have_ict_kit()) {
    SIMSR_MISSING("ICT kit not found in " << ict_kit_dir);
    return;
  }
  const auto& kit = simsr::test::ict_kit();
  const auto jaw = scenario::jaw_from_kit(exec::seq, kit);
  MESSAGE("jaw hinge: point " << jaw.hinge.point.transpose() << " cm, axis " << jaw.hinge.axis.transpose() << ", angle "
                              << jaw.hinge.angle * 180 / std::numbers::pi << "°, lower-teeth residual max " << jaw.lower_fit.max_residual
                              << " cm, upper teeth move " << jaw.upper_motion << " cm");
  CHECK(jaw.hinge.angle * 180 / std::numbers::pi == doctest::Approx(25.3).epsilon(0.005));
  CHECK(std::abs(jaw.hinge.axis.x()) > 0.999);  // left–right
  CHECK(jaw.lower_fit.max_residual < 0.03);
  CHECK(jaw.upper_motion < 1e-6);
  // the hinge lies behind the teeth and above the lower teeth (the jaw joints are in front of the ears)
  const auto lower = kit.region("teeth_lower");
  const Vec3<> teeth = kit.neutral.V.middleRows(lower.first, lower.size()).colwise().mean().transpose();
  CHECK(jaw.hinge.point.z() < teeth.z() - 3);
  CHECK(jaw.hinge.point.y() > teeth.y());
  // the hinge at the full angle reproduces jawOpen on the lower teeth, and opening is positive
  const RigidMotion<> open = hinge_rotation(jaw.hinge, jaw.hinge.angle);
  const Points<> X = kit.neutral.V.middleRows(lower.first, lower.size());
  const Points<> target = X + kit.expression("jawOpen").middleRows(lower.first, lower.size());
  CHECK((apply_rigid_motion(exec::seq, open, X) - target).rowwise().norm().maxCoeff() < 0.03);
  const Points<> half = apply_rigid_motion(exec::seq, hinge_rotation(jaw.hinge, 0.5 * jaw.hinge.angle), X);
  CHECK(half.col(1).mean() < X.col(1).mean());  // the chin goes down
  const auto jaw_omp = scenario::jaw_from_kit(exec::omp, kit);
  CHECK(jaw_omp.hinge.point == jaw.hinge.point);
  CHECK(jaw_omp.lower_fit.max_residual == jaw.lower_fit.max_residual);
  // an expression that does not open the jaw is no hinge
  CHECK_THROWS_AS(scenario::jaw_from_kit(exec::seq, kit, "mouthSmile_L"), ArgumentError);
}

TEST_CASE("head_surface: skin + mouth and eye sockets + a neck cap close into one outward surface") {
  if (!have_ict_kit()) {
    SIMSR_MISSING("ICT kit not found in " << ict_kit_dir);
    return;
  }
  const auto& kit = simsr::test::ict_kit();
  const auto head = scenario::head_surface(exec::seq, kit, kit.neutral.V);
  CHECK(boundary_edges(head.mesh.F).rows() == 0);
  CHECK(head.neck_loop.size() == 54);
  CHECK(head.kit_vertex.back() == -1);
  CHECK(Index(head.kit_vertex.size()) == head.mesh.num_vertices());
  // the parts' vertices, once each: 9409 + 1839 skin, 2046 mouth socket, 2 × 384 eye sockets, the cap centre
  CHECK(head.mesh.num_vertices() == 9409 + 1839 + 2046 + 384 + 384 + 1);
  Index counts[4] = {0, 0, 0, 0};
  for (auto p : head.part) ++counts[int(p)];
  CHECK(counts[int(scenario::HeadPart::skin)] == 2 * 11144);
  CHECK(counts[int(scenario::HeadPart::neck_cap)] == 54);
  CHECK(counts[int(scenario::HeadPart::mouth_socket)] > 0);
  CHECK(counts[int(scenario::HeadPart::eye_socket)] > 0);
  // outward: the enclosed volume is positive and about a head's (cm³)
  Tets T(head.mesh.F.rows(), 4);
  Points<> W(head.mesh.V.rows() + 1, 3);
  W << head.mesh.V, head.mesh.V.colwise().mean();
  for (Index f = 0; f < head.mesh.F.rows(); ++f) T.row(f) << VIndex(W.rows() - 1), head.mesh.F(f, 0), head.mesh.F(f, 1), head.mesh.F(f, 2);
  const double volume = total_volume(exec::seq, W, T);
  MESSAGE("closed head surface: " << head.mesh.num_vertices() << " vertices, " << head.mesh.num_faces() << " triangles, volume " << volume << " cm³");
  CHECK(volume > 2000);
  CHECK(volume < 8000);
  CHECK_THROWS_AS(scenario::head_surface(exec::seq, kit, kit.neutral.V.topRows(100)), ShapeError);
}
