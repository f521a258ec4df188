#include <doctest/doctest.h>

#include <simsr/discretize/bcc_lattice.hpp>
#include <simsr/io/npy.hpp>
#include <simsr/io/obj.hpp>
#include <simsr/mesh/generators.hpp>
#include <simsr/neighbors/linear_assignment.hpp>
#include <simsr/neighbors/upsampling_neighborhoods.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>
#include <set>

using namespace simsr;
using namespace simsr::neighbors;

namespace {

/// The library's ellipsoid surface (exactly nv vertices) as separate V, F.
void ellipsoid(Index nv, double a, double b, double c, Points<>& V, Tris& F) {
  auto m = ellipsoid_surface(nv, a, b, c);
  V = std::move(m.V);
  F = std::move(m.F);
}

/// Exactly `count` BCC lattice nodes inside 0.97 × the ellipsoid, innermost kept.
Points<> bcc_inside(Index count, double a, double b, double c) {
  return discretize::bcc_points_inside(ellipsoid_surface(2000, 0.97 * a, 0.97 * b, 0.97 * c), count);
}

/// k nearest sources by running one Dijkstra per source (the reference), ties by source id.
GeodesicSources reference_sources(const Points<>& V, const Tris& F, const IndexVector& src, Index k) {
  const auto g = neighbors::surface_edge_graph(V, F);
  std::vector<std::vector<double>> D;
  for (Index s = 0; s < src.size(); ++s) D.push_back(neighbors::detail::dijkstra(g, src[s]));
  GeodesicSources r;
  r.indices.resize(V.rows(), k);
  r.distances.resize(V.rows(), k);
  for (Index v = 0; v < V.rows(); ++v) {
    std::vector<std::pair<double, VIndex>> all;
    for (Index s = 0; s < src.size(); ++s) all.push_back({D[s][v], VIndex(s)});
    std::sort(all.begin(), all.end());
    for (Index c = 0; c < k; ++c) r.indices(v, c) = all[c].second, r.distances(v, c) = all[c].first;
  }
  return r;
}

/// Regular n×n grid of unit squares in the plane, each split into two triangles (many exact ties).
void grid(Index n, Points<>& V, Tris& F) {
  V.resize(n * n, 3);
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < n; ++j) V.row(i * n + j) << double(i), double(j), 0;
  F.resize(2 * (n - 1) * (n - 1), 3);
  Index f = 0;
  for (Index i = 0; i + 1 < n; ++i)
    for (Index j = 0; j + 1 < n; ++j) {
      const VIndex a = VIndex(i * n + j), b = a + 1, c = VIndex(a + n), d = c + 1;
      F.row(f++) << a, c, d;
      F.row(f++) << a, d, b;
    }
}

Index overlap(const Eigen::Ref<const Eigen::Matrix<std::int64_t, 1, Eigen::Dynamic>>& a,
              const Eigen::Ref<const Eigen::Matrix<VIndex, 1, Eigen::Dynamic>>& b) {
  std::set<std::int64_t> s(a.data(), a.data() + a.size());
  Index o = 0;
  for (Index i = 0; i < b.size(); ++i) o += s.count(b[i]);
  return o;
}

}  // namespace

TEST_CASE("ellipsoid fixture: closed surface with the requested vertex count") {
  Points<> V;
  Tris F;
  for (const Index nv : {8, 50, 641, 3001}) {
    ellipsoid(nv, 1.0, 0.8, 0.6, V, F);
    CHECK(V.rows() == nv);
    CHECK(F.rows() == 2 * nv - 4);                   // Euler: closed sphere
    CHECK(unique_edges(F).rows() == 3 * nv - 6);     // every edge in two triangles
    CHECK(connected_components(F, nv).count == 1);
  }
  CHECK(bcc_inside(300, 1, 0.8, 0.6).rows() == 300);
}

TEST_CASE("k-label Dijkstra equals one Dijkstra per source, bit for bit, ties by source id") {
  std::mt19937 rng(1);
  Points<> V;
  Tris F;
  SUBCASE("ellipsoid") { ellipsoid(400, 1.0, 0.7, 0.5, V, F); }
  SUBCASE("grid with exact ties") { grid(15, V, F); }
  SUBCASE("random heights") {
    grid(13, V, F);
    std::uniform_real_distribution<double> u(-0.7, 0.7);
    for (Index i = 0; i < V.rows(); ++i) V(i, 2) = u(rng);
  }
  for (const Index ns : {1, 7, 60}) {
    std::vector<VIndex> all(static_cast<std::size_t>(V.rows()));
    std::iota(all.begin(), all.end(), 0);
    std::shuffle(all.begin(), all.end(), rng);
    IndexVector src(ns);
    for (Index s = 0; s < ns; ++s) src[s] = all[s];
    if (ns == 60) src[59] = src[3];  // two sources on one vertex are still two sources
    for (const Index k : {Index(1), std::min<Index>(5, ns), ns}) {
      CAPTURE(ns);
      CAPTURE(k);
      const auto got = geodesic_k_nearest_sources(V, F, src, k);
      const auto want = reference_sources(V, F, src, k);
      CHECK(got.indices == want.indices);
      CHECK(got.distances == want.distances);  // exact, not approximate
    }
  }
}

TEST_CASE("geodesic_k_nearest_sources: errors") {
  Points<> V;
  Tris F;
  grid(4, V, F);
  IndexVector src(3);
  src << 0, 5, 15;
  CHECK_THROWS_AS(geodesic_k_nearest_sources(V, F, src, 4), ArgumentError);
  CHECK_THROWS_AS(geodesic_k_nearest_sources(V, F, src, 0), ArgumentError);
  src[1] = 16;
  CHECK_THROWS_WITH_AS(geodesic_k_nearest_sources(V, F, src, 2), doctest::Contains("source 1 at vertex 16"), ArgumentError);
  // Two separate grids; the second holds only one source, so its vertices reach 1 of k = 2.
  Points<> V2(2 * V.rows(), 3);
  V2 << V, V.array() + 10.0;
  Tris F2(2 * F.rows(), 3);
  F2 << F, F.array() + VIndex(V.rows());
  IndexVector s2(3);
  s2 << 0, 1, 20;
  CHECK_THROWS_WITH_AS(geodesic_k_nearest_sources(V2, F2, s2, 2), doctest::Contains("reaches only 1"), MeshError);
  CHECK_THROWS_AS(geodesic_k_nearest_sources(Eigen::MatrixXd::Zero(3, 2), F, src, 1), ShapeError);
}

TEST_CASE("upsampling_neighborhoods: lattice inside an ellipsoid; seq == omp; save/load round trip") {
  Points<> V;
  Tris F;
  ellipsoid(1500, 1.0, 0.8, 0.6, V, F);
  const Points<> L = bcc_inside(600, 1.0, 0.8, 0.6);
  UpsamplingOptions opt;
  opt.assignment.k = 4;
  const auto nb = upsampling_neighborhoods(exec::seq, L, V, F, opt);
  const auto nbo = upsampling_neighborhoods(exec::omp, L, V, F, opt);
  CHECK(nb.indices == nbo.indices);
  CHECK(nb.distances == nbo.distances);
  CHECK(nb.lr_to_hr == nbo.lr_to_hr);
  REQUIRE(nb.k() == 20);
  REQUIRE(nb.indices.rows() == V.rows());
  CHECK(nb.assignment_globally_optimal);
  CHECK_FALSE(nb.log.empty());

  Eigen::MatrixXd C(L.rows(), V.rows());
  for (Index i = 0; i < C.rows(); ++i)
    for (Index j = 0; j < C.cols(); ++j) C(i, j) = neighbors::detail::assignment_distance(L, i, V, j);
  CHECK(nb.assignment_cost == linear_assignment(C).total_cost);

  for (Index i = 0; i < L.rows(); ++i) {  // a mapped vertex's nearest LR vertex is its own
    CHECK(nb.indices(nb.lr_to_hr[i], 0) == i);
    CHECK(nb.distances(nb.lr_to_hr[i], 0) == 0.0);
  }
  for (Index j = 0; j < V.rows(); ++j)
    for (Index c = 1; c < nb.k(); ++c) REQUIRE(nb.distances(j, c - 1) <= nb.distances(j, c));

  const auto dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "neighbors";
  std::filesystem::create_directories(dir);
  save_upsampling_neighborhoods(dir / "nb.npz", nb);
  const auto back = load_upsampling_neighborhoods(dir / "nb.npz");
  CHECK(back.indices == nb.indices);
  CHECK(back.distances == nb.distances);
  CHECK(back.lr_to_hr == nb.lr_to_hr);
  CHECK(back.assignment_cost == nb.assignment_cost);
  CHECK(back.assignment_globally_optimal);

  auto broken = nb;
  broken.indices(3, 2) = VIndex(L.rows());
  save_upsampling_neighborhoods(dir / "broken.npz", broken);
  CHECK_THROWS_WITH_AS(load_upsampling_neighborhoods(dir / "broken.npz"), doctest::Contains("outside [0, 600)"), ArgumentError);
  CHECK_THROWS_AS(load_upsampling_neighborhoods(dir / "missing.npz"), ParseError);
}

TEST_CASE("bunny: against the authors' precomputed geo_dist_surf2tet neighbourhoods") {
  const std::filesystem::path data = std::filesystem::path(SIMSR_DATA_DIR) / "bunny";
  const auto lr = io::read_obj_tets((data / "lrestshape.obj").string());
  const auto hr = io::read_obj_triangles((data / "hrestshape.obj").string());
  REQUIRE(lr.V.rows() == 1747);
  REQUIRE(hr.V.rows() == 2503);
  const auto D = io::read_npy(data / "geo_dist_surf2tet.npy").to_matrix<double>();
  const auto I = io::read_npy(data / "geo_dist_surf2tet_idx.npy").to_matrix<std::int64_t>();
  REQUIRE(D.rows() == 2503);

  const auto nb = upsampling_neighborhoods(exec::omp, lr.V, hr.V, hr.F);
  CHECK(nb.assignment_globally_optimal);

  // The authors' mapping is encoded in their files: the HR vertices at distance 0 (1,747 of them,
  // one per LR vertex).
  IndexVector theirs = IndexVector::Constant(1747, -1);
  for (Index j = 0; j < D.rows(); ++j)
    if (D(j, 0) == 0.0) theirs[I(j, 0)] = VIndex(j);
  REQUIRE((theirs.array() >= 0).all());
  double their_cost = 0;
  Index same = 0;
  for (Index i = 0; i < 1747; ++i) {
    their_cost += neighbors::detail::assignment_distance(lr.V, i, hr.V, theirs[i]);
    same += theirs[i] == nb.lr_to_hr[i];
  }
  MESSAGE("assignment cost: ours " << nb.assignment_cost << " (proven optimal), authors' " << their_cost << "; "
                                   << same << " of 1747 LR vertices mapped alike");
  CHECK(nb.assignment_cost < their_cost);  // theirs is not the Euclidean optimum on these rest shapes
  CHECK(same > 900);

  const auto with_theirs = geodesic_k_nearest_sources(hr.V, hr.F, theirs, 20);
  for (const Index k : {10, 20}) {
    Index ours = 0, same_map = 0;
    double dd = 0;
    for (Index j = 0; j < D.rows(); ++j) {
      ours += overlap(I.row(j).head(k), nb.indices.row(j).head(k));
      same_map += overlap(I.row(j).head(k), with_theirs.indices.row(j).head(k));
      dd = std::max(dd, (D.row(j).head(k) - with_theirs.distances.row(j).head(k)).cwiseAbs().maxCoeff());
    }
    const double f_ours = double(ours) / double(D.rows() * k), f_same = double(same_map) / double(D.rows() * k);
    MESSAGE("k = " << k << ": neighbour overlap " << f_ours << " (our mapping), " << f_same
                   << " (their mapping); max |distance difference| with their mapping " << dd);
    CHECK(f_ours > 0.75);
    CHECK(f_same > 0.93);
    CHECK(dd < 0.01);  // distances reach 0.05; see the report for why they differ at all
  }
}
