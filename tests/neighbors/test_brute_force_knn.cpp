#include <simsr/neighbors/brute_force_knn.hpp>
#include <simsr/neighbors/concepts.hpp>
#include <simsr/neighbors/kd_tree.hpp>

#include <doctest/doctest.h>

#include <array>
#include <random>
#include <string>

#include "knn_reference.hpp"

using namespace simsr;
using neighbors::BruteForceKnn;
using neighbors::KnnResult;

template <class S>
using Features = typename BruteForceKnn<S>::point_matrix;

static_assert(neighbors::NeighborSearch<BruteForceKnn<float>>);
static_assert(neighbors::NeighborSearch<BruteForceKnn<double>>);
static_assert(!std::is_constructible_v<BruteForceKnn<float>, Features<float>&&>, "must not borrow a temporary");

namespace {

template <class S>
std::string name(Index n, Index d, Index k, int kind, const char* mode) {
  return std::string(std::is_same_v<S, float> ? "float" : "double") + " n=" + std::to_string(n) + " D=" + std::to_string(d) +
         " k=" + std::to_string(k) + " kind=" + std::to_string(kind) + " " + mode;
}

/// Tolerance on distances: the direct re-ranking is accumulated in double from S inputs.
template <class S>
long double tolerance(Index d) {
  return (std::is_same_v<S, float> ? 1e-6L : 1e-13L) * std::sqrt(static_cast<long double>(d)) * 4;
}

template <class S>
void random_case(std::mt19937& rng, Index n, Index d, Index k, int kind, typename BruteForceKnn<S>::Params params) {
  const auto P = test::random_points<Features<S>>(n, d, kind, rng);
  BruteForceKnn<S> knn(P, params);
  const long double tol = tolerance<S>(d);
  const bool exact_ties = kind >= 2 && params.extra_candidates > 0;  // integer lattice / exact duplicates (need a margin: GEMM rounds duplicates apart)
  if (k < n) {  // self excluded
    const auto seq = knn.query_self(exec::seq, k, true);
    const int diff = test::check_against_reference(seq, test::reference_knn(P, P, k + 1, true), tol, name<S>(n, d, k, kind, "self excluded"));
    if (exact_ties) CHECK_MESSAGE(diff == 0, name<S>(n, d, k, kind, "exact ties"));
    for (Index i = 0; i < n; ++i)
      for (Index j = 0; j < k; ++j) REQUIRE(seq.indices(i, j) != i);
    const auto omp = knn.query_self(exec::omp, k, true);
    CHECK(omp.indices == seq.indices);
    CHECK(omp.distances == seq.distances);
  }
  {  // self included: distance 0 first (an earlier exact duplicate may precede it)
    const auto seq = knn.query_self(exec::seq, k, false);
    const int diff = test::check_against_reference(seq, test::reference_knn(P, P, k + 1, false), tol, name<S>(n, d, k, kind, "self included"));
    if (exact_ties) CHECK_MESSAGE(diff == 0, name<S>(n, d, k, kind, "exact ties"));
    for (Index i = 0; i < n; ++i) REQUIRE(seq.distances(i, 0) == 0);
    if (kind == 1) {
      const auto omp = knn.query_self(exec::omp, k, false);
      CHECK(omp.indices == seq.indices);
      CHECK(omp.distances == seq.distances);
    }
  }
  {  // another query set
    const auto Q = test::random_points<Features<S>>(23, d, kind, rng);
    const auto seq = knn.query(exec::seq, Q, k);
    const int diff = test::check_against_reference(seq, test::reference_knn(Q, P, k + 1), tol, name<S>(n, d, k, kind, "queries"));
    if (exact_ties) CHECK_MESSAGE(diff == 0, name<S>(n, d, k, kind, "exact ties"));
    const auto omp = knn.query(exec::omp, Q, k);
    CHECK(omp.indices == seq.indices);
    CHECK(omp.distances == seq.distances);
  }
}

}  // namespace

TEST_CASE("BruteForceKnn matches a long-double brute force (dimensions 1..64, float and double, ties, clusters)") {
  std::mt19937 rng(5);
  const typename BruteForceKnn<float>::Params tiny{7, 13, 8};
  for (int kind = 0; kind < 4; ++kind)
    for (Index d : {1, 3, 64})
      for (Index n : {2, 10, 150}) {
        const Index k5 = std::min<Index>(n - 1, 5);
        for (Index k : {Index(1), k5, n - 1}) random_case<float>(rng, n, d, k, kind, tiny);
        random_case<double>(rng, n, d, k5, kind, {7, 13, 8});
        random_case<float>(rng, n, d, std::min<Index>(n - 1, 4), kind, {});
        random_case<double>(rng, n, d, std::min<Index>(n - 1, 4), kind, {5, 11, 0});
      }
}

TEST_CASE("BruteForceKnn under seq and omp is bitwise identical at a size where Eigen's own product would start threads") {
  std::mt19937 rng(9);
  const auto P = test::random_points<Features<float>>(3000, 64, 1, rng);
  BruteForceKnn<float> knn(P);
  KnnResult<float> seq, omp;
  knn.query_self_into(exec::seq, 5, seq);
  knn.query_self_into(exec::omp, 5, omp);
  CHECK(omp.indices == seq.indices);
  CHECK(omp.distances == seq.distances);
  // and agrees with the reference on a sample of rows
  const Features<float> sample = P.topRows(200);
  const auto r = knn.query(exec::omp, sample, 6);
  const int diff = test::check_against_reference(r, test::reference_knn(sample, P, 7), tolerance<float>(64), "3000×64 sample");
  CHECK(diff <= 2);
  for (Index i = 0; i < 200; ++i) CHECK(r.indices(i, 0) == i);
  for (Index i = 0; i < 200; ++i)
    for (Index j = 0; j < 5; ++j) CHECK(r.indices(i, j + 1) == seq.indices(i, j));
}

TEST_CASE("BruteForceKnn reuses its buffers and the result's storage") {
  std::mt19937 rng(1);
  const auto P = test::random_points<Features<float>>(500, 8, 0, rng);
  BruteForceKnn<float> knn(P, {64, 128, 4});
  KnnResult<float> r;
  knn.query_self_into(exec::omp, 5, r);
  const auto first = r;
  const VIndex* pi = r.indices.data();
  knn.query_self_into(exec::omp, 5, r);
  CHECK(r.indices.data() == pi);
  CHECK(r.indices == first.indices);
  CHECK(r.distances == first.distances);
}

TEST_CASE("KdTree and BruteForceKnn<double> agree through the NeighborSearch concept") {
  auto run = []<neighbors::NeighborSearch Search>(Search& s, const typename Search::point_matrix& P, Index k) {
    s.build(P);
    return s.query(exec::omp, P, k);
  };
  std::mt19937 rng(4);
  const Points<double> P3 = test::random_points<Points<double>>(800, 3, 0, rng);
  const Features<double> PD = P3;
  neighbors::KdTree<double> tree;
  BruteForceKnn<double> brute;
  const auto a = run(tree, P3, 12);
  const auto b = run(brute, PD, 12);
  CHECK(a.indices == b.indices);
  CHECK((a.distances - b.distances).cwiseAbs().maxCoeff() < 1e-14);
}

TEST_CASE("BruteForceKnn rejects bad input with messages that say what and where") {
  Features<float> P = Features<float>::Random(6, 4);
  BruteForceKnn<float> knn(P);
  KnnResult<float> r;
  CHECK_THROWS_WITH_AS(knn.query_self_into(exec::seq, 6, r), doctest::Contains("k = 6 exceeds the 5 other points"), ArgumentError);
  CHECK_NOTHROW(knn.query_self_into(exec::seq, 6, r, false));
  CHECK_THROWS_WITH_AS(knn.query_self_into(exec::seq, 0, r), doctest::Contains("k = 0 must be at least 1"), ArgumentError);
  Features<float> Q = Features<float>::Random(3, 5);
  CHECK_THROWS_WITH_AS(knn.query_into(exec::seq, Q, 1, r), doctest::Contains("expected shape (*, 4), got (3, 5)"), ShapeError);
  Features<float> Q4 = Features<float>::Random(300, 4);
  Q4(201, 3) = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH_AS(knn.query_into(exec::omp, Q4, 1, r), doctest::Contains("query row 201 holds a non-finite"), ArgumentError);
  P(2, 1) = std::numeric_limits<float>::infinity();
  CHECK_THROWS_WITH_AS(BruteForceKnn<float>{P}, doctest::Contains("points row 2 holds a non-finite"), ArgumentError);
  const Features<float> Z = Features<float>::Zero(3, 2);
  CHECK_THROWS_WITH_AS(BruteForceKnn<float>(Z, {0, 10, 1}), doctest::Contains("query_block and point_block must be >= 1"), ArgumentError);
}

namespace {

/// Rows of a and b agree up to the order of exact ties: the same distances bitwise, and wherever
/// the indices differ, the distance is tied with another entry of the row or with the k-th (a
/// tie group cut at k may keep different members).
template <class S>
void check_same_up_to_ties(const KnnResult<S>& a, const KnnResult<S>& b, const std::string& what) {
  INFO(what);
  REQUIRE(a.indices.rows() == b.indices.rows());
  REQUIRE(a.indices.cols() == b.indices.cols());
  CHECK(a.distances == b.distances);
  const Index k = a.k();
  int untied = 0;
  for (Index i = 0; i < a.queries(); ++i)
    for (Index j = 0; j < k; ++j) {
      if (a.indices(i, j) == b.indices(i, j)) continue;
      const S d = a.distances(i, j);
      const bool tied = (j > 0 && a.distances(i, j - 1) == d) || (j + 1 < k && a.distances(i, j + 1) == d) || a.distances(i, k - 1) == d;
      untied += !tied;
    }
  CHECK(untied == 0);
}

/// The fused self-query kernel against the blocked-GEMM one and the long-double reference, over
/// one random set; seq == omp bitwise.
template <class S>
void fused_case(std::mt19937& rng, Index n, Index d, Index k, int kind, typename BruteForceKnn<S>::Params params, bool exclude_self) {
  const auto P = test::random_points<Features<S>>(n, d, kind, rng);
  BruteForceKnn<S> fused(P, params);
  BruteForceKnn<S, neighbors::SelfKernel::blocked_gemm> gemm(P, params);
  const std::string what = name<S>(n, d, k, kind, exclude_self ? "fused, self excluded" : "fused, self included") +
                           " tile=" + std::to_string(params.query_block);
  const auto seq = fused.query_self(exec::seq, k, exclude_self);
  const auto omp = fused.query_self(exec::omp, k, exclude_self);
  CHECK_MESSAGE(omp.indices == seq.indices, what);
  CHECK_MESSAGE(omp.distances == seq.distances, what);
  check_same_up_to_ties(seq, gemm.query_self(exec::omp, k, exclude_self), what + " vs blocked_gemm");
  const int diff = test::check_against_reference(seq, test::reference_knn(P, P, k + 1, exclude_self), tolerance<S>(d), what);
  if (kind >= 2 && params.extra_candidates > 0) CHECK_MESSAGE(diff == 0, (what + ": exact ties by index"));
  if (exclude_self)
    for (Index i = 0; i < n; ++i)
      for (Index j = 0; j < k; ++j) REQUIRE(seq.indices(i, j) != i);
}

}  // namespace

TEST_CASE("BruteForceKnn's fused self-query kernel: feature widths 1..130, sizes off the tile and panel sizes, ties, k = N-1") {
  std::mt19937 rng(17);
  int cases = 0;
  for (Index d : {1, 2, 3, 5, 8, 15, 16, 17, 31, 33, 63, 64, 65, 100, 130})
    for (int kind = 0; kind < 4; ++kind) {
      // N below, at and past a panel (8 to 32 columns by target) and a tile; tiles of one panel and of several
      const Index n = std::array<Index, 5>{2, 9, 37, 100, 263}[static_cast<std::size_t>(rng() % 5)];
      const Index tile = std::array<Index, 3>{1, 40, 256}[static_cast<std::size_t>(rng() % 3)];
      const Index k = std::min<Index>(n - 1, std::array<Index, 3>{1, 5, 20}[static_cast<std::size_t>(rng() % 3)]);
      fused_case<float>(rng, n, d, k, kind, {tile, 64, 8}, true);
      fused_case<float>(rng, n, d, n - 1, kind, {tile, 64, 8}, true);  // every other point
      fused_case<float>(rng, n, d, std::min<Index>(n, 4), kind, {tile, 64, 8}, false);
      fused_case<double>(rng, n, d, k, kind, {tile, 64, 8}, true);
      cases += 4;
    }
  CHECK(cases == 15 * 4 * 4);
}

TEST_CASE("BruteForceKnn's fused kernel: many tiles, seq == omp bitwise and the blocked-GEMM kernel's graph") {
  std::mt19937 rng(23);
  for (int kind : {0, 1, 3}) {
    const auto P = test::random_points<Features<float>>(1500, 64, kind, rng);
    BruteForceKnn<float> fused(P, {64, 1024, 8});
    BruteForceKnn<float, neighbors::SelfKernel::blocked_gemm> gemm(P, {64, 1024, 8});
    KnnResult<float> seq, omp, ref;
    fused.query_self_into(exec::seq, 5, seq);
    fused.query_self_into(exec::omp, 5, omp);
    gemm.query_self_into(exec::seq, 5, ref);
    CHECK(omp.indices == seq.indices);
    CHECK(omp.distances == seq.distances);
    check_same_up_to_ties(seq, ref, "1500×64 kind " + std::to_string(kind));
    // the workers' thresholds kept apart (share_thresholds = false): the same graph
    BruteForceKnn<float> unshared(P, {64, 1024, 8, false});
    KnnResult<float> apart;
    unshared.query_self_into(exec::omp, 5, apart);
    CHECK(apart.indices == seq.indices);
    CHECK(apart.distances == seq.distances);
  }
}

TEST_CASE("BruteForceKnn rejects features whose squared norm overflows (the distances would select nothing)") {
  Features<float> P = Features<float>::Random(40, 8);
  P(17, 3) = 3e19f;  // finite, but its square is not
  CHECK_THROWS_WITH_AS(BruteForceKnn<float>{P}, doctest::Contains("points row 17 has a squared norm that overflows float"), ArgumentError);
  CHECK_THROWS_AS((BruteForceKnn<float, neighbors::SelfKernel::blocked_gemm>{P}), ArgumentError);
  BruteForceKnn<float> knn;
  CHECK_THROWS_AS(knn.build(P), ArgumentError);
  CHECK(knn.size() == 0);  // nothing half-built
  P(17, 3) = 3e9f;
  CHECK_NOTHROW(knn.build(P));
  CHECK(knn.query_self(exec::seq, 3).indices.rows() == 40);
}
