#include <simsr/io/npy.hpp>
#include <simsr/io/obj.hpp>
#include <simsr/neighbors/geodesic_knn.hpp>

#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <filesystem>
#include <random>
#include <string>

#include "../mesh/fixtures.hpp"
#include "knn_reference.hpp"

using namespace simsr;
using neighbors::GeodesicKnn;
using neighbors::KnnResult;

namespace {

/// All-pairs shortest paths along the edges of E by Floyd–Warshall in long double, as a
/// Reference (`keep` closest per vertex by (distance, index); unreachable = −1).
template <class DE>
test::Reference floyd_warshall(const Points<>& V, const Eigen::MatrixBase<DE>& E, Index keep) {
  const Index n = V.rows();
  const long double inf = std::numeric_limits<long double>::infinity();
  std::vector<long double> D(static_cast<std::size_t>(n * n), inf);
  auto at = [&](Index i, Index j) -> long double& { return D[static_cast<std::size_t>(i * n + j)]; };
  for (Index i = 0; i < n; ++i) at(i, i) = 0;
  for (Index e = 0; e < E.rows(); ++e)
    for (Index a = 0; a < E.cols(); ++a)
      for (Index b = a + 1; b < E.cols(); ++b) {
        const Index i = E(e, a), j = E(e, b);
        long double s = 0;
        for (int c = 0; c < 3; ++c) s += (static_cast<long double>(V(i, c)) - V(j, c)) * (static_cast<long double>(V(i, c)) - V(j, c));
        at(i, j) = at(j, i) = std::min(at(i, j), std::sqrt(s));
      }
  for (Index m = 0; m < n; ++m)
    for (Index i = 0; i < n; ++i)
      for (Index j = 0; j < n; ++j) at(i, j) = std::min(at(i, j), at(i, m) + at(m, j));
  test::Reference ref;
  for (Index i = 0; i < n; ++i) {
    std::vector<long double> row(static_cast<std::size_t>(n));
    std::vector<VIndex> order;
    for (Index j = 0; j < n; ++j) {
      row[static_cast<std::size_t>(j)] = at(i, j) == inf ? -1 : at(i, j);
      if (at(i, j) != inf) order.push_back(static_cast<VIndex>(j));
    }
    std::sort(order.begin(), order.end(), [&](VIndex a, VIndex b) { return row[a] < row[b] || (row[a] == row[b] && a < b); });
    order.resize(std::min<std::size_t>(order.size(), static_cast<std::size_t>(keep)));
    ref.dist.push_back(std::move(row));
    ref.order.push_back(std::move(order));
  }
  return ref;
}

template <class DE>
void compare(const Points<>& V, const Eigen::MatrixBase<DE>& E, Index k, const std::string& what, bool exact_ties) {
  GeodesicKnn<double> g(V, E);
  const auto seq = g.query(exec::seq, k);
  const int diff = test::check_against_reference(seq, floyd_warshall(V, E, k + 1), 1e-12L, what);
  if (exact_ties) CHECK_MESSAGE(diff == 0, what);
  for (Index i = 0; i < V.rows(); ++i) {
    REQUIRE(seq.indices(i, 0) == i);
    REQUIRE(seq.distances(i, 0) == 0);
  }
  const auto omp = g.query(exec::omp, k);
  CHECK(omp.indices == seq.indices);
  CHECK(omp.distances == seq.distances);
}

/// A random triangulated nx×ny grid in 3-D (heights random), vertices shuffled.
TriMesh<> random_sheet(int nx, int ny, std::mt19937& rng) {
  TriMesh<> m;
  m.V.resize((nx + 1) * (ny + 1), 3);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.V.row(i + (nx + 1) * j) << i + u(rng), j + u(rng), u(rng);
  m.F.resize(2 * nx * ny, 3);
  Index f = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const VIndex a = i + (nx + 1) * j, b = a + 1, c = a + nx + 1, d = c + 1;
      if (rng() % 2) {
        m.F.row(f++) << a, b, d;
        m.F.row(f++) << a, d, c;
      } else {
        m.F.row(f++) << a, b, c;
        m.F.row(f++) << b, d, c;
      }
    }
  test::shuffle_vertices(m.V, m.F, rng);
  return m;
}

}  // namespace

TEST_CASE("GeodesicKnn equals Floyd–Warshall on random tet and triangle meshes (self first, seq == omp)") {
  std::mt19937 rng(17);
  for (int t = 0; t < 6; ++t) {
    auto m = test::box_tets(2 + t % 3, 3, 2 + t % 2, 0.5, Vec3<>::Zero(), t % 2 == 1);
    test::jitter(m.V, 0.1, rng);
    test::shuffle_vertices(m.V, m.T, rng);
    for (Index k : {Index(1), Index(5), Index(20), m.V.rows()}) compare(m.V, m.T, k, "tets " + std::to_string(t) + " k=" + std::to_string(k), false);
  }
  for (int t = 0; t < 6; ++t) {
    const auto m = random_sheet(3 + t, 4, rng);
    for (Index k : {Index(2), Index(5), Index(12)}) compare(m.V, m.F, k, "sheet " + std::to_string(t) + " k=" + std::to_string(k), false);
  }
  // an unjittered lattice: many equal path lengths, resolved by index
  const auto lattice = test::box_tets(3, 3, 3, 1.0);
  for (Index k : {Index(5), Index(27), Index(64)}) compare(lattice.V, lattice.T, k, "lattice k=" + std::to_string(k), true);
}

TEST_CASE("GeodesicKnn on an edge list: a path graph, and components smaller than k") {
  Points<> V(5, 3);
  V << 0, 0, 0, 1, 0, 0, 3, 0, 0, 3.5, 0, 0, 10, 0, 0;
  Edges E(3, 2);
  E << 0, 1, 1, 2, 2, 3;  // vertex 4 is isolated
  GeodesicKnn<double> g(V, E);
  KnnResult<double> r;
  g.query_into(exec::seq, 1, r);
  CHECK(r.indices(4, 0) == 4);
  CHECK_THROWS_WITH_AS(g.query_into(exec::omp, 2, r), doctest::Contains("vertex 4 reaches only 1 vertices"), ArgumentError);
  Edges E2(4, 2);
  E2 << 0, 1, 1, 2, 2, 3, 3, 4;
  const auto r2 = neighbors::geodesic_knn(exec::seq, V, E2, 3);
  CHECK(r2.indices.row(2) == Eigen::RowVector3i(2, 3, 1));
  CHECK(r2.distances.row(2) == Eigen::RowVector3d(0, 0.5, 2));
  CHECK(r2.indices.row(0) == Eigen::RowVector3i(0, 1, 2));
  CHECK(r2.distances(0, 2) == 3);
  CHECK(r2.indices.row(4) == Eigen::RowVector3i(4, 3, 2));
  CHECK_THROWS_WITH_AS(neighbors::geodesic_knn(exec::seq, V, E2, 6), doctest::Contains("k = 6 exceeds the 5 vertices"), ArgumentError);
  CHECK_THROWS_WITH_AS(neighbors::geodesic_knn(exec::seq, V, E2, 0), doctest::Contains("k = 0 must be at least 1"), ArgumentError);
  Edges bad(1, 2);
  bad << 0, 7;
  CHECK_THROWS_AS(GeodesicKnn<double>(V, bad), MeshError);
  Eigen::MatrixXd V2 = Eigen::MatrixXd::Zero(5, 2);
  CHECK_THROWS_WITH_AS(GeodesicKnn<double>(V2, E2), doctest::Contains("expected shape (*, 3), got (5, 2)"), ShapeError);
  V(1, 1) = std::nan("");
  CHECK_THROWS_WITH_AS(GeodesicKnn<double>(V, E2), doctest::Contains("vertices row 1 holds a non-finite"), ArgumentError);
}

namespace {

/// Neighbours shared (as sets) by the first kk of every row of two index tables.
template <class A, class B>
Index shared_neighbours(const A& a, const B& b, Index kk) {
  Index shared = 0;
  for (Index i = 0; i < a.rows(); ++i)
    for (Index x = 0; x < kk; ++x)
      for (Index y = 0; y < kk; ++y) shared += a(i, x) == b(i, y);
  return shared;
}

}  // namespace

// The authors' geo_dist_tet2tet{,_idx}.npy (1747×100, self first) come with no script in their
// repository. Every tet edge of lrestshape.obj appears in them, and their edge lengths are the
// ideal lattice ones (h√3/2, h, h√2 with h = 0.0125, to float32 rounding), not the lengths of the
// vertices in lrestshape.obj (0.0104–0.0181): Dijkstra over the same edge graph measured on the
// undeformed embedding lattice. Their ties are in no particular order (about half of the
// equal-distance neighbours in their rows are not index-ascending).
TEST_CASE("GeodesicKnn on the bunny's LR tet mesh against the authors' precomputed geodesic neighbours") {
  const std::filesystem::path dir = std::filesystem::path(SIMSR_DATA_DIR) / "bunny";
  if (!std::filesystem::exists(dir / "lrestshape.obj") || !std::filesystem::exists(dir / "geo_dist_tet2tet_idx.npy")) {
    SIMSR_MISSING("bunny data not found in " << dir);
    return;
  }
  const auto lr = io::read_obj_tets<double>(dir / "lrestshape.obj");
  REQUIRE(lr.V.rows() == 1747);
  REQUIRE(lr.T.rows() == 4896);
  const auto their_idx = io::read_npy(dir / "geo_dist_tet2tet_idx.npy").to_matrix<std::int64_t>();
  const auto their_dist = io::read_npy(dir / "geo_dist_tet2tet.npy").to_matrix<double>();
  REQUIRE(their_idx.rows() == 1747);
  REQUIRE(their_idx.cols() == 100);
  const Index n = 1747, k = 20;

  // 1. Their graph: our edges, their lengths. Distances must agree to rounding, neighbour sets
  //    wherever no tie straddles the cut.
  const Edges E = unique_edges(lr.T);
  Eigen::VectorXd their_len(E.rows());
  for (Index e = 0; e < E.rows(); ++e) {
    Index j = 0;
    while (j < 100 && their_idx(E(e, 0), j) != E(e, 1)) ++j;
    REQUIRE_MESSAGE(j < 100, "edge " << E(e, 0) << "-" << E(e, 1) << " missing from the authors' neighbours");
    their_len(e) = their_dist(E(e, 0), j);
  }
  GeodesicKnn<double> lattice;
  lattice.build_graph(n, E, their_len);
  const auto same_graph = lattice.query(exec::omp, k);
  CHECK((same_graph.distances - their_dist.leftCols(k)).cwiseAbs().maxCoeff() < 1e-15);
  for (Index kk : {Index(5), Index(20)}) {
    Index rows_without_tie = 0, rows_equal = 0;
    for (Index i = 0; i < n; ++i) {
      if (their_dist(i, kk - 1) == their_dist(i, kk)) continue;
      ++rows_without_tie;
      std::vector<std::int64_t> a(same_graph.indices.row(i).data(), same_graph.indices.row(i).data() + kk), b(their_idx.row(i).data(), their_idx.row(i).data() + kk);
      std::sort(a.begin(), a.end()), std::sort(b.begin(), b.end());
      rows_equal += a == b;
    }
    CHECK(rows_equal == rows_without_tie);
    MESSAGE("authors' edge lengths, first " << kk << ": " << shared_neighbours(same_graph.indices, their_idx, kk) << " / " << kk * n
                                            << " shared; rows without a tie across the cut: " << rows_equal << " / " << rows_without_tie << " identical sets");
  }

  // 2. Lengths measured on lrestshape.obj's vertices (what geodesic_knn(V, T) does).
  GeodesicKnn<double> g(lr.V, lr.T);
  const auto ours = g.query(exec::omp, k);
  const auto seq = g.query(exec::seq, k);
  CHECK(ours.indices == seq.indices);
  CHECK(ours.distances == seq.distances);
  for (Index i = 0; i < n; ++i) REQUIRE(ours.indices(i, 0) == i);
  const double max_diff = (ours.distances - their_dist.leftCols(k)).cwiseAbs().maxCoeff();
  const Index shared5 = shared_neighbours(ours.indices, their_idx, 5), shared20 = shared_neighbours(ours.indices, their_idx, 20);
  MESSAGE("rest-pose edge lengths: first 5 shared " << shared5 << " / " << 5 * n << ", first 20 shared " << shared20 << " / " << 20 * n
                                                    << ", max |distance difference| over ranks 0..19 " << max_diff);
  CHECK(shared5 >= Index(0.88 * 5 * n));
  CHECK(shared20 >= Index(0.9 * 20 * n));
  CHECK(max_diff < 0.2 * 0.0125);  // a fifth of a lattice edge
}
