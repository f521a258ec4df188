#include <doctest/doctest.h>

#include <simsr/mesh/topology.hpp>

#include <map>
#include <set>

#include "fixtures.hpp"

namespace mesh_test_topology {

using namespace simsr;
using namespace simsr::test;

namespace {

/// Random elements with k corners over nv vertices (corners distinct).
template <class M>
M random_elements(Index n, int k, int nv, std::mt19937& rng) {
  M E(n, k);
  std::uniform_int_distribution<int> u(0, nv - 1);
  for (Index e = 0; e < n; ++e) {
    std::set<int> s;
    while (int(s.size()) < k) s.insert(u(rng));
    std::vector<int> c(s.begin(), s.end());
    std::shuffle(c.begin(), c.end(), rng);
    for (int i = 0; i < k; ++i) E(e, i) = c[i];
  }
  return E;
}

/// Signed volume enclosed by a closed surface (divergence theorem): Σ v0·(v1×v2)/6.
double enclosed_volume(const Points<>& V, const Tris& F) {
  double s = 0;
  for (Index f = 0; f < F.rows(); ++f)
    s += V.row(F(f, 0)).dot(V.row(F(f, 1)).cross(V.row(F(f, 2))));
  return s / 6;
}

/// V − E + F of the surface F (counting only referenced vertices).
Index euler_characteristic(const Tris& F) {
  std::set<VIndex> verts(F.data(), F.data() + F.size());
  return Index(verts.size()) - unique_edges(F).rows() + F.rows();
}

/// Every undirected edge of F is used exactly twice, once in each direction (closed, consistently oriented).
bool closed_and_oriented(const Tris& F) {
  std::map<std::pair<VIndex, VIndex>, int> directed;
  for (Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) ++directed[{F(f, c), F(f, (c + 1) % 3)}];
  for (auto& [e, n] : directed) {
    auto it = directed.find({e.second, e.first});
    if (n != 1 || it == directed.end() || it->second != 1) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("unique_edges matches a brute-force set for edges, triangles and tets") {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 30; ++trial) {
    const int nv = 5 + int(rng() % 40);
    const Index n = 1 + rng() % 60;
    auto check = [&](const auto& E) {
      std::set<std::pair<VIndex, VIndex>> truth;
      for (Index e = 0; e < E.rows(); ++e)
        for (Index i = 0; i < E.cols(); ++i)
          for (Index j = 0; j < E.cols(); ++j)
            if (E(e, i) < E(e, j)) truth.insert({E(e, i), E(e, j)});
      const Edges U = unique_edges(E);
      REQUIRE(U.rows() == Index(truth.size()));
      Index r = 0;
      for (auto& [a, b] : truth) {  // std::set order is lexicographic: rows must come out sorted
        CHECK(U(r, 0) == a);
        CHECK(U(r, 1) == b);
        ++r;
      }
    };
    check(random_elements<Edges>(n, 2, nv, rng));
    check(random_elements<Tris>(n, 3, nv, rng));
    check(random_elements<Tets>(n, 4, std::max(nv, 4), rng));
    check(random_elements<Eigen::MatrixXi>(n, 4, std::max(nv, 4), rng));
  }
  Tets one(1, 4);
  one << 3, 1, 2, 0;
  CHECK(unique_edges(one).rows() == 6);
  Tris neg(1, 3);
  neg << 0, -1, 2;
  CHECK_THROWS_AS(unique_edges(neg), MeshError);
}

TEST_CASE("vertex_adjacency: sorted, symmetric, no self, same as brute force") {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 30; ++trial) {
    const int nv = 4 + int(rng() % 50);
    const Tets T = random_elements<Tets>(1 + rng() % 40, 4, nv, rng);
    const Index total = nv + 3;  // three trailing vertices that no tet uses
    const Adjacency A = vertex_adjacency(T, total);
    REQUIRE(A.num_vertices() == total);
    std::vector<std::set<VIndex>> truth(static_cast<std::size_t>(total));
    for (Index t = 0; t < T.rows(); ++t)
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          if (i != j) truth[T(t, i)].insert(T(t, j));
    for (Index v = 0; v < total; ++v) {
      auto nb = A[v];
      CHECK(std::vector<VIndex>(nb.begin(), nb.end()) == std::vector<VIndex>(truth[v].begin(), truth[v].end()));
    }
  }
  Tris F(1, 3);
  F << 0, 1, 5;
  CHECK_THROWS_AS(vertex_adjacency(F, 4), MeshError);
  CHECK(vertex_adjacency(F).num_vertices() == 6);
}

TEST_CASE("boundary_faces of box tetrahedralizations: analytic count, closed, outward, encloses the tet volume") {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 24; ++trial) {
    const int nx = 1 + int(rng() % 5), ny = 1 + int(rng() % 5), nz = 1 + int(rng() % 5);
    const double h = 0.1 + 0.01 * double(rng() % 100);
    const bool five = trial % 2;
    TetMesh<> m = box_tets(nx, ny, nz, h, Vec3<>(-1.0, 2.0, 0.5), five);
    CAPTURE(nx);
    CAPTURE(ny);
    CAPTURE(nz);
    CAPTURE(five);
    shuffle_vertices(m.V, m.T, rng);
    const Tris B = boundary_faces(m.T);
    CHECK(B.rows() == box_boundary_count(nx, ny, nz));
    CHECK(euler_characteristic(B) == 2);
    CHECK(closed_and_oriented(B));
    CHECK(boundary_edges(B).rows() == 0);
    // Outward: on a convex box every boundary normal points away from the centre.
    const Vec3<> centre = m.V.colwise().mean().transpose();
    for (Index f = 0; f < B.rows(); ++f) {
      const Vec3<> a = m.V.row(B(f, 0)), b = m.V.row(B(f, 1)), c = m.V.row(B(f, 2));
      CHECK((b - a).cross(c - a).dot((a + b + c) / 3 - centre) > 0);
    }
    // Divergence theorem on a jittered copy: the surface encloses the sum of the tet volumes.
    jitter(m.V, 0.1 * h, rng);
    double tets = 0;
    for (Index t = 0; t < m.T.rows(); ++t) tets += det_volume6(m.V, {m.T(t, 0), m.T(t, 1), m.T(t, 2), m.T(t, 3)}) / 6;
    CHECK(enclosed_volume(m.V, B) == doctest::Approx(tets).epsilon(1e-12));
    const TriMesh<> s = boundary_surface(m);
    CHECK(s.F == B);
    CHECK(s.V.rows() == m.V.rows());
  }
}

TEST_CASE("boundary_faces: a single tet is its own boundary; shared faces cancel; non-manifold faces throw") {
  Tets one(1, 4);
  one << 0, 1, 2, 3;
  CHECK(boundary_faces(one).rows() == 4);
  Tets two(2, 4);
  two << 0, 1, 2, 3, 0, 2, 1, 4;  // glued along (0,1,2), opposite orientations
  CHECK(boundary_faces(two).rows() == 6);
  Tets three(3, 4);
  three << 0, 1, 2, 3, 0, 2, 1, 4, 5, 2, 1, 0;  // face (0,1,2) in three tets
  try {
    boundary_faces(three);
    FAIL("expected MeshError");
  } catch (const MeshError& e) {
    CHECK(e.kind() == "tet");
    CHECK(e.element() == 2);
  }
}

TEST_CASE("connected_components on random unions of disjoint boxes and isolated vertices") {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 20; ++trial) {
    const int boxes = 1 + int(rng() % 5), isolated = int(rng() % 4);
    std::vector<TetMesh<>> parts;
    Index nv = 0, nt = 0;
    for (int b = 0; b < boxes; ++b) {
      parts.push_back(box_tets(1 + rng() % 3, 1 + rng() % 3, 1 + rng() % 3, 1.0, Vec3<>(10.0 * b, 0, 0), rng() & 1));
      nv += parts.back().V.rows(), nt += parts.back().T.rows();
    }
    TetMesh<> m;
    m.V.resize(nv + isolated, 3);
    m.T.resize(nt, 4);
    std::vector<int> box_of(static_cast<std::size_t>(nv + isolated), -1);
    Index v0 = 0, t0 = 0;
    for (int b = 0; b < boxes; ++b) {
      m.V.middleRows(v0, parts[b].V.rows()) = parts[b].V;
      m.T.middleRows(t0, parts[b].T.rows()) = parts[b].T.array() + VIndex(v0);
      std::fill(box_of.begin() + v0, box_of.begin() + v0 + parts[b].V.rows(), b);
      v0 += parts[b].V.rows(), t0 += parts[b].T.rows();
    }
    m.V.bottomRows(isolated).setZero();
    // Shuffle vertex numbers, remembering each vertex's box.
    std::vector<VIndex> p(box_of.size());
    std::iota(p.begin(), p.end(), 0);
    std::shuffle(p.begin(), p.end(), rng);
    std::vector<int> box_of_new(box_of.size());
    for (std::size_t v = 0; v < p.size(); ++v) box_of_new[p[v]] = box_of[v];
    for (Index i = 0; i < m.T.size(); ++i) m.T.data()[i] = p[m.T.data()[i]];

    const Components C = connected_components(m.T, m.V.rows());
    CHECK(C.count == boxes + isolated);
    REQUIRE(C.labels.size() == m.V.rows());
    // Same box ⇔ same label; labels numbered by smallest vertex.
    std::map<int, VIndex> label_of_box;
    VIndex next = 0;
    for (Index v = 0; v < m.V.rows(); ++v) {
      const int b = box_of_new[v];
      if (b < 0) {
        CHECK(C.labels[v] == next++);
        continue;
      }
      auto it = label_of_box.find(b);
      if (it == label_of_box.end()) {
        CHECK(C.labels[v] == next);
        label_of_box[b] = next++;
      } else {
        CHECK(C.labels[v] == it->second);
      }
    }
    CHECK(std::accumulate(C.sizes.begin(), C.sizes.end(), Index(0)) == m.V.rows());
    // The boundary of the union: 2 per component (each box is a sphere).
    CHECK(euler_characteristic(boundary_faces(m.T)) == 2 * boxes);
  }
}

TEST_CASE("boundary_edges and boundary_loops of open surfaces") {
  std::mt19937 rng(5);
  for (int n = 1; n <= 6; ++n) {
    const TriMesh<> g = grid_surface(n, rng);
    const Edges B = boundary_edges(g.F);
    CHECK(B.rows() == 4 * n);
    const auto loops = boundary_loops(g.F);
    REQUIRE(loops.size() == 1);
    CHECK(loops[0].size() == std::size_t(4 * n));
    // boundary_vertices: the loop's vertices, each once, ascending
    const IndexVector bv = boundary_vertices(g.F);
    std::vector<VIndex> from_loop = loops[0];
    std::sort(from_loop.begin(), from_loop.end());
    CHECK(std::vector<VIndex>(bv.data(), bv.data() + bv.size()) == from_loop);
    // Counter-clockwise seen from +z (the normal side): positive shoelace area n².
    double area = 0;
    for (std::size_t i = 0; i < loops[0].size(); ++i) {
      const auto a = g.V.row(loops[0][i]), b = g.V.row(loops[0][(i + 1) % loops[0].size()]);
      area += a.x() * b.y() - b.x() * a.y();
    }
    CHECK(area / 2 == doctest::Approx(double(n * n)));
  }
  // A sphere with k disjoint faces removed has k triangular holes; χ = 2 − k.
  const TriMesh<> s = icosphere(2);
  CHECK(boundary_edges(s.F).rows() == 0);
  CHECK(boundary_loops(s.F).empty());
  CHECK(boundary_vertices(s.F).size() == 0);
  for (int k : {1, 2, 5}) {
    std::vector<Index> keep;
    std::set<VIndex> used;
    int removed = 0;
    for (Index f = 0; f < s.F.rows(); ++f) {
      const bool touches = used.count(s.F(f, 0)) || used.count(s.F(f, 1)) || used.count(s.F(f, 2));
      if (removed < k && f % 7 == 0 && !touches) {
        ++removed;
        for (int c = 0; c < 3; ++c) used.insert(s.F(f, c));
      } else {
        keep.push_back(f);
      }
    }
    REQUIRE(removed == k);
    Tris F(Index(keep.size()), 3);
    for (Index i = 0; i < F.rows(); ++i) F.row(i) = s.F.row(keep[i]);
    const auto loops = boundary_loops(F);
    CHECK(loops.size() == std::size_t(k));
    for (auto& l : loops) CHECK(l.size() == 3);
    CHECK(euler_characteristic(F) == 2 - k);
  }
  // Inconsistent orientation leaves open chains.
  Tris bad(2, 3);
  bad << 0, 1, 2, 0, 1, 3;
  CHECK_THROWS_AS(boundary_loops(bad), MeshError);
}

}  // namespace mesh_test_topology
