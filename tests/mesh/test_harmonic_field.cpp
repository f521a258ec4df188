#include <doctest/doctest.h>

#include <simsr/mesh/harmonic_field.hpp>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>

#include "fixtures.hpp"

namespace mesh_test_harmonic_field {

using namespace simsr;
using namespace simsr::test;

namespace {

/// The path 0 − 1 − … − (n−1) as 2-vertex elements.
Edges path_edges(Index n) {
  Edges E(n - 1, 2);
  for (Index i = 0; i + 1 < n; ++i) E.row(i) << VIndex(i), VIndex(i + 1);
  return E;
}

/// The harmonic field by a dense solve of the full Laplace system with the fixed rows replaced
/// by identity rows (the brute-force reference; unreachable vertices given by the caller).
VecX<> dense_harmonic(const Adjacency& A, const IndexVector& fixed, const VecX<>& values, const std::vector<char>& reached, double unreachable) {
  const Index n = A.num_vertices();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
  VecX<> b = VecX<>::Zero(n);
  std::vector<char> is_fixed(std::size_t(n), 0);
  for (Index k = 0; k < fixed.size(); ++k) {
    is_fixed[std::size_t(fixed[k])] = 1;
    K(fixed[k], fixed[k]) = 1;
    b[fixed[k]] = values[k];
  }
  for (Index v = 0; v < n; ++v) {
    if (is_fixed[std::size_t(v)]) continue;
    if (!reached[std::size_t(v)]) {
      K(v, v) = 1;
      b[v] = unreachable;
      continue;
    }
    K(v, v) = double(A.degree(v));
    for (const VIndex u : A[v]) K(v, u) -= 1;
  }
  return K.fullPivLu().solve(b);
}

}  // namespace

TEST_CASE("harmonic_field: linear along a path between two fixed ends (analytic)") {
  const Index n = 57;
  const Adjacency A = vertex_adjacency(path_edges(n), n);
  IndexVector fixed(2);
  fixed << 0, n - 1;
  VecX<> values(2);
  values << -2.0, 5.0;
  const VecX<> w = harmonic_field(exec::seq, A, fixed, values);
  for (Index i = 0; i < n; ++i) CHECK(w[i] == doctest::Approx(-2.0 + 7.0 * double(i) / double(n - 1)).epsilon(1e-9));
}

TEST_CASE("harmonic_field: random tet meshes and boundary sets against a dense solve; mean-value and maximum principles; seq == omp") {
  std::mt19937 rng(20261125);
  for (int trial = 0; trial < 40; ++trial) {
    std::uniform_int_distribution<int> size(1, 4);
    TetMesh<> m = box_tets(size(rng), size(rng), size(rng));
    // a second box far away, sometimes with no fixed vertex: its vertices are unreachable
    const TetMesh<> other = box_tets(2, 1, 1, 1.0, Vec3<>(10, 0, 0));
    const Index n0 = m.num_vertices();
    TetMesh<> both{Points<>(n0 + other.num_vertices(), 3), Tets(m.num_tets() + other.num_tets(), 4)};
    both.V << m.V, other.V;
    both.T << m.T, (other.T.array() + VIndex(n0)).matrix();
    const Index n = both.num_vertices();
    shuffle_vertices(both.V, both.T, rng);
    const Adjacency A = vertex_adjacency(both.T, n);

    std::vector<Index> ids(static_cast<std::size_t>(n));
    std::iota(ids.begin(), ids.end(), Index(0));
    std::shuffle(ids.begin(), ids.end(), rng);
    const Index k = std::uniform_int_distribution<Index>(1, std::max<Index>(1, n / 3))(rng);
    IndexVector fixed(k);
    VecX<> values(k);
    std::uniform_real_distribution<double> val(-3, 3);
    for (Index i = 0; i < k; ++i) {
      fixed[i] = VIndex(ids[std::size_t(i)]);
      values[i] = val(rng);
    }
    const double unreachable = 0.25 * trial;
    const VecX<> w = harmonic_field(exec::seq, A, fixed, values, unreachable, 1e-13);
    CHECK(harmonic_field(exec::omp, A, fixed, values, unreachable, 1e-13) == w);

    // reached: joined to a fixed vertex by a path (flood fill here, independently)
    std::vector<char> reached(std::size_t(n), 0), is_fixed(std::size_t(n), 0);
    for (Index i = 0; i < k; ++i) reached[std::size_t(fixed[i])] = is_fixed[std::size_t(fixed[i])] = 1;
    for (bool grew = true; grew;) {
      grew = false;
      for (Index t = 0; t < both.num_tets(); ++t) {
        bool any = false;
        for (int c = 0; c < 4; ++c) any = any || reached[std::size_t(both.T(t, c))];
        if (any)
          for (int c = 0; c < 4; ++c)
            if (!reached[std::size_t(both.T(t, c))]) reached[std::size_t(both.T(t, c))] = 1, grew = true;
      }
    }
    const VecX<> ref = dense_harmonic(A, fixed, values, reached, unreachable);
    CHECK((w - ref).cwiseAbs().maxCoeff() < 1e-9);
    for (Index i = 0; i < k; ++i) CHECK(w[fixed[i]] == values[i]);  // exact
    const double lo = values.minCoeff(), hi = values.maxCoeff();
    for (Index v = 0; v < n; ++v) {
      if (is_fixed[std::size_t(v)]) continue;
      if (!reached[std::size_t(v)]) {
        CHECK(w[v] == unreachable);
        continue;
      }
      double mean = 0;
      for (const VIndex u : A[v]) mean += w[u];
      mean /= double(A.degree(v));
      CHECK(w[v] == doctest::Approx(mean).epsilon(1e-9).scale(3));
      CHECK(w[v] >= lo - 1e-9);
      CHECK(w[v] <= hi + 1e-9);
    }
  }
}

TEST_CASE("harmonic_field: bad input is refused naming what") {
  const Adjacency A = vertex_adjacency(path_edges(5), 5);
  IndexVector fixed(2);
  fixed << 0, 4;
  CHECK_THROWS_AS(harmonic_field(exec::seq, A, fixed, VecX<>::Ones(3)), ShapeError);
  VecX<> nan = VecX<>::Ones(2);
  nan[1] = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(harmonic_field(exec::seq, A, fixed, nan), ArgumentError);
  CHECK_THROWS_AS(harmonic_field(exec::seq, A, fixed, VecX<>::Ones(2), std::numeric_limits<double>::infinity()), ArgumentError);
  fixed << 0, 5;
  CHECK_THROWS_AS(harmonic_field(exec::seq, A, fixed, VecX<>::Ones(2)), MeshError);
  fixed << 3, 3;
  CHECK_THROWS_AS(harmonic_field(exec::seq, A, fixed, VecX<>::Ones(2)), MeshError);
  // no fixed vertex at all: everything unreachable
  CHECK(harmonic_field(exec::seq, A, IndexVector(0), VecX<>(0), 7.0) == VecX<>::Constant(5, 7.0));
}

}  // namespace mesh_test_harmonic_field
