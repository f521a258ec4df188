#include <doctest/doctest.h>

#include <simsr/mesh/element_colouring.hpp>
#include <simsr/mesh/generators.hpp>

#include <algorithm>
#include <numeric>
#include <random>
#include <set>

namespace mesh_test_element_colouring {

using namespace simsr;

/// Cells as CSR (offsets, vertices).
struct Cells {
  std::vector<Index> offsets{0}, vertices;
  Index size() const { return Index(offsets.size()) - 1; }
  bool share(Index a, Index b) const {
    for (Index i = offsets[std::size_t(a)]; i < offsets[std::size_t(a) + 1]; ++i)
      for (Index j = offsets[std::size_t(b)]; j < offsets[std::size_t(b) + 1]; ++j)
        if (vertices[std::size_t(i)] == vertices[std::size_t(j)]) return true;
    return false;
  }
};

template <class M>
Cells rows_as_cells(const M& C) {
  Cells cells;
  for (Index c = 0; c < C.rows(); ++c) {
    for (Index a = 0; a < C.cols(); ++a) cells.vertices.push_back(Index(C(c, a)));
    cells.offsets.push_back(Index(cells.vertices.size()));
  }
  return cells;
}

/// Every property a first-fit colouring must have, checked by brute force over all cell pairs:
/// a partition into colours, listed in increasing element order; no two cells of a colour share
/// a vertex; and first fit itself: a cell of colour c has, for every c' < c, an earlier neighbour
/// of colour c' (else greedy would have taken c'); at most 1 + the most neighbours of one cell.
void check_first_fit(const Cells& C, Index num_vertices, const ElementColouring& col) {
  const Index n = C.size();
  REQUIRE(col.num_elements() == n);
  REQUIRE(Index(col.colour_of.size()) == n);
  REQUIRE(col.offsets.front() == 0);
  REQUIRE(col.offsets.back() == n);
  std::vector<int> seen(std::size_t(n), 0);
  for (Index k = 0; k < col.num_colours(); ++k) {
    CHECK(col.size(k) > 0);
    for (Index i = 0; i < col.size(k); ++i) {
      const Index e = col.element(k, i);
      REQUIRE((e >= 0 && e < n));
      ++seen[std::size_t(e)];
      CHECK(col.colour_of[std::size_t(e)] == k);
      if (i > 0) CHECK(col.element(k, i - 1) < e);
    }
  }
  CHECK(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
  std::vector<Index> valence(std::size_t(num_vertices), 0);
  for (Index v : C.vertices) ++valence[std::size_t(v)];
  Index bound = 0;  // 1 + the most neighbours a cell can have
  for (Index c = 0; c < n; ++c) {
    Index b = 1;
    for (Index i = C.offsets[std::size_t(c)]; i < C.offsets[std::size_t(c) + 1]; ++i) b += valence[std::size_t(C.vertices[std::size_t(i)])] - 1;
    bound = std::max(bound, b);
  }
  CHECK(col.num_colours() <= bound);
  for (Index a = 0; a < n; ++a) {
    std::set<Index> earlier;
    for (Index b = 0; b < n; ++b) {
      if (b == a || !C.share(a, b)) continue;
      CHECK(col.colour_of[std::size_t(a)] != col.colour_of[std::size_t(b)]);
      if (b < a) earlier.insert(col.colour_of[std::size_t(b)]);
    }
    for (Index c = 0; c < col.colour_of[std::size_t(a)]; ++c) CHECK(earlier.count(c) == 1);
  }
}

TEST_CASE("greedy_element_colouring: random box tet meshes, shuffled, are coloured first-fit and vertex-disjoint") {
  std::mt19937 rng(31);
  for (int trial = 0; trial < 40; ++trial) {
    const Index nx = 1 + Index(rng() % 4), ny = 1 + Index(rng() % 4), nz = 1 + Index(rng() % 3);
    TetMesh<> mesh = box_tet_mesh<double>(nx, ny, nz);
    std::vector<Index> order(std::size_t(mesh.num_tets()));
    std::iota(order.begin(), order.end(), Index(0));
    std::shuffle(order.begin(), order.end(), rng);
    Tets T(mesh.num_tets(), 4);
    for (Index t = 0; t < T.rows(); ++t) T.row(t) = mesh.T.row(order[std::size_t(t)]);
    const ElementColouring col = greedy_element_colouring(T, mesh.num_vertices());
    check_first_fit(rows_as_cells(T), mesh.num_vertices(), col);
    CHECK(col.num_colours() >= 1);
  }
}

TEST_CASE("greedy_element_colouring: random cell soups of 1 to 5 vertices per cell, and the empty mesh") {
  std::mt19937 rng(32);
  for (int trial = 0; trial < 60; ++trial) {
    const Index k = 1 + Index(rng() % 5), nv = k + Index(rng() % 30), nc = Index(rng() % 80);
    Eigen::Matrix<VIndex, Eigen::Dynamic, Eigen::Dynamic> C(nc, k);
    std::vector<VIndex> pool(static_cast<std::size_t>(nv));
    std::iota(pool.begin(), pool.end(), VIndex(0));
    for (Index c = 0; c < nc; ++c) {
      std::shuffle(pool.begin(), pool.end(), rng);  // distinct vertices within a cell
      for (Index a = 0; a < k; ++a) C(c, a) = pool[std::size_t(a)];
    }
    const ElementColouring col = greedy_element_colouring(C, nv);
    check_first_fit(rows_as_cells(C), nv, col);
    // single-vertex cells: one colour per distinct multiplicity level of a vertex
    if (k == 1 && nc > 0) {
      std::vector<Index> mult(std::size_t(nv), 0);
      for (Index c = 0; c < nc; ++c) ++mult[std::size_t(C(c, 0))];
      CHECK(col.num_colours() == *std::max_element(mult.begin(), mult.end()));
    }
  }
  const ElementColouring none = greedy_element_colouring(Tets(0, 4), 5);
  CHECK(none.num_colours() == 0);
  CHECK(none.num_elements() == 0);
}

TEST_CASE("greedy_colouring: cells of varying sizes (CSR) against brute force; malformed offsets refused") {
  std::mt19937 rng(33);
  for (int trial = 0; trial < 40; ++trial) {
    const Index nv = 1 + Index(rng() % 40), nc = Index(rng() % 50);
    std::vector<Index> offsets{0}, vertices;
    std::vector<Index> pool(static_cast<std::size_t>(nv));
    std::iota(pool.begin(), pool.end(), Index(0));
    for (Index c = 0; c < nc; ++c) {
      std::shuffle(pool.begin(), pool.end(), rng);
      const Index size = Index(rng() % std::min<Index>(nv + 1, 9));  // 0 to 8 vertices; an empty cell conflicts with none
      vertices.insert(vertices.end(), pool.begin(), pool.begin() + size);
      offsets.push_back(Index(vertices.size()));
    }
    const ElementColouring col = greedy_colouring(offsets, vertices, nv);
    check_first_fit(Cells{offsets, vertices}, nv, col);
  }
  CHECK_THROWS_AS(greedy_colouring({}, {}, 3), ArgumentError);
  CHECK_THROWS_AS(greedy_colouring({1, 2}, {0, 1}, 3), ArgumentError);
  CHECK_THROWS_AS(greedy_colouring({0, 2, 1}, {0}, 3), ArgumentError);
  CHECK_THROWS_AS(greedy_colouring({0, 2}, {0, 1, 2}, 3), ArgumentError);
  CHECK_THROWS_WITH_AS(greedy_colouring({0, 2, 4}, {0, 1, 2, 2}, 3), doctest::Contains("cell 1: vertex 2 appears twice"), MeshError);
  CHECK_THROWS_WITH_AS(greedy_colouring({0, 1}, {3}, 3), doctest::Contains("cell 0: vertex index 3 out of range"), MeshError);
}

TEST_CASE("greedy_element_colouring: out-of-range and repeated vertices are MeshErrors naming the cell") {
  Tets T(3, 4);
  T << 0, 1, 2, 3, 1, 2, 3, 4, 2, 3, 4, 9;
  CHECK_THROWS_WITH_AS(greedy_element_colouring(T, 5), doctest::Contains("tet 2: vertex index 9 outside [0, 5)"), MeshError);
  T(2, 3) = -1;
  CHECK_THROWS_WITH_AS(greedy_element_colouring(T, 5), doctest::Contains("tet 2"), MeshError);
  T(2, 3) = 0;
  T(1, 2) = 1;
  CHECK_THROWS_WITH_AS(greedy_element_colouring(T, 5), doctest::Contains("cell 1: vertex 1 appears twice"), MeshError);
  CHECK_THROWS_AS(greedy_element_colouring(Tets(0, 4), -1), ArgumentError);
}

TEST_CASE("greedy_graph_colouring: random symmetric graphs (self-loops listed or not) are coloured first-fit with no adjacent pair alike; one-sided or out-of-range entries refused") {
  std::mt19937 rng(41);
  for (int trial = 0; trial < 60; ++trial) {
    const Index n = Index(rng() % 200);
    const double p = std::uniform_real_distribution<double>(0, 0.2)(rng);
    std::vector<std::vector<int>> adj(static_cast<std::size_t>(n));
    std::vector<std::vector<char>> edge(static_cast<std::size_t>(n), std::vector<char>(static_cast<std::size_t>(n), 0));
    for (Index i = 0; i < n; ++i) {
      if (trial % 2) adj[std::size_t(i)].push_back(int(i));  // a matrix pattern lists the diagonal
      for (Index j = i + 1; j < n; ++j)
        if (std::bernoulli_distribution(p)(rng)) {
          adj[std::size_t(i)].push_back(int(j)), adj[std::size_t(j)].push_back(int(i));
          edge[std::size_t(i)][std::size_t(j)] = edge[std::size_t(j)][std::size_t(i)] = 1;
        }
    }
    std::vector<int> offsets{0}, flat;
    for (auto& a : adj) {
      std::shuffle(a.begin(), a.end(), rng);
      flat.insert(flat.end(), a.begin(), a.end());
      offsets.push_back(int(flat.size()));
    }
    const ElementColouring c = greedy_graph_colouring(offsets.data(), flat.data(), n);
    REQUIRE(c.num_elements() == n);
    std::vector<int> seen(std::size_t(n), 0);
    for (Index k = 0; k < c.num_colours(); ++k) {
      CHECK(c.size(k) > 0);
      for (Index i = 0; i < c.size(k); ++i) {
        const Index v = c.element(k, i);
        ++seen[std::size_t(v)];
        CHECK(c.colour_of[std::size_t(v)] == k);
        if (i > 0) CHECK(c.element(k, i - 1) < v);
      }
    }
    for (Index v = 0; v < n; ++v) {
      CHECK(seen[std::size_t(v)] == 1);
      // first fit: the smallest colour no earlier neighbour has (brute force)
      Index expected = 0;
      const auto taken = [&](Index colour) {
        for (Index w = 0; w < v; ++w)
          if (edge[std::size_t(v)][std::size_t(w)] && c.colour_of[std::size_t(w)] == colour) return true;
        return false;
      };
      while (taken(expected)) ++expected;
      CHECK(c.colour_of[std::size_t(v)] == expected);
      for (Index w = 0; w < n; ++w)
        if (edge[std::size_t(v)][std::size_t(w)]) CHECK(c.colour_of[std::size_t(v)] != c.colour_of[std::size_t(w)]);
    }
  }
  // 0 → 1 listed, 1 → 0 not: refused (they would share colour 0)
  const std::vector<int> one_sided_offsets{0, 1, 1}, one_sided{1};
  CHECK_THROWS_AS(greedy_graph_colouring(one_sided_offsets.data(), one_sided.data(), 2), ArgumentError);
  const std::vector<int> out_offsets{0, 1}, out_of_range{3};
  CHECK_THROWS_AS(greedy_graph_colouring(out_offsets.data(), out_of_range.data(), 1), ArgumentError);
  const std::vector<int> bad_offsets{0, 2, 1}, two{1, 0};
  CHECK_THROWS_AS(greedy_graph_colouring(bad_offsets.data(), two.data(), 2), ArgumentError);
}

}  // namespace mesh_test_element_colouring
