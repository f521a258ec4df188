#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <simsr/discretize/bcc_lattice.hpp>
#include <simsr/io/obj.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/quality.hpp>
#include <simsr/mesh/topology.hpp>
#include <simsr/mesh/validate.hpp>

#include <filesystem>
#include <map>
#include <random>
#include <set>

using namespace simsr;
using namespace simsr::discretize;

namespace {

/// Cells kept with probability p in an n0×n1×n2 grid of side h (seeded).
VoxelSet random_cells(std::array<Index, 3> n, double h, double p, unsigned seed) {
  VoxelSet v;
  v.grid.origin = Vec3<>(0.3, -1.0, 2.0);
  v.grid.h = h;
  v.grid.dims = n;
  std::mt19937 rng(seed);
  std::bernoulli_distribution keep(p);
  for (Index k = 0; k < n[2]; ++k)
    for (Index j = 0; j < n[1]; ++j)
      for (Index i = 0; i < n[0]; ++i)
        if (keep(rng)) v.cells.push_back({i, j, k});
  return v;
}

/// Faces of kept cells with no kept neighbour across them (each is 2 boundary triangles).
Index outer_cell_faces(const VoxelSet& v) {
  std::set<std::array<Index, 3>> kept(v.cells.begin(), v.cells.end());
  Index n = 0;
  for (const auto& c : v.cells)
    for (int a = 0; a < 3; ++a)
      for (int d : {-1, 1}) {
        auto m = c;
        m[a] += d;
        n += !kept.count(m);
      }
  return n;
}

double det_volume(const TetMesh<>& m, Index t) {
  Eigen::Matrix3d M;
  for (int c = 0; c < 3; ++c) M.col(c) = (m.V.row(m.T(t, c + 1)) - m.V.row(m.T(t, 0))).transpose();
  return M.determinant() / 6;
}

/// Checks shared by every conforming split: exact volume, positive tets above `min_quality`, the
/// boundary is exactly the outer cell faces, nodes unique and all used, node_coords consistent,
/// and each cell's tets (straddling ones counted half) fill exactly h³.
template <class Split>
void check_lattice(const VoxelSet& cells, double min_quality, bool conforming = true) {
  const auto L = build_lattice<Split>(cells);
  const double h = cells.grid.h, h3 = h * h * h;
  CHECK_NOTHROW(validate(exec::seq, L.mesh));
  const auto report = check(exec::seq, L.mesh);
  CHECK(report.unreferenced_vertex.count == 0);
  double vol = 0;
  for (Index t = 0; t < L.mesh.T.rows(); ++t) vol += det_volume(L.mesh, t);
  CHECK(vol == doctest::Approx(cells.volume()).epsilon(1e-12));
  const auto q = element_quality(exec::seq, L.mesh.V, L.mesh.T);
  CHECK(q.minCoeff() >= min_quality);
  if (conforming) CHECK(boundary_faces(L.mesh.T).rows() == 2 * outer_cell_faces(cells));
  std::set<std::array<std::int64_t, 3>> coords;
  for (Index v = 0; v < L.mesh.V.rows(); ++v) {
    coords.insert({L.node_coords(v, 0), L.node_coords(v, 1), L.node_coords(v, 2)});
    const Vec3<> x = cells.grid.origin + 0.5 * h * L.node_coords.row(v).transpose().template cast<double>();
    CHECK((x - L.mesh.V.row(v).transpose()).norm() < 1e-12);
  }
  CHECK(Index(coords.size()) == L.mesh.V.rows());
  REQUIRE(Index(L.cell_offsets.size()) == cells.size() + 1);
  std::vector<int> listed(std::size_t(L.mesh.T.rows()), 0);
  for (Index c = 0; c < cells.size(); ++c)
    for (Index p = L.cell_offsets[c]; p < L.cell_offsets[c + 1]; ++p) ++listed[L.cell_tets[p]];
  for (Index c = 0; c < cells.size(); ++c) {
    double cv = 0;
    for (Index p = L.cell_offsets[c]; p < L.cell_offsets[c + 1]; ++p) cv += det_volume(L.mesh, L.cell_tets[p]) / listed[L.cell_tets[p]];
    CHECK(cv == doctest::Approx(h3).epsilon(1e-12));
  }
  for (Index t = 0; t < L.mesh.T.rows(); ++t) CHECK(listed[t] >= 1);
}

}  // namespace

TEST_CASE("build_lattice on a full box: counts, volume, boundary, quality per split") {
  for (const Index n : {1, 2, 4}) {
    CAPTURE(n);
    VoxelSet box = random_cells({n, n + 1, n}, 0.1, 1.0, 1);
    const Index cells = n * (n + 1) * n, corners = (n + 1) * (n + 2) * (n + 1);
    const auto bcc = build_lattice<BccSplit>(box);
    CHECK(bcc.mesh.T.rows() == 12 * cells);
    CHECK(bcc.mesh.V.rows() == corners + cells);
    CHECK(build_lattice<FreudenthalSplit>(box).mesh.T.rows() == 6 * cells);
    CHECK(build_lattice<FreudenthalSplit>(box).mesh.V.rows() == corners);
    CHECK(build_lattice<AlternatingSplit>(box).mesh.T.rows() == 5 * cells);
    CHECK(build_lattice<CentredFiveSplit<>>(box).mesh.T.rows() == 8 * cells);
    check_lattice<BccSplit>(box, 0.76);
    check_lattice<FreudenthalSplit>(box, 0.755);
    check_lattice<AlternatingSplit>(box, 0.83);
    check_lattice<CentredFiveSplit<true>>(box, 0.577);
  }
}

TEST_CASE("build_lattice on random cell sets: conforming splits cover exactly the kept cells") {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    const auto cells = random_cells({6, 5, 4}, 0.37, 0.55, seed);
    check_lattice<BccSplit>(cells, 0.76);
    check_lattice<FreudenthalSplit>(cells, 0.755);
    check_lattice<AlternatingSplit>(cells, 0.83);
    check_lattice<CentredFiveSplit<true>>(cells, 0.577);
    check_lattice<CentredFiveSplit<false>>(cells, 0.577, false);
  }
}

TEST_CASE("BCC quality: face tets 0.95, in mean ratio, pyramid halves only on the boundary") {
  const auto cells = random_cells({5, 5, 5}, 1.0, 1.0, 3);
  const auto L = build_lattice<BccSplit>(cells);
  const auto q = element_quality(exec::seq, L.mesh.V, L.mesh.T);
  std::map<long, Index> hist;
  for (Index t = 0; t < q.size(); ++t) ++hist[std::lround(q[t] * 1000)];
  REQUIRE(hist.size() == 2);  // two shapes: (centre, centre, edge) and (centre, face triangle)
  const double face_q = double(hist.rbegin()->first) / 1000, pyramid_q = double(hist.begin()->first) / 1000;
  CHECK(face_q == doctest::Approx(0.9524).epsilon(0.001));  // BCC tet: edges h, h and 4 × (√3/2)h
  CHECK(pyramid_q == doctest::Approx(0.7620).epsilon(0.001));
  CHECK(hist.begin()->second == 2 * outer_cell_faces(cells));
  CHECK(q.mean() > 0.8);
}

TEST_CASE("non-alternating centred split (the bunny's) shares nodes but not faces") {
  VoxelSet two = random_cells({2, 1, 1}, 1.0, 1.0, 1);
  const auto alt = build_lattice<CentredFiveSplit<true>>(two), uni = build_lattice<CentredFiveSplit<false>>(two);
  CHECK(boundary_faces(alt.mesh.T).rows() == 2 * 10);
  CHECK(boundary_faces(uni.mesh.T).rows() == 2 * 10 + 4);  // the shared square's two triangulations cross
  CHECK(alt.mesh.V.rows() == uni.mesh.V.rows());
}

TEST_CASE("the authors' bunny LR mesh is a uniform centred 5-tet lattice (8 tets per cell, face diagonals crossing)") {
  const auto path = std::filesystem::path(SIMSR_DATA_DIR) / "bunny" / "lrestshape.obj";
  if (!std::filesystem::exists(path)) {
    SIMSR_MISSING("bunny LR mesh not found: " << path);
    return;
  }
  const auto m = io::read_obj_tets(path);
  REQUIRE(m.T.rows() == 4896);
  REQUIRE(m.V.rows() == 1747);
  // Edge lengths fall in three classes: (√3/2)H centre–corner, H axis, √2·H face diagonal;
  // no √3·H main diagonals (so not Freudenthal) and the centre–corner class proves cube centres.
  const Edges E = unique_edges(m.T);
  Index n[3] = {0, 0, 0};
  const double H = 0.0125;
  for (Index e = 0; e < E.rows(); ++e) {
    const double l = (m.V.row(E(e, 0)) - m.V.row(E(e, 1))).norm() / H;
    if (std::abs(l - std::sqrt(0.75)) < 0.08) ++n[0];
    else if (std::abs(l - 1.0) < 0.08) ++n[1];
    else if (std::abs(l - std::sqrt(2.0)) < 0.08) ++n[2];
  }
  CHECK(n[0] + n[1] + n[2] == E.rows());
  CHECK(n[0] > 2000);
  // Volumes: H³/6 corner tets and H³/12 centre tets, 4896 = 8 per cell.
  Index sixth = 0, twelfth = 0;
  for (Index t = 0; t < m.T.rows(); ++t) {
    const double v = std::abs(det_volume(m, t)) / (H * H * H);
    sixth += std::abs(v - 1.0 / 6) < 0.02;
    twelfth += std::abs(v - 1.0 / 12) < 0.015;
  }
  CHECK(sixth + twelfth == m.T.rows());
  CHECK(std::abs(sixth - twelfth) < 60);
  // Not face-conforming: far more boundary faces than its outer surface could have.
  CHECK(boundary_faces(m.T).rows() == 7344);
}

TEST_CASE("bcc_lattice of an ellipsoid surface and of a tet mesh; bcc_points_inside") {
  const auto surf = ellipsoid_surface(2000, 1.0, 0.8, 0.6);
  const double h = 0.15;
  const auto L = bcc_lattice(surf, h);
  CHECK_NOTHROW(validate(exec::seq, L.mesh));
  CHECK(L.mesh.T.rows() > 0);
  CHECK(boundary_faces(L.mesh.T).rows() == 2 * outer_cell_faces(L.cells));
  CHECK(connected_components(L.mesh.T, L.mesh.V.rows()).count == 1);
  const auto F = bcc_lattice<FreudenthalSplit>(surf, h);
  CHECK(F.cells.cells == L.cells.cells);
  CHECK(F.mesh.T.rows() == 6 * L.num_cells());
  const auto shell = sphere_shell_tet_mesh(0.4, 1.0, 2, 2);
  const auto S = bcc_lattice(shell, 0.2);
  CHECK(S.cells.cells == voxelize(boundary_surface(shell), 0.2).cells);

  double hb = 0;
  const auto P = bcc_points_inside(surf, 300, &hb);
  REQUIRE(P.rows() == 300);
  const auto in = inside_surface(surf, P);
  for (Index p = 0; p < P.rows(); ++p) CHECK(in[p]);
  // Every point is a BCC node of spacing hb: 2x/hb all integers of one parity.
  for (Index p = 0; p < P.rows(); ++p) {
    const Vec3<> d = 2.0 * P.row(p).transpose() / hb;
    CHECK((d - d.array().round().matrix()).cwiseAbs().maxCoeff() < 1e-6);
    const long a = std::lround(d[0]) & 1, b = std::lround(d[1]) & 1, c = std::lround(d[2]) & 1;
    CHECK((a == b && b == c));
  }
  CHECK(bcc_nodes_inside(surf, hb).rows() >= 300);
  CHECK(bcc_nodes_inside(surf, hb * 1.02).rows() < 330);
  CHECK_THROWS_AS(bcc_points_inside(surf, 0), ArgumentError);
  CHECK_THROWS_AS(build_lattice(VoxelSet{}), ArgumentError);
}
