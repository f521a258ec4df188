#include <simsr/io/npy.hpp>
#include <simsr/neighbors/brute_force_knn.hpp>
#include <simsr/neighbors/concepts.hpp>
#include <simsr/neighbors/geodesic_knn.hpp>
#include <simsr/neighbors/kd_tree.hpp>

#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

#include "knn_reference.hpp"

using namespace simsr;
using neighbors::KdTree;
using neighbors::KnnResult;

static_assert(neighbors::NeighborSearch<KdTree<double>>);
static_assert(neighbors::NeighborSearch<KdTree<float>>);
static_assert(neighbors::assert_neighbor_search<neighbors::BruteForceKnn<float>>());
static_assert(!neighbors::NeighborSearch<neighbors::GeodesicKnn<double>>, "a geodesic search is built on a mesh, not on points");
static_assert(!neighbors::NeighborSearch<Points<double>>);
static_assert(!std::is_constructible_v<KdTree<double>, Points<double>&&>, "a tree must not borrow a temporary");

namespace {

template <class S>
long double tolerance() {
  return std::is_same_v<S, float> ? 2e-6L : 1e-14L;
}

template <class S>
void random_case(std::mt19937& rng, Index n, Index nq, Index k, int kind) {
  const Points<S> P = test::random_points<Points<S>>(n, 3, kind, rng);
  Points<S> Q = test::random_points<Points<S>>(nq, 3, kind, rng);
  for (Index i = 0; i < nq; i += 4) Q.row(i) = P.row(std::uniform_int_distribution<Index>(0, n - 1)(rng));  // queries on points
  KdTree<S> tree(P, {static_cast<std::size_t>(1 + rng() % 16)});
  const auto seq = tree.query(exec::seq, Q, k);
  const std::string what = std::string(std::is_same_v<S, float> ? "float" : "double") + " n=" + std::to_string(n) + " nq=" +
                           std::to_string(nq) + " k=" + std::to_string(k) + " kind=" + std::to_string(kind);
  const int differing = test::check_against_reference(seq, test::reference_knn(Q, P, k + 1), tolerance<S>() * 4, what);
  if (kind >= 2) CHECK_MESSAGE(differing == 0, what);  // exact ties: the smaller index, always
  const auto omp = tree.query(exec::omp, Q, k);
  CHECK(omp.indices == seq.indices);
  CHECK(omp.distances == seq.distances);
}

}  // namespace

TEST_CASE("KdTree matches a long-double brute force on random point sets (float and double, ties, duplicates)") {
  std::mt19937 rng(7);
  for (int kind = 0; kind < 4; ++kind)
    for (Index n : {1, 2, 9, 64, 700}) {
      for (Index k : {Index(1), Index(3), std::min<Index>(n, 20), n}) {
        if (k > n) continue;
        random_case<double>(rng, n, 37, k, kind);
        random_case<float>(rng, n, 37, k, kind);
      }
    }
  random_case<double>(rng, 5000, 800, 20, 1);
  random_case<float>(rng, 5000, 800, 20, 3);
}

TEST_CASE("KdTree: a query point equal to an indexed point finds it first at distance 0; exact duplicates come by index") {
  Points<double> P(6, 3);
  P << 0, 0, 0, 1, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0, 1, 0, 0;
  KdTree<double> tree(P);
  Points<double> Q(2, 3);
  Q << 0, 0, 0, 1, 0, 0;
  const auto r = tree.query(exec::seq, Q, 4);
  CHECK(r.indices.row(0) == Eigen::RowVector4i(0, 2, 4, 1));
  CHECK(r.distances.row(0) == Eigen::RowVector4d(0, 0, 0, 1));
  CHECK(r.indices.row(1) == Eigen::RowVector4i(1, 5, 0, 2));
  CHECK(r.distances.row(1) == Eigen::RowVector4d(0, 0, 1, 1));
  const auto r1 = tree.query(exec::seq, Q, 2);  // the boundary tie keeps the smaller indices
  CHECK(r1.indices.row(0) == Eigen::RowVector2i(0, 2));
}

TEST_CASE("KdTree::query_into reuses the result's storage") {
  std::mt19937 rng(3);
  const auto P = test::random_points<Points<double>>(500, 3, 0, rng);
  const auto Q = test::random_points<Points<double>>(100, 3, 0, rng);
  KdTree<double> tree(P);
  KnnResult<double> r;
  tree.query_into(exec::omp, Q, 8, r);
  const VIndex* pi = r.indices.data();
  const double* pd = r.distances.data();
  const auto first = r;
  tree.query_into(exec::omp, Q, 8, r);
  CHECK(r.indices.data() == pi);
  CHECK(r.distances.data() == pd);
  CHECK(r.indices == first.indices);
  // any Eigen expression with 3 columns works as queries, column-major and other scalar types too
  const Eigen::MatrixXf Qf = Q.cast<float>();
  const auto rf = tree.query(exec::seq, Qf, 8);
  CHECK(rf.queries() == 100);
  // a Map of caller-owned memory is a valid point set
  KdTree<double> mapped(Eigen::Map<const Points<double>>(P.data(), P.rows(), 3));
  CHECK(mapped.query(exec::seq, Q, 8).indices == first.indices);
}

TEST_CASE("KdTree::radius_into returns the points strictly inside the radius, sorted") {
  std::mt19937 rng(11);
  const auto P = test::random_points<Points<double>>(400, 3, 3, rng);
  KdTree<double> tree(P);
  std::vector<std::pair<VIndex, double>> hits;
  for (int t = 0; t < 20; ++t) {
    const Vec3<> q = P.row(t * 7).transpose() + Vec3<>::Constant(0.01 * t);
    const double radius = 0.05 * (t + 1);
    tree.radius_into(q, radius, hits);
    std::vector<std::pair<double, VIndex>> expect;
    for (Index j = 0; j < P.rows(); ++j) {
      const double d2 = (P.row(j).transpose() - q).squaredNorm();
      if (d2 < radius * radius) expect.emplace_back(std::sqrt(d2), static_cast<VIndex>(j));
    }
    std::sort(expect.begin(), expect.end());
    REQUIRE(hits.size() == expect.size());
    for (std::size_t i = 0; i < hits.size(); ++i) {
      CHECK(hits[i].first == expect[i].second);
      CHECK(hits[i].second == doctest::Approx(expect[i].first).epsilon(1e-12));
    }
  }
}

TEST_CASE("KdTree rejects bad input with messages that say what and where") {
  Points<double> P = Points<double>::Random(10, 3);
  KdTree<double> tree(P);
  Points<double> Q = Points<double>::Random(4, 3);
  CHECK_THROWS_WITH_AS(tree.query(exec::seq, Q, 0), doctest::Contains("k = 0 must be at least 1"), ArgumentError);
  CHECK_THROWS_WITH_AS(tree.query(exec::seq, Q, 11), doctest::Contains("k = 11 exceeds the 10 indexed points"), ArgumentError);
  Eigen::MatrixXd Q2 = Eigen::MatrixXd::Zero(4, 2);
  CHECK_THROWS_WITH_AS(tree.query(exec::seq, Q2, 1), doctest::Contains("expected shape (*, 3), got (4, 2)"), ShapeError);
  Q(2, 1) = std::nan("");
  CHECK_THROWS_WITH_AS(tree.query(exec::omp, Q, 1), doctest::Contains("query row 2 holds a non-finite"), ArgumentError);
  P(7, 2) = std::numeric_limits<double>::infinity();
  KdTree<double> bad;
  CHECK_THROWS_WITH_AS(bad.build(P), doctest::Contains("points row 7 holds a non-finite coordinate"), ArgumentError);
  CHECK_THROWS_WITH_AS(bad.query(exec::seq, Q, 1), doctest::Contains("exceeds the 0 indexed points"), ArgumentError);
}

namespace {

/// The peer script next to the sources: SIMSR_SOURCE_DIR when the build defines it, else the
/// path of this file.
std::filesystem::path peer_script() {
#ifdef SIMSR_SOURCE_DIR
  return std::filesystem::path(SIMSR_SOURCE_DIR) / "scripts/peers/knn_peer.py";
#else
  return std::filesystem::path(__FILE__).parent_path().parent_path().parent_path() / "scripts/peers/knn_peer.py";
#endif
}

bool debian_scipy_available() {
  return std::filesystem::exists("/usr/bin/python3") && std::system("/usr/bin/python3 -c 'import scipy.spatial' >/dev/null 2>&1") == 0;
}

}  // namespace

TEST_CASE("KdTree gives exactly scipy's cKDTree results (peer script, when Debian's scipy is there)") {
  const auto script = peer_script();
  if (!std::filesystem::exists(script) || !debian_scipy_available()) {
    SIMSR_MISSING("/usr/bin/python3 with scipy (python3-scipy) or " << script << " not found");
    return;
  }
  const std::filesystem::path tmp = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "knn_peer";
  std::filesystem::create_directories(tmp);
  std::mt19937 rng(2023);
  for (int kind : {0, 1}) {
    const auto P = test::random_points<Points<double>>(3000, 3, kind, rng);
    const auto Q = test::random_points<Points<double>>(1000, 3, kind, rng);
    const Index k = 20;
    io::write_npy(tmp / "points.npy", P);
    io::write_npy(tmp / "queries.npy", Q);
    const std::string cmd = "/usr/bin/python3 '" + script.string() + "' --points '" + (tmp / "points.npy").string() + "' --queries '" +
                            (tmp / "queries.npy").string() + "' --k " + std::to_string(k) + " --indices '" + (tmp / "idx.npy").string() +
                            "' --distances '" + (tmp / "dist.npy").string() + "'";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const auto idx = io::read_npy(tmp / "idx.npy").to_matrix<std::int64_t>();
    const auto dist = io::read_npy(tmp / "dist.npy").to_matrix<double>();
    const auto r = KdTree<double>(P).query(exec::omp, Q, k);
    REQUIRE(idx.rows() == Q.rows());
    REQUIRE(idx.cols() == k);
    CHECK((idx.cast<VIndex>().array() == r.indices.array()).all());
    CHECK((dist - r.distances).cwiseAbs().maxCoeff() <= 1e-12);
  }
}
