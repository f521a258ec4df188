// The layered head (SoftDECA's template structure) on a sphere standing in for a head: sizes per
// layer, orientation, the folding repair, the neck, and the skull's per-axis scaling.
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/normals.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/volume.hpp>
#include <simsr/scenario/softdeca/layered_head.hpp>

#include <doctest/doctest.h>

namespace scenario_test_layered_head {

using namespace simsr;
using namespace simsr::scenario;

/// A sphere of radius 1 (or the part above z = cut), unit inward directions, bones: cranium
/// above y = 0.3, jaw below y = −0.4, free between.
struct Ball {
  TriMesh<> outer;
  Points<> inward;
  std::vector<Bone> bones;
};

Ball ball(double cut = -2) {
  const auto s = icosphere<double>(2, 1.0);
  Ball b;
  std::vector<VIndex> map(std::size_t(s.V.rows()), -1);
  std::vector<VIndex> used;
  std::vector<std::array<VIndex, 3>> tris;
  for (Index f = 0; f < s.F.rows(); ++f) {
    bool keep = true;
    for (int c = 0; c < 3; ++c) keep = keep && s.V(s.F(f, c), 2) > cut;
    if (!keep) continue;
    std::array<VIndex, 3> t{};
    for (int c = 0; c < 3; ++c) {
      VIndex& m = map[std::size_t(s.F(f, c))];
      if (m < 0) {
        m = VIndex(used.size());
        used.push_back(s.F(f, c));
      }
      t[std::size_t(c)] = m;
    }
    tris.push_back(t);
  }
  b.outer.V.resize(Index(used.size()), 3);
  for (std::size_t i = 0; i < used.size(); ++i) b.outer.V.row(Index(i)) = s.V.row(used[i]);
  b.outer.F.resize(Index(tris.size()), 3);
  for (std::size_t f = 0; f < tris.size(); ++f)
    for (int c = 0; c < 3; ++c) b.outer.F(Index(f), c) = tris[f][std::size_t(c)];
  b.inward = -b.outer.V.rowwise().normalized();
  for (Index i = 0; i < b.outer.V.rows(); ++i)
    b.bones.push_back(b.outer.V(i, 1) > 0.3 ? Bone::cranium : b.outer.V(i, 1) < -0.4 ? Bone::jaw : Bone::none);
  return b;
}

TEST_CASE("layered_head: L prisms per shell, 3 tets each, positive; muscle next to the bone; sizes add up") {
  const Ball b = ball();
  for (Index L : {1, 2, 3}) {
    CAPTURE(L);
    const LayeredHead h = layered_head(exec::omp, b.outer, b.inward, VecX<>::Constant(b.outer.V.rows(), 0.3), b.bones,
                                       {.layers = L, .muscle_fraction = 0.4});
    const Index F = b.outer.F.rows(), nv = b.outer.V.rows();
    CHECK(h.num_wraps() == 2 * L + 1);
    CHECK(h.mesh.num_vertices() == (2 * L + 1) * nv);
    CHECK(h.count(TissueLayer::soft_tissue) == 3 * F * L);
    CHECK(h.count(TissueLayer::muscle) == 3 * F * L);
    CHECK(signed_volumes(exec::seq, h.mesh.V, h.mesh.T).minCoeff() > 0);
    CHECK(h.repaired_vertices == 0);
    // the shell between the sphere and its copy at r = 0.7 (both polyhedral: the volumes they
    // enclose); soft tissue outside r = 0.82, muscle inside
    const auto enclosed = [&](const Points<>& V) {
      double v = 0;
      for (Index f = 0; f < F; ++f) v += V.row(b.outer.F(f, 0)).dot(V.row(b.outer.F(f, 1)).cross(V.row(b.outer.F(f, 2)))) / 6;
      return v;
    };
    const double outer = total_volume(exec::seq, h.mesh.V, h.mesh.T);
    CHECK(outer == doctest::Approx(enclosed(b.outer.V) - enclosed(h.mesh.V.middleRows(2 * L * nv, nv))).epsilon(1e-12));
    CHECK(enclosed(h.mesh.V.middleRows(2 * L * nv, nv)) == doctest::Approx(0.343 * enclosed(b.outer.V)).epsilon(1e-12));
    const TetMesh<> muscle = h.layer_mesh(TissueLayer::muscle), soft = h.layer_mesh(TissueLayer::soft_tissue);
    for (Index v = 0; v < muscle.num_vertices(); ++v) CHECK(muscle.V.row(v).norm() < 0.82 + 1e-9);
    for (Index v = 0; v < soft.num_vertices(); ++v) CHECK(soft.V.row(v).norm() > 0.82 - 1e-9);
    CHECK(total_volume(exec::seq, muscle.V, muscle.T) + total_volume(exec::seq, soft.V, soft.T) == doctest::Approx(outer).epsilon(1e-12));
    // bones on the inner wrap only
    CHECK(h.count(Bone::cranium) + h.count(Bone::jaw) == Index(std::count_if(b.bones.begin(), b.bones.end(), [](Bone x) { return x != Bone::none; })));
    for (Index v = 0; v < 2 * L * nv; ++v) CHECK(h.bone[std::size_t(v)] == Bone::none);
  }
}

TEST_CASE("layered_head: a thickness beyond the centre folds the prisms; the repair thins them until none folds") {
  const Ball b = ball();
  const LayeredHead h = layered_head(exec::seq, b.outer, b.inward, VecX<>::Constant(b.outer.V.rows(), 1.6), b.bones, {.layers = 1});
  CHECK(h.repaired_vertices > 0);
  CHECK(h.thickness.maxCoeff() < 1.0);
  CHECK(signed_volumes(exec::seq, h.mesh.V, h.mesh.T).minCoeff() > 0);
  // no repair rounds allowed: the fold is named
  CHECK_THROWS_WITH_AS(layered_head(exec::seq, b.outer, b.inward, VecX<>::Constant(b.outer.V.rows(), 1.6), b.bones, {.layers = 1, .max_repairs = 0}),
                       doctest::Contains("still fold"), MeshError);
}

TEST_CASE("layered_head: a column no thickness unfolds pinches to the surface; the shell stays conforming and positive") {
  Ball b = ball();
  b.inward.row(7) *= -1;  // vertex 7 offsets outward: its prisms fold at any thickness
  const Index nv = b.outer.V.rows();
  const LayeredHead h = layered_head(exec::seq, b.outer, b.inward, VecX<>::Constant(nv, 0.2), b.bones, {.layers = 2, .collapse_below = 0.01});
  // the repair thins every corner of a folded prism, so vertex 7's neighbours pinch with it
  CHECK(h.collapsed_vertices >= 1);
  CHECK(h.collapsed_vertices <= 7);
  CHECK(h.thickness[7] == 0);
  CHECK(h.mesh.num_vertices() < h.num_wraps() * nv);
  for (Index w = 0; w < h.num_wraps(); ++w) CHECK(h.vertex(w, 7) == 7);
  CHECK(h.bone[7] == Bone::none);
  CHECK(signed_volumes(exec::seq, h.mesh.V, h.mesh.T).minCoeff() > 0);
  // conforming: the shell's boundary is closed (every boundary edge in two boundary triangles)
  CHECK(boundary_edges(boundary_faces(h.mesh.T)).rows() == 0);
  // and every vertex is used by a tet (inner copies left without one are dropped)
  std::vector<char> used(std::size_t(h.mesh.num_vertices()), 0);
  for (Index t = 0; t < h.mesh.num_tets(); ++t)
    for (int c = 0; c < 4; ++c) used[std::size_t(h.mesh.T(t, c))] = 1;
  // but outer vertices whose triangles all pinched (here vertex 7) are kept, without tets
  for (Index v = 0; v < h.mesh.num_vertices(); ++v)
    if (!used[std::size_t(v)]) {
      CHECK(v < nv);
      CHECK(h.thickness[v] == 0);
    }
}

TEST_CASE("layered_head: the open boundary (the neck) is held in every wrap") {
  const Ball b = ball(-0.6);
  const Index nv = b.outer.V.rows();
  const LayeredHead h = layered_head(exec::seq, b.outer, b.inward, VecX<>::Constant(nv, 0.2), b.bones, {.layers = 2});
  const Edges open = boundary_edges(b.outer.F);
  REQUIRE(open.rows() > 0);
  for (Index e = 0; e < open.rows(); ++e)
    for (Index w = 0; w < h.num_wraps(); ++w) CHECK(h.bone[std::size_t(h.vertex(w, open(e, 0)))] == Bone::neck);
}

TEST_CASE("layered_head: bone_targets scale the cranium about its centroid and the jaw about the hinge the cranium carries") {
  const Ball b = ball();
  const Vec3<> hinge(0.1, -0.3, 0.2);
  const LayeredHead h = layered_head(exec::seq, b.outer, b.inward, VecX<>::Constant(b.outer.V.rows(), 0.3), b.bones, {.layers = 1}, hinge);
  const auto same = h.bone_targets(Vec3<>::Ones(), Vec3<>::Ones());
  for (Index k = 0; k < same.size(); ++k) CHECK((same.targets.row(k) - h.mesh.V.row(same.vertices[k])).norm() < 1e-15);
  const Vec3<> sc(1.4, 0.7, 1.1), sj(0.6, 1.3, 0.9);
  const auto scaled = h.bone_targets(sc, sj);
  const Vec3<> c = h.cranium_centre, moved_hinge = c + sc.cwiseProduct(hinge - c);
  for (Index k = 0; k < scaled.size(); ++k) {
    const Vec3<> x = h.mesh.V.row(scaled.vertices[k]).transpose(), y = scaled.targets.row(k).transpose();
    if (h.bone[std::size_t(scaled.vertices[k])] == Bone::jaw)
      CHECK((y - (moved_hinge + sj.cwiseProduct(x - hinge))).norm() < 1e-14);
    else
      CHECK((y - (c + sc.cwiseProduct(x - c))).norm() < 1e-14);
  }
}

TEST_CASE("layered_head: bad input is named") {
  const Ball b = ball();
  const VecX<> t = VecX<>::Constant(b.outer.V.rows(), 0.3);
  CHECK_THROWS_AS(layered_head(exec::seq, b.outer, b.inward, t, b.bones, {.layers = 0}), ArgumentError);
  CHECK_THROWS_AS(layered_head(exec::seq, b.outer, b.inward, t, b.bones, {.layers = 1, .muscle_fraction = 1.0}), ArgumentError);
  CHECK_THROWS_AS(layered_head(exec::seq, b.outer, b.inward, t.head(3), b.bones), ShapeError);
  VecX<> bad = t;
  bad[4] = std::nan("");
  CHECK_THROWS_WITH_AS(layered_head(exec::seq, b.outer, b.inward, bad, b.bones), doctest::Contains("thickness[4]"), ArgumentError);
  Points<> dirs = b.inward;
  dirs.row(2) *= 2;
  CHECK_THROWS_WITH_AS(layered_head(exec::seq, b.outer, dirs, t, b.bones), doctest::Contains("not a unit vector"), ArgumentError);
}

}  // namespace scenario_test_layered_head
