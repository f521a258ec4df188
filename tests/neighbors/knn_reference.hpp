#pragma once
/// \file
/// Independent references for the neighbour tests: plain-loop brute force in long double, and a
/// row-by-row comparison that tolerates only genuine near-ties.

#include <simsr/neighbors/knn_result.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace simsr::test {


/// Exhaustive distances from every row of Q to every row of P (any dimension) in long double:
/// `dist[i][j]` (−1 for j = i when `exclude_self`), and `order[i]`, the `keep` closest indices by
/// (distance, index).
struct Reference {
  std::vector<std::vector<long double>> dist;
  std::vector<std::vector<VIndex>> order;
};

template <class MQ, class MP>
Reference reference_knn(const MQ& Q, const MP& P, Index keep, bool exclude_self = false) {
  Reference ref;
  ref.dist.resize(static_cast<std::size_t>(Q.rows()));
  ref.order.resize(static_cast<std::size_t>(Q.rows()));
  for (Index i = 0; i < Q.rows(); ++i) {
    auto& d = ref.dist[static_cast<std::size_t>(i)];
    auto& o = ref.order[static_cast<std::size_t>(i)];
    d.assign(static_cast<std::size_t>(P.rows()), -1);
    for (Index j = 0; j < P.rows(); ++j) {
      if (exclude_self && i == j) continue;
      long double s = 0;
      for (Index c = 0; c < P.cols(); ++c) {
        const long double diff = static_cast<long double>(Q(i, c)) - static_cast<long double>(P(j, c));
        s += diff * diff;
      }
      d[static_cast<std::size_t>(j)] = std::sqrt(s);
      o.push_back(static_cast<VIndex>(j));
    }
    const auto m = std::min<std::size_t>(o.size(), static_cast<std::size_t>(keep));
    std::partial_sort(o.begin(), o.begin() + static_cast<std::ptrdiff_t>(m), o.end(), [&](VIndex a, VIndex b) {
      return d[static_cast<std::size_t>(a)] < d[static_cast<std::size_t>(b)] || (d[static_cast<std::size_t>(a)] == d[static_cast<std::size_t>(b)] && a < b);
    });
    o.resize(m);
  }
  return ref;
}

/// Checks a kNN result against the reference (built with keep ≥ k + 1): every row ascending,
/// ties by ascending index, distances equal to the reference's rank by rank within `tol`, every
/// reported distance the true distance of its index within `tol`, no index twice, and indices
/// equal to the reference's wherever the reference distance is separated from its neighbours (and
/// from the (k+1)-th) by more than `tol`. Returns the number of rows whose indices differ from the
/// reference anywhere (only near-ties may cause that).
template <class S>
int check_against_reference(const neighbors::KnnResult<S>& r, const Reference& ref, long double tol, const std::string& what) {
  INFO(what);
  REQUIRE(r.queries() == static_cast<Index>(ref.order.size()));
  const Index k = r.k();
  int differing = 0, failures = 0;
  for (Index i = 0; i < r.queries() && failures < 10; ++i) {
    const auto& dist = ref.dist[static_cast<std::size_t>(i)];
    const auto& order = ref.order[static_cast<std::size_t>(i)];
    REQUIRE(order.size() >= static_cast<std::size_t>(k));
    auto rd = [&](Index j) { return dist[static_cast<std::size_t>(order[static_cast<std::size_t>(j)])]; };
    bool differs = false;
    for (Index j = 0; j < k; ++j) {
      const VIndex got = r.indices(i, j);
      const long double gd = static_cast<long double>(r.distances(i, j));
      const bool valid = got >= 0 && static_cast<std::size_t>(got) < dist.size() && dist[static_cast<std::size_t>(got)] >= 0;
      bool ok = valid && std::fabs(gd - rd(j)) <= tol && std::fabs(gd - dist[static_cast<std::size_t>(got)]) <= tol;
      if (j > 0) ok = ok && (r.distances(i, j - 1) < r.distances(i, j) || (r.distances(i, j - 1) == r.distances(i, j) && r.indices(i, j - 1) < got));
      for (Index t = 0; t < j; ++t) ok = ok && r.indices(i, t) != got;
      const bool sep_before = j == 0 || rd(j) - rd(j - 1) > tol;
      const bool sep_after = static_cast<std::size_t>(j + 1) >= order.size() || rd(j + 1) - rd(j) > tol;
      if (sep_before && sep_after) ok = ok && got == order[static_cast<std::size_t>(j)];
      if (got != order[static_cast<std::size_t>(j)]) differs = true;
      if (!ok) {
        ++failures;
        FAIL_CHECK("row " << i << " rank " << j << ": got index " << got << " at " << static_cast<double>(gd) << ", reference index "
                          << order[static_cast<std::size_t>(j)] << " at " << static_cast<double>(rd(j)));
      }
    }
    differing += differs;
  }
  CHECK(failures == 0);
  return differing;
}

/// Random point sets of several kinds (D columns): uniform in a cube, Gaussian clusters, a lattice
/// (many exactly equal distances) and sets with exact duplicate points.
template <class M, class Rng>
M random_points(Index n, Index dim, int kind, Rng& rng) {
  M P(n, dim);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> g(0, 0.01);
  switch (kind) {
    case 0:
      for (Index i = 0; i < P.size(); ++i) P.data()[i] = static_cast<typename M::Scalar>(u(rng));
      break;
    case 1: {  // 5 tight clusters
      M centers(5, dim);
      for (Index i = 0; i < centers.size(); ++i) centers.data()[i] = static_cast<typename M::Scalar>(u(rng));
      for (Index i = 0; i < n; ++i)
        for (Index d = 0; d < dim; ++d) P(i, d) = static_cast<typename M::Scalar>(centers(i % 5, d) + g(rng));
      break;
    }
    case 2:  // integer lattice: exact ties everywhere
      for (Index i = 0; i < P.size(); ++i) P.data()[i] = static_cast<typename M::Scalar>(std::uniform_int_distribution<int>(-3, 3)(rng));
      break;
    default: {  // a third of the points repeat earlier ones exactly
      for (Index i = 0; i < P.size(); ++i) P.data()[i] = static_cast<typename M::Scalar>(u(rng));
      for (Index i = 1; i < n; i += 3) P.row(i) = P.row(std::uniform_int_distribution<Index>(0, i - 1)(rng));
    }
  }
  return P;
}

}  // namespace simsr::test
