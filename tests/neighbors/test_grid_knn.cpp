#include <simsr/neighbors/concepts.hpp>
#include <simsr/neighbors/grid_knn.hpp>
#include <simsr/neighbors/kd_tree.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <limits>
#include <random>
#include <string>

#include "knn_reference.hpp"

using namespace simsr;
using neighbors::GridKnn;
using neighbors::KdTree;
using neighbors::KnnResult;

static_assert(neighbors::assert_neighbor_search<GridKnn<double>>());
static_assert(neighbors::NeighborSearch<GridKnn<float>>);

namespace {

/// The grid against the kd-tree (the same indices and distances, bitwise: the same squared
/// distances and tie rule) and the long-double reference; seq == omp.
template <class S>
void grid_case(const Points<S>& P, const Points<S>& Q, Index k, double per_cell, const std::string& what) {
  INFO(what);
  GridKnn<S> grid(P, {per_cell});
  const KdTree<S> tree(P);
  const auto seq = grid.query(exec::seq, Q, k);
  const auto omp = grid.query(exec::omp, Q, k);
  const auto kd = tree.query(exec::seq, Q, k);
  CHECK(seq.indices == kd.indices);
  CHECK(seq.distances == kd.distances);
  CHECK(omp.indices == seq.indices);
  CHECK(omp.distances == seq.distances);
  const long double scale = 1 + std::max(P.cwiseAbs().maxCoeff(), Q.cwiseAbs().maxCoeff());  // distances round relative to the coordinates
  test::check_against_reference(seq, test::reference_knn(Q, P, std::min<Index>(k + 1, P.rows())),
                                (std::is_same_v<S, float> ? 1e-5L : 1e-13L) * scale, what);
}

}  // namespace

TEST_CASE("GridKnn equals KdTree bitwise on random sets (clusters, lattice ties, duplicates, queries outside, k up to N)") {
  std::mt19937 rng(31);
  int cases = 0;
  for (int kind = 0; kind < 4; ++kind)
    for (Index n : {1, 2, 19, 300, 2000}) {
      const Points<double> P = test::random_points<Points<double>>(n, 3, kind, rng);
      Points<double> Q = test::random_points<Points<double>>(97, 3, kind, rng);
      for (Index i = 0; i < Q.rows(); i += 3) Q.row(i) *= 3.0;  // outside the grid's box
      for (Index i = 1; i < Q.rows(); i += 5) Q.row(i) = P.row(std::uniform_int_distribution<Index>(0, n - 1)(rng));  // on points
      const double per_cell = std::array<double, 3>{0.3, 2.0, 10.0}[static_cast<std::size_t>(rng() % 3)];
      for (Index k : {Index(1), std::min<Index>(n, 20), n}) {
        const std::string what = "kind " + std::to_string(kind) + " n=" + std::to_string(n) + " k=" + std::to_string(k) + " per_cell=" + std::to_string(per_cell);
        grid_case<double>(P, Q, k, per_cell, what);
        grid_case<float>(P.cast<float>(), Q.cast<float>(), k, per_cell, what + " float");
        cases += 2;
      }
    }
  CHECK(cases == 4 * 5 * 3 * 2);
}

TEST_CASE("GridKnn on degenerate sets: one point repeated, a plane, a line, far-apart clusters") {
  std::mt19937 rng(37);
  std::uniform_real_distribution<double> u(-1, 1);
  Points<double> same(50, 3), plane(400, 3), line(300, 3), far(200, 3), Q(60, 3);
  for (Index i = 0; i < 50; ++i) same.row(i) << 0.25, -0.5, 1.0;
  for (Index i = 0; i < 400; ++i) plane.row(i) << u(rng), u(rng), 0.0;
  for (Index i = 0; i < 300; ++i) line.row(i) << 0.0, u(rng), 2.0;
  for (Index i = 0; i < 200; ++i) far.row(i) << u(rng) + (i % 2 ? 1e4 : 0), u(rng), u(rng);  // two clusters 10 km apart: mostly empty cells
  for (Index i = 0; i < Q.size(); ++i) Q.data()[i] = 2 * u(rng);
  grid_case<double>(same, Q, 7, 2.0, "one point 50 times");
  grid_case<double>(plane, Q, 20, 2.0, "plane");
  grid_case<double>(line, Q, 20, 2.0, "line");
  grid_case<double>(far, Q, 20, 2.0, "far clusters");
  grid_case<double>(far, Q, 150, 2.0, "far clusters, k past one cluster");
}

TEST_CASE("GridKnn reuses the result's storage and its own") {
  std::mt19937 rng(41);
  const Points<double> P = test::random_points<Points<double>>(500, 3, 0, rng);
  const Points<double> Q = test::random_points<Points<double>>(200, 3, 0, rng);
  GridKnn<double> grid(P);
  KnnResult<double> r;
  grid.query_into(exec::omp, Q, 8, r);
  const auto first = r;
  const VIndex* pi = r.indices.data();
  grid.query_into(exec::omp, Q, 8, r);
  CHECK(r.indices.data() == pi);
  CHECK(r.indices == first.indices);
  CHECK(r.distances == first.distances);
}

TEST_CASE("GridKnn rejects bad input with messages that say what and where") {
  Points<double> P = Points<double>::Random(6, 3);
  GridKnn<double> grid(P);
  KnnResult<double> r;
  CHECK_THROWS_WITH_AS(grid.query_into(exec::seq, P, 7, r), doctest::Contains("k = 7 exceeds the 6 indexed points"), ArgumentError);
  CHECK_THROWS_WITH_AS(grid.query_into(exec::seq, P, 0, r), doctest::Contains("k = 0 must be at least 1"), ArgumentError);
  const Eigen::MatrixXd Q2 = Eigen::MatrixXd::Random(3, 2);
  CHECK_THROWS_WITH_AS(grid.query_into(exec::seq, Q2, 1, r), doctest::Contains("expected shape (*, 3), got (3, 2)"), ShapeError);
  Points<double> Q = Points<double>::Random(40, 3);
  Q(33, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH_AS(grid.query_into(exec::omp, Q, 1, r), doctest::Contains("query row 33 holds a non-finite"), ArgumentError);
  P(4, 2) = -std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH_AS(GridKnn<double>{P}, doctest::Contains("points row 4 holds a non-finite"), ArgumentError);
  const Points<double> Z = Points<double>::Zero(3, 3);
  CHECK_THROWS_WITH_AS(GridKnn<double>(Z, {0.0}), doctest::Contains("points_per_cell must be finite and > 0"), ArgumentError);
  GridKnn<double> empty(Points<double>(0, 3));
  CHECK(empty.size() == 0);
  CHECK_THROWS_AS(empty.query_into(exec::seq, Z, 1, r), ArgumentError);
}
