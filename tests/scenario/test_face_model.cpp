// The face model on a coarse setting (face_fixture.hpp): both meshes oriented, the skin on the
// HR boundary and embedded in LR, no LR element holding both lips, two rigid bones that follow
// the teeth, every muscle present at both resolutions with comparable volumes.
#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <simsr/discretize/embedding.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/volume.hpp>
#include <simsr/eval/intersections.hpp>
#include <simsr/nn/contact_loss.hpp>
#include <simsr/scenario/scenario.hpp>

#include "face_fixture.hpp"

#include <cmath>
#include <cstdlib>
#include <set>

using namespace simsr;

namespace {

/// The centroid of a kit part (m).
Vec3<> part_centroid(const scenario::IctKit& kit, const std::string& part) {
  const scenario::VertexRange r = kit.region(part);
  return kit.neutral.V.middleRows(r.first, r.size()).colwise().mean().transpose() * 0.01;
}

/// The row of `ids` whose point in V lies nearest to p.
Index nearest_row(const Points<>& V, const IndexVector& ids, const Vec3<>& p) {
  Index best = 0;
  for (Index i = 1; i < ids.size(); ++i)
    if ((V.row(ids[i]).transpose() - p).squaredNorm() < (V.row(ids[best]).transpose() - p).squaredNorm()) best = i;
  return best;
}

}  // namespace

TEST_CASE("face model: both meshes positively oriented, the skin on the HR boundary and embedded in the LR mesh") {
  SIMSR_REQUIRE_FACE_INPUTS();
  const auto& face = test::coarse_face();
  MESSAGE("coarse face: HR " << face.hr.num_vertices() << " vertices / " << face.hr.num_tets() << " tets, LR " << face.lr.num_vertices() << " / "
                             << face.lr.num_tets() << " (" << face.lr_split.split_lattice_tets << " lattice tets split), surface "
                             << face.surface.num_vertices() << " vertices");
  const VecX<> hv = signed_volumes(exec::omp, face.hr.V, face.hr.T), lv = signed_volumes(exec::omp, face.lr.V, face.lr.T);
  CHECK(hv.minCoeff() > 0);
  CHECK(lv.minCoeff() > 0);
  CHECK(face.hr.num_tets() > 5 * face.lr.num_tets());
  // the output surface is made of HR vertices on the HR boundary, unmoved
  const TriMesh<> hb = boundary_surface(face.hr);
  std::vector<char> on_boundary(std::size_t(face.hr.num_vertices()), 0);
  for (Index f = 0; f < hb.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) on_boundary[std::size_t(hb.F(f, c))] = 1;
  Index off_boundary = 0;
  double moved = 0;
  for (Index i = 0; i < face.surface.num_vertices(); ++i) {
    off_boundary += on_boundary[std::size_t(face.surface_hr_vertex[i])] ? 0 : 1;
    moved = std::max(moved, (face.surface.V.row(i) - face.hr.V.row(face.surface_hr_vertex[i])).norm());
  }
  CHECK(off_boundary == 0);
  CHECK(moved == 0.0);
  // the embedding reproduces the rest skin from the LR rest nodes; every skin vertex is inside
  const Points<> from_lr = deform(exec::omp, face.surface_in_lr, face.lr.T, face.lr.V);
  CHECK((from_lr - face.surface.V).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(face.surface_in_lr.inside.all());
  // the skin's triangles are the HR boundary's (as index triples through surface_hr_vertex)
  std::set<std::array<VIndex, 3>> boundary;
  for (Index f = 0; f < hb.F.rows(); ++f) {
    std::array<VIndex, 3> t{hb.F(f, 0), hb.F(f, 1), hb.F(f, 2)};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    boundary.insert(t);
  }
  Index not_on_boundary = 0;
  for (Index f = 0; f < face.surface.num_faces(); ++f) {
    std::array<VIndex, 3> t{face.surface_hr_vertex[face.surface.F(f, 0)], face.surface_hr_vertex[face.surface.F(f, 1)], face.surface_hr_vertex[face.surface.F(f, 2)]};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    not_on_boundary += boundary.count(t) ? 0 : 1;
  }
  CHECK(not_on_boundary == 0);
  // the blendshape base is the kit's neutral at the surface's kit vertices (m)
  const auto& kit = test::ict_kit();
  double base = 0;
  for (Index i = 0; i < face.surface.num_vertices(); ++i)
    base = std::max(base, (face.neutral.row(i) - 0.01 * kit.neutral.V.row(face.surface_kit_vertex[i])).norm());
  CHECK(base < 1e-12);
}

TEST_CASE("face model: no LR element holds both lips (the split keeps them apart)") {
  SIMSR_REQUIRE_FACE_INPUTS();
  const auto& face = test::coarse_face();
  // mid-lip vertices: the lips' middle third, where they are separate bodies at rest
  std::vector<char> upper(std::size_t(face.hr.num_vertices()), 0), lower(upper.size(), 0);
  for (Index i = 0; i < face.lip_upper_vertices.size(); ++i)
    if (std::abs(face.hr.V(face.lip_upper_vertices[i], 0)) < 0.01) upper[std::size_t(face.lip_upper_vertices[i])] = 1;
  for (Index i = 0; i < face.lip_lower_vertices.size(); ++i)
    if (std::abs(face.hr.V(face.lip_lower_vertices[i], 0)) < 0.01) lower[std::size_t(face.lip_lower_vertices[i])] = 1;
  REQUIRE(std::count(upper.begin(), upper.end(), 1) > 10);
  REQUIRE(std::count(lower.begin(), lower.end(), 1) > 10);
  const auto& split = face.lr_split;
  Index both = 0, holding_lips = 0;
  for (Index s = 0; s < split.num_tets(); ++s) {
    bool u = false, l = false;
    for (Index q = split.piece_offsets[std::size_t(s)]; q < split.piece_offsets[std::size_t(s) + 1]; ++q)
      for (int c = 0; c < 4; ++c) {
        const Index v = face.hr.T(split.piece_material[std::size_t(q)], c);
        u = u || upper[std::size_t(v)];
        l = l || lower[std::size_t(v)];
      }
    both += (u && l) ? 1 : 0;
    holding_lips += (u || l) ? 1 : 0;
  }
  CHECK(holding_lips > 0);
  CHECK(both == 0);
  // and the lips' skin vertices are embedded in LR tets of their own lip only
  std::vector<char> lr_upper(std::size_t(face.lr.num_tets()), 0), lr_lower(lr_upper.size(), 0);
  for (Index i = 0; i < face.surface.num_vertices(); ++i) {
    const Index v = face.surface_hr_vertex[i], t = face.surface_in_lr.tet[i];
    if (upper[std::size_t(v)]) lr_upper[std::size_t(t)] = 1;
    if (lower[std::size_t(v)]) lr_lower[std::size_t(t)] = 1;
  }
  Index shared = 0;
  for (std::size_t t = 0; t < lr_upper.size(); ++t) shared += (lr_upper[t] && lr_lower[t]) ? 1 : 0;
  CHECK(shared == 0);
}

TEST_CASE("face model: two rigid bones, the jaw's around the lower teeth and the cranium's around the upper, at both resolutions") {
  SIMSR_REQUIRE_FACE_INPUTS();
  const auto& face = test::coarse_face();
  const auto& kit = test::ict_kit();
  const Vec3<> lower_teeth = part_centroid(kit, "teeth_lower"), upper_teeth = part_centroid(kit, "teeth_upper");
  for (const bool high : {true, false}) {
    CAPTURE(high);
    const Points<>& V = high ? face.hr.V : face.lr.V;
    const IndexVector& ids = high ? face.hr_bone : face.lr_bone;
    const VecX<>& w = high ? face.hr_bone_jaw : face.lr_bone_jaw;
    REQUIRE(ids.size() == w.size());
    REQUIRE(ids.size() > 0);
    Index jaw = 0;
    for (Index i = 0; i < w.size(); ++i) {
      CHECK((w[i] == 0.0 || w[i] == 1.0));
      jaw += w[i] == 1.0 ? 1 : 0;
    }
    CHECK(jaw > 0);
    CHECK(jaw < ids.size() / 2);
    CHECK(w[nearest_row(V, ids, lower_teeth)] == 1.0);
    CHECK(w[nearest_row(V, ids, upper_teeth)] == 0.0);
    // no vertex twice, all in range
    std::set<VIndex> unique(ids.data(), ids.data() + ids.size());
    CHECK(Index(unique.size()) == ids.size());
    CHECK(*unique.rbegin() < V.rows());
  }
  // the options are checked
  auto bad = test::coarse_face_options();
  bad.jaw_weight_min = 0.1;
  bad.cranium_weight_max = 0.2;
  CHECK_THROWS_AS(scenario::build_face_model(exec::seq, kit, bad, std::filesystem::temp_directory_path()), ArgumentError);
}

TEST_CASE("face model: every named muscle is present at both resolutions with comparable active volume") {
  SIMSR_REQUIRE_FACE_INPUTS();
  const auto& face = test::coarse_face();
  std::set<std::string> names;
  for (const auto& m : face.muscles) names.insert(m.spec.name);
  for (const char* n : {"zygomaticus_major_L", "zygomaticus_major_R", "orbicularis_oris", "frontalis_L", "frontalis_R", "depressor_anguli_oris_L",
                        "depressor_anguli_oris_R", "mentalis", "levator_labii_superioris_L", "levator_labii_superioris_R", "risorius_L", "risorius_R",
                        "corrugator_L", "corrugator_R", "buccinator_L", "buccinator_R"})
    CHECK_MESSAGE(names.count(n) == 1, n);
  const scenario::FaceSimulator<> lr(exec::omp, face, scenario::FaceResolution::low);
  const scenario::FaceSimulator<> hr(exec::omp, face, scenario::FaceResolution::high);
  const auto vl = lr.muscle_volumes(), vh = hr.muscle_volumes();
  REQUIRE(vl.size() == face.muscles.size());
  REQUIRE(vh.size() == face.muscles.size());
  for (std::size_t k = 0; k < vl.size(); ++k) {
    CAPTURE(face.muscles[k].spec.name);
    CHECK(vh[k] > 0);
    CHECK(vl[k] > 0);
    // one definition, two meshes: the coarse lattice smears a thin bundle (2 cm cells against a
    // ~1 cm thick muscle) but keeps its volume within a factor of two
    CHECK(vl[k] / vh[k] > 0.5);
    CHECK(vl[k] / vh[k] < 2.0);
  }
}

TEST_CASE("face model presets: the LR cell of each (the HR mesh the same), a bad name named") {
  const scenario::FaceModelOptions d = scenario::face_model_preset("default"), r = scenario::face_model_preset("paper-ratio"),
                                   p = scenario::face_model_preset("paper-lr");
  CHECK(d.lr_cell == scenario::FaceModelOptions{}.lr_cell);
  CHECK(r.lr_cell > d.lr_cell);  // fewer LR tets: the paper's 26× ratio
  CHECK(p.lr_cell < d.lr_cell);  // more LR tets: the paper's 73k
  for (const auto* o : {&r, &p}) {
    CHECK(o->hr.max_volume == d.hr.max_volume);
    CHECK(o->skull_lattice == d.skull_lattice);
  }
  CHECK_THROWS_WITH_AS(scenario::face_model_preset("paper"), doctest::Contains("got 'paper'"), ArgumentError);
}

TEST_CASE("face model presets with overrides: each override > 0 replaces its size, 0 keeps the preset's, a negative or NaN one is refused by name") {
  const scenario::FaceModelOptions r = scenario::face_model_preset("paper-ratio");
  const scenario::FaceModelOptions a = scenario::face_model_preset("paper-ratio", 2.5, 0, 0), b = scenario::face_model_preset("default", 0, 1.7, 0.8);
  CHECK(a.lr_cell == 2.5);
  CHECK(a.skull_lattice == r.skull_lattice);
  CHECK(a.hr.max_volume == r.hr.max_volume);
  CHECK(b.lr_cell == scenario::FaceModelOptions{}.lr_cell);
  CHECK(b.skull_lattice == 1.7);
  CHECK(b.hr.max_volume == 0.8);
  CHECK_THROWS_WITH_AS(scenario::face_model_preset("default", -1, 0, 0), doctest::Contains("lr_cell = -1"), ArgumentError);
  CHECK_THROWS_WITH_AS(scenario::face_model_preset("default", 0, 0, std::nan("")), doctest::Contains("hr_max_volume"), ArgumentError);
  CHECK_THROWS_WITH_AS(scenario::face_model_preset("huge", 1, 1, 1), doctest::Contains("got 'huge'"), ArgumentError);
}

TEST_CASE("face_lip_patches: the skin's lip triangles, upper in a and lower in b, facing each other: still at rest, crossing when the upper lip drops") {
  SIMSR_REQUIRE_FACE_INPUTS();
  const auto& face = test::coarse_face();
  const ContactPatches lips = scenario::face_lip_patches(face);
  REQUIRE(lips.a.rows() > 10);
  REQUIRE(lips.b.rows() > 10);
  std::set<std::array<VIndex, 3>> surface_rows;
  for (Index t = 0; t < face.surface.F.rows(); ++t) surface_rows.insert({face.surface.F(t, 0), face.surface.F(t, 1), face.surface.F(t, 2)});
  const std::set<VIndex> upper(face.lip_upper_vertices.data(), face.lip_upper_vertices.data() + face.lip_upper_vertices.size());
  const std::set<VIndex> lower(face.lip_lower_vertices.data(), face.lip_lower_vertices.data() + face.lip_lower_vertices.size());
  for (int s = 0; s < 2; ++s) {
    const Tris& T = s ? lips.b : lips.a;
    for (Index t = 0; t < T.rows(); ++t) {
      CHECK(surface_rows.count({T(t, 0), T(t, 1), T(t, 2)}) == 1);  // a skin triangle, its orientation kept
      for (Index k = 0; k < 3; ++k) CHECK((s ? lower : upper).count(face.surface_hr_vertex[T(t, k)]) == 1);
    }
  }
  // The contact term at the face's scale: pairs within 1.5 cm, nothing pushes at rest.
  nn::ContactLoss<double> loss(face.surface.V, lips, 0.015, 2e-4);
  REQUIRE(loss.pairs().size() > 50);
  const nn::Matrix<double> rest = nn::Matrix<double>::Zero(face.surface.num_vertices(), 3);
  CHECK(loss.value_and_gradient(exec::seq, rest) == 0.0);
  // The upper lip dropped 6 mm (−y, the kit's up is +y) passes through the lower one: the term and
  // the exact test see it (the patches face each other: outward normals of the skin).
  nn::Matrix<double> drop = rest;
  for (Index t = 0; t < lips.a.rows(); ++t)
    for (Index k = 0; k < 3; ++k) drop(lips.a(t, k), 1) = -6e-3;
  CHECK(loss.value_and_gradient(exec::seq, drop) > 0);
  CHECK(loss.penetrating() > 0);
  data::FrameMatrix<> frames(2, 3 * face.surface.num_vertices());
  for (Index v = 0; v < face.surface.num_vertices(); ++v)
    for (Index k = 0; k < 3; ++k) {
      frames(0, 3 * v + k) = face.surface.V(v, k);
      frames(1, 3 * v + k) = face.surface.V(v, k) + drop(v, k);
    }
  const auto counts = eval::intersecting_pairs_per_frame(exec::omp, frames, lips);
  CHECK(counts[1] > counts[0]);
}
