#include <simsr/physics/forces/self_contact.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "../support/error_of.hpp"
#include "forces_checks.hpp"

using namespace simsr;
using namespace simsr::physics;

namespace {

/// Two parallel n×n grids of spacing s (z = 0 and z = gap), 2 triangles per square; vertex ids
/// 0..n²−1 bottom, n²..2n²−1 top.
struct Sheets {
  Points<> x;
  Tris bottom, top;
  IndexVector bottom_vertices, top_vertices;
};

Sheets two_sheets(int n, double s, double gap) {
  Sheets m;
  m.x.resize(2 * n * n, 3);
  m.bottom.resize(2 * (n - 1) * (n - 1), 3);
  m.top.resize(2 * (n - 1) * (n - 1), 3);
  m.bottom_vertices.resize(n * n);
  m.top_vertices.resize(n * n);
  for (int l = 0; l < 2; ++l)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) m.x.row(l * n * n + j * n + i) << i * s, j * s, l * gap;
  for (int v = 0; v < n * n; ++v) m.bottom_vertices[v] = v, m.top_vertices[v] = n * n + v;
  int f = 0;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i, f += 2) {
      const VIndex a = j * n + i, b = a + 1, c = a + n, d = c + 1;
      m.bottom.row(f) << a, b, d;
      m.bottom.row(f + 1) << a, d, c;
      m.top.row(f) << a + n * n, d + n * n, b + n * n;
      m.top.row(f + 1) << a + n * n, c + n * n, d + n * n;
    }
  return m;
}

/// Brute-force O(V·T) active pairs, with the same exclusions.
std::set<std::pair<VIndex, Index>> brute_pairs(const Points<>& x, const IndexVector& v, const Tris& F, double dhat, bool adjacent) {
  std::set<std::pair<VIndex, VIndex>> edges;
  for (Index t = 0; t < F.rows(); ++t)
    for (int i = 0; i < 3; ++i) edges.insert({F(t, i), F(t, (i + 1) % 3)}), edges.insert({F(t, (i + 1) % 3), F(t, i)});
  std::set<std::pair<VIndex, Index>> out;
  for (Index i = 0; i < v.size(); ++i)
    for (Index t = 0; t < F.rows(); ++t) {
      bool skip = false;
      for (int c = 0; c < 3; ++c) skip = skip || F(t, c) == v[i] || (adjacent && edges.count({F(t, c), v[i]}));
      if (skip) continue;
      const Vec3<> p = x.row(v[i]).transpose(), a = x.row(F(t, 0)).transpose(), b = x.row(F(t, 1)).transpose(), c = x.row(F(t, 2)).transpose();
      const Vec3<> beta = closest_point_barycentric(p, a, b, c);
      if ((p - (beta[0] * a + beta[1] * b + beta[2] * c)).norm() < dhat) out.insert({v[i], t});
    }
  return out;
}

std::set<std::pair<VIndex, Index>> hashed_pairs(const SelfContact<>& c, const Points<>& x) {
  std::set<std::pair<VIndex, Index>> out;
  for (const auto& p : c.pairs(x)) CHECK(out.insert({p.vertex, p.triangle}).second);  // each pair once
  return out;
}

}  // namespace

TEST_CASE("SelfContact: a vertex hovering over a triangle's interior") {
  Points<> x(4, 3);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 0.003;
  Tris F(1, 3);
  F << 0, 1, 2;
  const double k = 1e3, dhat = 0.01, h = 0.003;
  const SelfContact<> c(IndexVector::Constant(1, 3), F, 4, k, dhat);
  const auto pairs = c.pairs(x);
  REQUIRE(pairs.size() == 1);
  CHECK(pairs[0].distance == doctest::Approx(h));
  CHECK((pairs[0].barycentric - Vec3<>(0.6, 0.2, 0.2)).norm() < 1e-14);
  CHECK(c.energy(exec::seq, x) == doctest::Approx(k / 2 * (dhat - h) * (dhat - h)));
  const Points<> g = test::gradient(c, x);
  CHECK((g.row(3) - Eigen::RowVector3d(0, 0, -k * (dhat - h))).norm() < 1e-12);  // force k(d̂−h) along +n
  CHECK((g.row(0) - Eigen::RowVector3d(0, 0, 0.6 * k * (dhat - h))).norm() < 1e-12);
  CHECK(g.colwise().sum().norm() < 1e-12);  // internal force: momentum conserved
  // in the face region the vertex's own block is exact: k n nᵀ
  const Eigen::MatrixXd H = test::assembled_hessian(c, x), Hfd = test::fd_hessian(c, x, 1e-7);
  CHECK((H.block<3, 3>(9, 9) - Hfd.block<3, 3>(9, 9)).cwiseAbs().maxCoeff() < 1e-5 * k);
  CHECK(H(11, 11) == doctest::Approx(k));
  // above d̂: nothing
  x(3, 2) = 0.0101;
  CHECK(c.pairs(x).empty());
  CHECK(c.energy(exec::seq, x) == 0.0);
}

TEST_CASE("closest_point_barycentric: all 7 regions agree with dense sampling of the triangle") {
  std::mt19937 rng(8);
  const int N = 300;
  double worst = 0;
  int regions[3] = {0, 0, 0};  // face, edge, vertex (by the number of non-zero weights)
  for (int trial = 0; trial < 150; ++trial) {
    const Points<> T = test::random_points(3, -1, 1, rng);
    const Vec3<> a = T.row(0).transpose(), b = T.row(1).transpose(), c = T.row(2).transpose();
    const Vec3<> p = test::random_points(1, -2, 2, rng).row(0).transpose();
    const Vec3<> beta = closest_point_barycentric(p, a, b, c);
    CHECK(beta.minCoeff() >= 0.0);
    CHECK(beta.sum() == doctest::Approx(1.0));
    ++regions[(beta.array() > 0).count() == 3 ? 0 : (beta.array() > 0).count() == 2 ? 1 : 2];
    const double d = (p - (beta[0] * a + beta[1] * b + beta[2] * c)).norm();
    double best = INFINITY;
    for (int i = 0; i <= N; ++i)
      for (int j = 0; i + j <= N; ++j) best = std::min(best, (p - (a + (b - a) * (double(i) / N) + (c - a) * (double(j) / N))).norm());
    const double spacing = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()}) / N;
    CHECK(d <= best + 1e-12);         // it is the minimum...
    CHECK(best - d <= spacing);       // ...which the sampling approaches
    worst = std::max(worst, (best - d) / spacing);
  }
  MESSAGE("closest point: face/edge/vertex regions hit " << regions[0] << "/" << regions[1] << "/" << regions[2]
                                                         << ", worst sampling gap " << worst << " sample spacings");
  CHECK(regions[0] > 5);
  CHECK(regions[1] > 5);
  CHECK(regions[2] > 5);
}

TEST_CASE("SelfContact: the spatial hash finds exactly the brute-force pairs") {
  std::mt19937 rng(99);
  Index total = 0;
  for (int trial = 0; trial < 24; ++trial) {
    const Index nv = 300;
    Points<> x = test::random_points(nv, 0, 1, rng);
    // half small local triangles (3 fresh vertices around a centre), half random triples
    std::vector<std::array<VIndex, 3>> tris;
    std::uniform_int_distribution<VIndex> pick(0, VIndex(nv - 1));
    for (VIndex t = 0; t + 3 <= 150; t += 3) {
      x.middleRows(t + 1, 2) = x.row(t).replicate(2, 1) + test::random_points(2, -0.1, 0.1, rng);
      tris.push_back({t, VIndex(t + 1), VIndex(t + 2)});
    }
    for (int t = 0; t < 20; ++t) {
      VIndex a = pick(rng), b = pick(rng), c = pick(rng);
      if (a != b && b != c && a != c) tris.push_back({a, b, c});
    }
    Tris F(Index(tris.size()), 3);
    for (Index t = 0; t < F.rows(); ++t) F.row(t) << tris[t][0], tris[t][1], tris[t][2];
    IndexVector v(nv / 2);
    for (Index i = 0; i < v.size(); ++i) v[i] = VIndex(2 * i);  // includes triangle corners
    const double dhat = trial % 3 == 0 ? 0.02 : 0.08;
    SelfContactOptions opt;
    opt.exclude_adjacent = trial % 2 == 0;
    opt.cell_size = trial % 4 == 1 ? 0.01 : trial % 4 == 3 ? 0.3 : 0.0;  // smaller than d̂, larger, auto
    const SelfContact<> c(v, F, nv, 10.0, dhat, opt);
    const auto hashed = hashed_pairs(c, x), brute = brute_pairs(x, v, F, dhat, opt.exclude_adjacent);
    CHECK(hashed == brute);
    total += Index(brute.size());
    for (const auto& [vv, t] : hashed)
      for (int k = 0; k < 3; ++k) CHECK(F(t, k) != vv);  // corners excluded
  }
  MESSAGE("spatial hash: " << total << " pairs over 24 clouds, all equal to brute force");
  CHECK(total > 200);
}

TEST_CASE("SelfContact: corner and edge-neighbour exclusion") {
  // a fan of two triangles sharing edge (0, 2); vertex 3 shares an edge with corners 0 and 2 of triangle 0
  Points<> x(4, 3);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, -0.05, 0.5, 0.0;
  Tris F(2, 3);
  F << 0, 1, 2, 0, 2, 3;
  IndexVector v(4);
  v << 0, 1, 2, 3;
  SelfContactOptions keep;
  keep.exclude_adjacent = false;
  const SelfContact<> excl(v, F, 4, 1.0, 0.1), incl(v, F, 4, 1.0, 0.1, keep);
  CHECK(excl.pairs(x).empty());
  const auto p = incl.pairs(x);
  REQUIRE(p.size() == 1);  // vertex 3, 0.05 from triangle 0's edge (0, 2), which it shares edges with
  CHECK(p[0].vertex == 3);
  CHECK(p[0].triangle == 0);
  CHECK(p[0].distance == doctest::Approx(0.05));
  CHECK((p[0].barycentric - Vec3<>(0.5, 0, 0.5)).norm() < 1e-14);
}

TEST_CASE("SelfContact: gradient matches finite differences, Gauss–Newton Hessian is PSD") {
  std::mt19937 rng(17);
  double worst_g = 0, min_eig = 0;
  Index active = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Sheets m = two_sheets(4, 0.1, 0.03);
    m.x += test::random_points(m.x.rows(), -0.02, 0.02, rng);
    const double dhat = 0.05;
    const bool lips = trial % 2 == 0;  // two lips against each other, or one sheet against itself
    const Tris F = lips ? m.bottom : m.top;
    const IndexVector& v = m.top_vertices;
    const SelfContact<> c(v, F, m.x.rows(), 50.0, dhat);
    active += Index(c.pairs(m.x).size());
    worst_g = std::max(worst_g, test::rel_error(test::gradient(c, m.x), test::fd_gradient(c, m.x, 1e-7)));
    const Eigen::MatrixXd H = test::assembled_hessian(c, m.x);
    min_eig = std::min(min_eig, test::min_eigenvalue(H) / std::max(1.0, H.cwiseAbs().maxCoeff()));
  }
  MESSAGE("self contact: worst gradient error " << worst_g << ", min eigenvalue " << min_eig << ", active pairs " << active);
  CHECK(active > 100);
  CHECK(worst_g < 1e-6);
  CHECK(min_eig > -1e-12);
}

TEST_CASE("SelfContact: one thickness per vertex: each vertex's pairs by its own d̂ (brute force), FD gradient, PSD Hessian") {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> thick(0.005, 0.06);
  double worst_g = 0, min_eig = 0;
  Index active = 0, only_by_own = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Sheets m = two_sheets(5, 0.1, 0.03);
    m.x += test::random_points(m.x.rows(), -0.02, 0.02, rng);
    const IndexVector& v = m.top_vertices;
    VecX<> dhat(v.size());
    for (Index i = 0; i < v.size(); ++i) dhat[i] = thick(rng);
    const SelfContact<> c(v, m.bottom, m.x.rows(), 50.0, dhat);
    CHECK(c.thickness() == dhat.maxCoeff());
    // brute force, vertex by vertex with its own d̂
    std::set<std::pair<VIndex, Index>> brute;
    for (Index i = 0; i < v.size(); ++i) {
      const IndexVector one = IndexVector::Constant(1, v[i]);
      for (const auto& p : brute_pairs(m.x, one, m.bottom, dhat[i], true)) brute.insert(p);
      only_by_own += Index(brute_pairs(m.x, one, m.bottom, dhat.maxCoeff(), true).size()) - Index(brute_pairs(m.x, one, m.bottom, dhat[i], true).size());
    }
    CHECK(hashed_pairs(c, m.x) == brute);
    for (const auto& p : c.pairs(m.x)) {
      const Index i = Index(std::find(v.data(), v.data() + v.size(), p.vertex) - v.data());
      CHECK(p.thickness == dhat[i]);
      CHECK(p.distance < dhat[i]);
    }
    active += Index(brute.size());
    worst_g = std::max(worst_g, test::rel_error(test::gradient(c, m.x), test::fd_gradient(c, m.x, 1e-7)));
    const Eigen::MatrixXd H = test::assembled_hessian(c, m.x);
    min_eig = std::min(min_eig, test::min_eigenvalue(H) / std::max(1.0, H.cwiseAbs().maxCoeff()));
  }
  MESSAGE("per-vertex thickness: " << active << " active pairs, " << only_by_own << " more with the largest d̂ for all; worst gradient error " << worst_g
                                   << ", min eigenvalue " << min_eig);
  CHECK(active > 50);
  CHECK(only_by_own > 20);  // the per-vertex thicknesses decide
  CHECK(worst_g < 1e-6);
  CHECK(min_eig > -1e-12);
  // equal thicknesses are the uniform contact, to the bit
  Sheets m = two_sheets(4, 0.1, 0.02);
  m.x += test::random_points(m.x.rows(), -0.01, 0.01, rng);
  const SelfContact<> uniform(m.top_vertices, m.bottom, m.x.rows(), 50.0, 0.04), each(m.top_vertices, m.bottom, m.x.rows(), 50.0, VecX<>::Constant(m.top_vertices.size(), 0.04));
  CHECK(uniform.energy(exec::seq, m.x) > 0);
  CHECK(uniform.energy(exec::seq, m.x) == each.energy(exec::seq, m.x));
  CHECK(test::gradient(uniform, m.x) == test::gradient(each, m.x));
}

TEST_CASE("SelfContact: bad input throws typed errors") {
  Tris F(1, 3);
  F << 0, 1, 2;
  const IndexVector v = IndexVector::Constant(1, 3);
  CHECK_THROWS_AS(SelfContact<>(v, F, 3, 1.0, 0.1), ArgumentError);  // vertex 3 of 3
  Tris G = F;
  G(0, 2) = -1;
  CHECK_THROWS_AS(SelfContact<>(v, G, 4, 1.0, 0.1), ArgumentError);
  CHECK_THROWS_AS(SelfContact<>(v, F, 4, -1.0, 0.1), ArgumentError);
  CHECK_THROWS_AS(SelfContact<>(v, F, 4, 1.0, 0.0), ArgumentError);
  CHECK_THROWS_AS(SelfContact<>(v, F, 4, 1.0, std::nan("")), ArgumentError);
  CHECK_THROWS_AS(SelfContact<>(v, F, 4, 1.0, VecX<>::Constant(2, 0.1)), ShapeError);  // 2 thicknesses, 1 vertex
  CHECK_THROWS_AS(SelfContact<>(v, F, 4, 1.0, VecX<>::Constant(1, 0.0)), ArgumentError);
  CHECK_THROWS_AS(SelfContact<>(v, F, 4, 1.0, VecX<>::Constant(1, std::nan(""))), ArgumentError);
  CHECK(test::error_of([&] { SelfContact<>(v, F, 4, 1.0, VecX<>::Constant(1, -1.0)); }).find("vertex 3") != std::string::npos);
  SelfContactOptions opt;
  opt.cell_size = -1;
  CHECK_THROWS_AS(SelfContact<>(v, F, 4, 1.0, 0.1, opt), ArgumentError);
  const SelfContact<> c(v, F, 4, 1.0, 0.1);
  CHECK_THROWS_AS(c.energy(exec::seq, Points<>::Zero(3, 3)), ShapeError);
  CHECK_THROWS_AS(c.pairs(Points<>::Zero(5, 3)), ShapeError);
  // a wild configuration does not hang or throw: a far-away corner makes the triangle span many cells
  Points<> x(4, 3);
  x << 0, 0, 0, 1e9, 0, 0, 0, 1e9, 1e9, 0.1, 0.1, 0.01;
  CHECK_NOTHROW(c.energy(exec::seq, x));
}
