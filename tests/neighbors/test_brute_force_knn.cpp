#include <simsr/neighbors/brute_force_knn.hpp>
#include <simsr/neighbors/concepts.hpp>
#include <simsr/neighbors/kd_tree.hpp>

#include <doctest/doctest.h>

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
