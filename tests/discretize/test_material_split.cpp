#include <doctest/doctest.h>

#include <simsr/discretize/material_split.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/mesh/topology.hpp>

#include <random>
#include <set>

using namespace simsr;

namespace {

TetMesh<> concatenate(const TetMesh<>& a, const TetMesh<>& b) {
  TetMesh<> m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.T.resize(a.T.rows() + b.T.rows(), 4);
  m.T << a.T, (b.T.array() + VIndex(a.V.rows())).matrix();
  return m;
}

/// The tets of `m` whose centroid passes `keep`, unused vertices kept (they are harmless here).
template <class F>
TetMesh<> keep_tets(const TetMesh<>& m, F keep) {
  std::vector<Index> rows;
  for (Index t = 0; t < m.T.rows(); ++t) {
    Vec3<> c = Vec3<>::Zero();
    for (int k = 0; k < 4; ++k) c += m.V.row(m.T(t, k)).transpose() / 4;
    if (keep(c)) rows.push_back(t);
  }
  TetMesh<> out{m.V, Tets(Index(rows.size()), 4)};
  for (std::size_t r = 0; r < rows.size(); ++r) out.T.row(Index(r)) = m.T.row(rows[r]);
  return out;
}

Vec3<> centroid(const TetMesh<>& m, Index t) {
  Vec3<> c = Vec3<>::Zero();
  for (int k = 0; k < 4; ++k) c += m.V.row(m.T(t, k)).transpose() / 4;
  return c;
}

/// A box mesh with every vertex jittered (`boundary_too`) or only the interior ones. The draws
/// are sequenced one by one: argument evaluation order differs between compilers.
TetMesh<> jittered_box(std::uint32_t seed, bool boundary_too) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.015, 0.015);
  const Vec3<> lo(0.05, 0.1, 0.0), hi(0.95, 0.8, 0.55);
  TetMesh<> box = box_tet_mesh<double>(5, 4, 3, lo, hi);
  for (Index v = 0; v < box.V.rows(); ++v) {
    bool on_boundary = false;
    for (int a = 0; a < 3; ++a) on_boundary = on_boundary || std::abs(box.V(v, a) - lo[a]) < 1e-12 || std::abs(box.V(v, a) - hi[a]) < 1e-12;
    if (on_boundary && !boundary_too) continue;
    for (int a = 0; a < 3; ++a) box.V(v, a) += jitter(rng);
  }
  return box;
}

/// Every (lattice tet, M-tet) pair split_by_material lists, checked against all pairs.
void check_pairs_by_brute_force(const discretize::Lattice<>& L, const TetMesh<>& box, const discretize::MaterialSplit<>& split) {
  std::set<std::pair<Index, Index>> truth, listed;
  for (Index t = 0; t < L.mesh.T.rows(); ++t)
    for (Index e = 0; e < box.T.rows(); ++e)
      if (tets_overlap(discretize::detail::corners_of<double>(L.mesh.V, L.mesh.T, t), discretize::detail::corners_of<double>(box.V, box.T, e),
                       1e-9 * 0.3))
        truth.insert({t, e});
  for (Index s = 0; s < split.num_tets(); ++s)
    for (Index q = split.piece_offsets[std::size_t(s)]; q < split.piece_offsets[std::size_t(s) + 1]; ++q)
      listed.insert({split.tet_parent[s], split.piece_material[std::size_t(q)]});
  CHECK(listed == truth);
}

}  // namespace

TEST_CASE("split_by_material lists exactly the overlapping pairs (brute force); its pieces are the vertex-connected groups") {
  for (const std::uint32_t seed : {3u, 4u, 5u}) {
    CAPTURE(seed);
    const TetMesh<> box = jittered_box(seed, true);
    const auto L = discretize::bcc_lattice(box, 0.3);
    const auto split = discretize::split_by_material(exec::seq, L, box);
    check_pairs_by_brute_force(L, box, split);
    // pieces of one lattice tet share no M-vertex; inside a piece the M-tets are vertex-connected
    for (Index s = 0; s < split.num_tets(); ++s) {
      std::vector<Index> piece(split.piece_material.begin() + split.piece_offsets[std::size_t(s)],
                               split.piece_material.begin() + split.piece_offsets[std::size_t(s) + 1]);
      auto shares = [&](Index a, Index b) {
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j)
            if (box.T(a, i) == box.T(b, j)) return true;
        return false;
      };
      std::vector<bool> reached(piece.size(), false);
      reached[0] = true;
      for (bool grew = true; grew;) {
        grew = false;
        for (std::size_t i = 0; i < piece.size(); ++i)
          for (std::size_t j = 0; j < piece.size(); ++j)
            if (reached[i] && !reached[j] && shares(piece[i], piece[j])) reached[j] = grew = true;
      }
      CHECK(std::count(reached.begin(), reached.end(), true) == Index(piece.size()));
      for (Index r = s + 1; r < split.num_tets() && split.tet_parent[r] == split.tet_parent[s]; ++r)
        for (Index q = split.piece_offsets[std::size_t(r)]; q < split.piece_offsets[std::size_t(r) + 1]; ++q)
          for (Index e : piece) CHECK_FALSE(shares(e, split.piece_material[std::size_t(q)]));
    }
  }
}

TEST_CASE("split_by_material leaves convex material unsplit (a convex set meets a lattice tet in one piece)") {
  for (const std::uint32_t seed : {3u, 4u, 5u}) {
    CAPTURE(seed);
    const TetMesh<> box = jittered_box(seed, false);  // flat faces: the material is the box itself
    const auto L = discretize::bcc_lattice(box, 0.3);
    const auto split = discretize::split_by_material(exec::seq, L, box);
    check_pairs_by_brute_force(L, box, split);
    CHECK(split.split_lattice_tets == 0);
    CHECK(split.duplicated_nodes == 0);
    CHECK(connected_components(split.mesh.T, split.num_nodes()).count == 1);
    // the split mesh is the lattice minus the tets without material
    CHECK(split.num_tets() + split.lattice_tets_without_material == L.mesh.T.rows());
    for (Index s = 0; s < split.num_tets(); ++s)
      for (int c = 0; c < 4; ++c) CHECK(split.node_parent[split.mesh.T(s, c)] == L.mesh.T(split.tet_parent[s], c));
    // every M-tet is held somewhere
    for (Index e = 0; e < box.T.rows(); ++e) CHECK(split.material_offsets[std::size_t(e) + 1] > split.material_offsets[std::size_t(e)]);
  }
}

TEST_CASE("two slabs closer than a cell: every shared cell is split and the lattice falls into two bodies") {
  for (const double gap : {0.02, 0.1, 0.2}) {
    const double mid = 0.45;  // the gap lies inside the lattice's cell layer [0.3, 0.6]
    const TetMesh<> lower = box_tet_mesh<double>(6, 6, 3, Vec3<>(0, 0, 0), Vec3<>(1, 1, mid - gap / 2));
    const TetMesh<> upper = box_tet_mesh<double>(6, 6, 3, Vec3<>(0, 0, mid + gap / 2), Vec3<>(1, 1, 1));
    const TetMesh<> both = concatenate(lower, upper);
    const Index n_lower_tets = lower.T.rows();
    const auto L = discretize::bcc_lattice(both, 0.3);
    const auto split = discretize::split_by_material(exec::omp, L, both);
    CAPTURE(gap);
    // no split tet holds both slabs
    for (Index s = 0; s < split.num_tets(); ++s) {
      bool lo = false, hi = false;
      for (Index q = split.piece_offsets[std::size_t(s)]; q < split.piece_offsets[std::size_t(s) + 1]; ++q)
        (split.piece_material[std::size_t(q)] < n_lower_tets ? lo : hi) = true;
      CHECK(lo != hi);
    }
    CHECK(split.split_lattice_tets > 0);
    CHECK(split.duplicated_nodes > 0);
    CHECK(connected_components(split.mesh.T, split.num_nodes()).count == 2);
    // seq gives the same output
    const auto seq = discretize::split_by_material(exec::seq, L, both);
    CHECK(seq.mesh.T == split.mesh.T);
    CHECK(seq.mesh.V == split.mesh.V);
    // the slabs' vertices embed into split tets of their own slab and are reproduced
    IndexVector all(both.V.rows());
    for (Index v = 0; v < all.size(); ++v) all[v] = VIndex(v);
    const auto emb = discretize::embed_material_vertices(exec::omp, split, both, all);
    CHECK(emb.num_outside() == 0);
    for (Index v = 0; v < all.size(); ++v) {
      Vec3<> p = Vec3<>::Zero();
      for (int k = 0; k < 4; ++k) p += emb.weights(v, k) * split.mesh.V.row(split.mesh.T(emb.tet[v], k)).transpose();
      CHECK((p - both.V.row(v).transpose()).norm() < 1e-12);
      const Index s = emb.tet[v];
      const bool own_lower = v < lower.V.rows();
      bool holds_own = false;
      for (Index q = split.piece_offsets[std::size_t(s)]; q < split.piece_offsets[std::size_t(s) + 1]; ++q)
        holds_own |= (split.piece_material[std::size_t(q)] < n_lower_tets) == own_lower;
      CHECK(holds_own);
    }
  }
}

TEST_CASE("a U-shaped body: cells across the slot are split, the body stays one piece") {
  const TetMesh<> plate = box_tet_mesh<double>(20, 20, 2, Vec3<>(0, 0, 0), Vec3<>(1, 1, 0.2));
  // slot x ∈ (0.45, 0.55) above y = 0.3: two columns of cells, so the arms share no vertex
  const TetMesh<> u = keep_tets(plate, [](const Vec3<>& c) { return !(std::abs(c.x() - 0.5) < 0.06 && c.y() > 0.3); });
  const auto L = discretize::bcc_lattice(u, 0.2);
  const auto split = discretize::split_by_material(exec::omp, L, u);
  CHECK(split.split_lattice_tets > 0);
  CHECK(split.duplicated_nodes > 0);
  // one body: the unused plate vertices are components of their own, so count over used nodes
  CHECK(connected_components(split.mesh.T, split.num_nodes()).count == 1);
  // a piece holding both arms must also hold the base that joins them inside its lattice tet
  for (Index s = 0; s < split.num_tets(); ++s) {
    bool left = false, right = false, base = false;
    for (Index q = split.piece_offsets[std::size_t(s)]; q < split.piece_offsets[std::size_t(s) + 1]; ++q) {
      const Vec3<> c = centroid(u, split.piece_material[std::size_t(q)]);
      if (c.y() <= 0.3) base = true;
      else (c.x() < 0.5 ? left : right) = true;
    }
    if (left && right) CHECK(base);
  }
}
