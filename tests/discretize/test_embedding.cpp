#include <simsr/discretize/embedding.hpp>
#include <simsr/discretize/point_location.hpp>

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "../mesh/fixtures.hpp"

using namespace simsr;

namespace {

using V4 = Eigen::Vector4d;

/// Reference barycentric weights by Cramer's rule: w_i = vol(tet with p in place of v_i) / vol.
V4 ref_weights(const std::array<Eigen::Vector3d, 4>& x, const Eigen::Vector3d& p) {
  auto det = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
    Eigen::Matrix3d M;
    M << b - a, c - a, d - a;
    return M.determinant();
  };
  const double vol = det(x[0], x[1], x[2], x[3]);
  V4 w;
  for (int i = 0; i < 4; ++i) {
    auto y = x;
    y[std::size_t(i)] = p;
    w[i] = det(y[0], y[1], y[2], y[3]) / vol;
  }
  return w;
}

double seg_dist(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

/// Reference point–triangle distance: plane projection if it falls inside (sign tests of the
/// sub-triangle normals), otherwise the nearest of the three edges.
double tri_dist(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  const Eigen::Vector3d q = p - n * n.dot(p - a);
  const bool in = n.dot((b - a).cross(q - a)) >= 0 && n.dot((c - b).cross(q - b)) >= 0 && n.dot((a - c).cross(q - c)) >= 0;
  if (in) return std::abs(n.dot(p - a));
  return std::min({seg_dist(p, a, b), seg_dist(p, b, c), seg_dist(p, c, a)});
}

/// Reference point–tet distance: 0 inside (all Cramer weights ≥ 0), else the nearest face.
double ref_tet_dist(const std::array<Eigen::Vector3d, 4>& x, const Eigen::Vector3d& p) {
  if ((ref_weights(x, p).array() >= 0).all()) return 0;
  return std::min({tri_dist(p, x[1], x[2], x[3]), tri_dist(p, x[0], x[2], x[3]), tri_dist(p, x[0], x[1], x[3]),
                   tri_dist(p, x[0], x[1], x[2])});
}

std::array<Eigen::Vector3d, 4> tet_corners(const TetMesh<>& m, Index t) {
  std::array<Eigen::Vector3d, 4> x;
  for (int k = 0; k < 4; ++k) x[std::size_t(k)] = m.V.row(m.T(t, k)).transpose();
  return x;
}

struct RefHit {
  Index tet;
  V4 w;
  bool inside;
  double distance;
};

/// Brute-force location: the lowest-id tet with all weights ≥ −tol, else the nearest tet by
/// reference distance (lowest id among equal distances up to `tie`).
RefHit brute_force(const TetMesh<>& m, const Eigen::Vector3d& p, double tol) {
  for (Index t = 0; t < m.T.rows(); ++t) {
    const V4 w = ref_weights(tet_corners(m, t), p);
    if ((w.array() >= -tol).all()) return {t, w, true, 0.0};
  }
  Index best = -1;
  double bd = std::numeric_limits<double>::infinity();
  for (Index t = 0; t < m.T.rows(); ++t) {
    const double d = ref_tet_dist(tet_corners(m, t), p);
    if (d < bd) {
      bd = d;
      best = t;
    }
  }
  return {best, ref_weights(tet_corners(m, best), p), false, bd};
}

std::array<Eigen::Vector3d, 4> random_tet(std::mt19937& rng, double min_quality = 0.05) {
  std::uniform_real_distribution<double> u(-1, 1);
  for (;;) {
    std::array<Eigen::Vector3d, 4> x;
    for (auto& v : x) v = Eigen::Vector3d(u(rng), u(rng), u(rng));
    Eigen::Matrix3d M;
    M << x[1] - x[0], x[2] - x[0], x[3] - x[0];
    double l = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) l = std::max(l, (x[std::size_t(i)] - x[std::size_t(j)]).norm());
    if (std::abs(M.determinant()) / 6 > min_quality * l * l * l) return x;
  }
}

TetMesh<> single_tet(const std::array<Eigen::Vector3d, 4>& x) {
  TetMesh<> m;
  m.V.resize(4, 3);
  for (int k = 0; k < 4; ++k) m.V.row(k) = x[std::size_t(k)].transpose();
  m.T.resize(1, 4);
  m.T << 0, 1, 2, 3;
  return m;
}

}  // namespace

TEST_CASE("barycentric weights of random points in random tets reproduce the point; inside iff all weights >= -eps") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const double eps = TetLocatorOptions{}.inside_tolerance;
  int inside = 0, outside = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const auto x = random_tet(rng);
    const TetMesh<> m = single_tet(x);
    const TetLocator<> loc(m);
    for (int i = 0; i < 50; ++i) {
      Eigen::Vector3d p(u(rng), u(rng), u(rng));
      if (i % 2) {  // half near the tet: a random convex combination of its corners, nudged
        V4 c = V4::Random().cwiseAbs();
        c /= c.sum();
        p = c[0] * x[0] + c[1] * x[1] + c[2] * x[2] + c[3] * x[3] + 0.05 * p;
      }
      const V4 w = loc.barycentric(0, p);
      CHECK(std::abs(w.sum() - 1) < 1e-14);
      const Eigen::Vector3d back = w[0] * x[0] + w[1] * x[1] + w[2] * x[2] + w[3] * x[3];
      CHECK((back - p).norm() < 1e-13);
      const V4 r = ref_weights(x, p);
      CHECK((w - r).cwiseAbs().maxCoeff() < 1e-11);
      // Inside by the independent sub-volume signs (skip the measure-zero tolerance band).
      if (r.cwiseAbs().minCoeff() < 1e-9) continue;
      const bool ref_inside = (r.array() > 0).all();
      V4 wl;
      const Index t = loc.locate(p, wl);
      CHECK((t == 0) == ref_inside);
      CHECK(((w.array() >= -eps).all()) == ref_inside);
      ref_inside ? ++inside : ++outside;
    }
  }
  CHECK(inside > 1500);
  CHECK(outside > 3000);
}

TEST_CASE("exact point-tet distance matches a dense sampling of the tet's boundary") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-2.5, 2.5);
  const int n = 120;  // samples per face edge
  for (int trial = 0; trial < 30; ++trial) {
    const auto x = random_tet(rng);
    const TetLocator<> loc(single_tet(x));
    double lmax = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) lmax = std::max(lmax, (x[std::size_t(i)] - x[std::size_t(j)]).norm());
    for (int q = 0; q < 6; ++q) {
      const Eigen::Vector3d p(u(rng), u(rng), u(rng));
      V4 cw;
      const double d = loc.distance(0, p, &cw);
      if (d == 0) {
        CHECK((ref_weights(x, p).array() >= -1e-12).all());
        continue;
      }
      double ds = std::numeric_limits<double>::infinity();
      const int faces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
      for (const auto& f : faces)
        for (int a = 0; a <= n; ++a)
          for (int b = 0; a + b <= n; ++b) {
            const double s = double(a) / n, t = double(b) / n;
            const Eigen::Vector3d y = (1 - s - t) * x[std::size_t(f[0])] + s * x[std::size_t(f[1])] + t * x[std::size_t(f[2])];
            ds = std::min(ds, (p - y).norm());
          }
      CHECK(d <= ds + 1e-12);              // no sample is closer than the exact distance
      CHECK(ds - d <= lmax / n);           // the closest point is within one sample spacing of a sample
      CHECK(std::abs(d - ref_tet_dist(x, p)) < 1e-12);
      // The clamped weights name that closest point.
      CHECK((cw.array() >= 0).all());
      CHECK(std::abs(cw.sum() - 1) < 1e-14);
      const Eigen::Vector3d c = cw[0] * x[0] + cw[1] * x[1] + cw[2] * x[2] + cw[3] * x[3];
      CHECK(std::abs((p - c).norm() - d) < 1e-12);
    }
  }
}

namespace {

/// Compares embed against brute force for every query; returns (#inside, #outside).
std::pair<int, int> compare_with_brute_force(const TetMesh<>& m, const Points<>& Q, const Embedding<>& e) {
  const double tol = TetLocatorOptions{}.inside_tolerance;
  int in = 0, out = 0, tet_mismatch = 0, weight_mismatch = 0, dist_mismatch = 0;
  for (Index q = 0; q < Q.rows(); ++q) {
    const Eigen::Vector3d p = Q.row(q).transpose();
    const RefHit r = brute_force(m, p, tol);
    REQUIRE(e.inside[q] == r.inside);
    if (r.inside) {
      ++in;
      if (e.tet[q] != r.tet) ++tet_mismatch;
      if ((e.weights.row(q).transpose() - r.w).cwiseAbs().maxCoeff() > 1e-11) ++weight_mismatch;
      if (e.distance[q] != 0) ++dist_mismatch;
    } else {
      ++out;
      // Equal distances (shared boundary faces/edges) may round apart: the tet must be one of the nearest.
      const double d_chosen = ref_tet_dist(tet_corners(m, e.tet[q]), p);
      if (d_chosen > r.distance + 1e-12) ++tet_mismatch;
      if (std::abs(e.distance[q] - r.distance) > 1e-12) ++dist_mismatch;
      const V4 w = ref_weights(tet_corners(m, e.tet[q]), p);
      if ((e.weights.row(q).transpose() - w).cwiseAbs().maxCoeff() > 1e-10) ++weight_mismatch;
    }
  }
  CHECK(tet_mismatch == 0);
  CHECK(weight_mismatch == 0);
  CHECK(dist_mismatch == 0);
  return {in, out};
}

}  // namespace

TEST_CASE("embed agrees with brute-force location on box meshes: random, on shared faces/edges/vertices, outside") {
  std::mt19937 rng(3);
  for (bool five : {false, true}) {
    CAPTURE(five);
    // Dyadic spacing: grid vertices, edge and face midpoints are exact in floating point.
    TetMesh<> m = test::box_tets(5, 4, 3, 0.5, Vec3<>(-1.0, -0.75, 0.25), five);
    std::uniform_real_distribution<double> ux(-1.6, 2.1), uy(-1.3, 1.8), uz(-0.3, 2.3);
    std::vector<Eigen::Vector3d> pts;
    for (int i = 0; i < 1500; ++i) pts.emplace_back(ux(rng), uy(rng), uz(rng));
    // Exactly on lattice vertices, edge/face midpoints and cube centres (shared by many tets).
    for (int i = 0; i < 500; ++i) {
      std::uniform_int_distribution<int> ci(0, 10), cj(0, 8), ck(0, 6);
      pts.emplace_back(-1.0 + 0.25 * ci(rng), -0.75 + 0.25 * cj(rng), 0.25 + 0.25 * ck(rng));
    }
    // Exactly on random points of random tets' faces (barycentric combinations of 3 corners).
    for (int i = 0; i < 300; ++i) {
      const Index t = std::uniform_int_distribution<Index>(0, m.T.rows() - 1)(rng);
      std::uniform_real_distribution<double> uw(0, 1);
      double a = uw(rng), b = uw(rng) * (1 - a);
      pts.push_back(a * m.V.row(m.T(t, 0)).transpose() + b * m.V.row(m.T(t, 1)).transpose() +
                    (1 - a - b) * m.V.row(m.T(t, 3)).transpose());
    }
    // Far away.
    pts.emplace_back(100.0, -50.0, 3.0);
    pts.emplace_back(-1.3, -0.75, 0.25);
    Points<> Q(Index(pts.size()), 3);
    for (Index i = 0; i < Q.rows(); ++i) Q.row(i) = pts[std::size_t(i)].transpose();
    const Embedding<> e = embed(exec::seq, m, Q);
    const auto [in, out] = compare_with_brute_force(m, Q, e);
    CHECK(in > 1000);
    CHECK(out > 500);
    CHECK(e.num_inside() == in);
    // seq == omp, bitwise.
    const Embedding<> eo = embed(exec::omp, m, Q);
    CHECK(eo.tet == e.tet);
    CHECK(eo.weights == e.weights);
    CHECK((eo.inside == e.inside).all());
    CHECK(eo.distance == e.distance);
  }
  SUBCASE("jittered lattice (non-axis-aligned faces), cell sizes from small to large") {
    TetMesh<> m = test::box_tets(6, 5, 4, 1.0, Vec3<>(0.0, 0.0, 0.0), false);
    test::jitter(m.V, 0.12, rng);
    std::uniform_real_distribution<double> ux(-1.0, 7.0), uy(-1.0, 6.0), uz(-1.0, 5.0);
    Points<> Q(1500, 3);
    for (Index i = 0; i < Q.rows(); ++i) Q.row(i) << ux(rng), uy(rng), uz(rng);
    for (double scale : {0.3, 1.0, 4.0}) {
      CAPTURE(scale);
      EmbeddingOptions o;
      o.locator.cell_scale = scale;
      const Embedding<> e = embed(exec::omp, m, Q, o);
      const auto [in, out] = compare_with_brute_force(m, Q, e);
      CHECK(in > 500);
      CHECK(out > 300);
    }
  }
}

TEST_CASE("deform reproduces affine fields at inside and extrapolated points; clamp lands on the closest point") {
  std::mt19937 rng(5);
  TetMesh<> m = test::box_tets(4, 3, 3, 1.0, Vec3<>::Zero(), true);
  test::jitter(m.V, 0.1, rng);
  std::uniform_real_distribution<double> u(-0.8, 4.8);
  Points<> Q(800, 3);
  for (Index i = 0; i < Q.rows(); ++i) Q.row(i) << u(rng), u(rng) * 0.8, u(rng) * 0.8;
  Eigen::Matrix3d A = Eigen::Matrix3d::Random() + 2 * Eigen::Matrix3d::Identity();
  const Eigen::RowVector3d b(0.3, -1.2, 2.0);
  const Points<> V2 = (m.V * A.transpose()).rowwise() + b;
  const Points<> expect = (Q * A.transpose()).rowwise() + b;

  const Embedding<> e = embed(exec::seq, m, Q);
  REQUIRE(e.num_outside() > 100);
  const Points<> X = deform(exec::seq, e, m.T, V2);
  CHECK((X - expect).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((deform(exec::omp, e, m.T, V2) - X).cwiseAbs().maxCoeff() == 0);
  CHECK((deform(exec::seq, e, m.T, m.V) - Q).cwiseAbs().maxCoeff() < 1e-12);
  for (Index q = 0; q < Q.rows(); ++q) CHECK(std::abs(e.weights.row(q).sum() - 1) < 1e-13);

  const auto W = embedding_matrix(e, m.T, m.num_vertices());
  CHECK(W.rows() == Q.rows());
  CHECK(W.cols() == m.num_vertices());
  CHECK(W.nonZeros() == 4 * Q.rows());
  CHECK((Points<>(W * V2) - X).cwiseAbs().maxCoeff() < 1e-12);

  EmbeddingOptions clamp;
  clamp.outside = OutsideMode::clamp;
  const Embedding<> c = embed(exec::seq, m, Q, clamp);
  CHECK(c.tet == e.tet);
  CHECK(c.distance == e.distance);
  const Points<> C = deform(exec::seq, c, m.T, m.V);
  for (Index q = 0; q < Q.rows(); ++q) {
    CHECK((c.weights.row(q).array() >= (e.inside[q] ? -1e-10 : 0.0)).all());
    CHECK(std::abs((C.row(q) - Q.row(q)).norm() - c.distance[q]) < 1e-12);
  }
}

TEST_CASE("embedding errors name the tet, the point or the shape") {
  TetMesh<> m = test::box_tets(2, 2, 2);
  Points<> Q(3, 3);
  Q << 0.5, 0.5, 0.5, 1.5, 0.2, 0.3, 0.1, 0.1, 0.1;

  SUBCASE("degenerate tet") {
    TetMesh<> bad = m;
    bad.T.row(5) << bad.T(5, 0), bad.T(5, 1), bad.T(5, 2), bad.T(5, 2);  // repeated vertex
    CHECK_THROWS_AS(embed(exec::seq, bad, Q), MeshError);
    TetMesh<> flat = m;
    flat.V.conservativeResize(flat.V.rows() + 1, 3);
    flat.V.row(flat.V.rows() - 1) = (flat.V.row(flat.T(7, 0)) + flat.V.row(flat.T(7, 1))) / 2;  // on an edge: coplanar
    flat.T(7, 3) = VIndex(flat.V.rows() - 1);
    try {
      embed(exec::seq, flat, Q);
      FAIL("no MeshError");
    } catch (const MeshError& err) {
      CHECK(err.element() == 7);
      CHECK(std::string(err.what()).find("tet 7") != std::string::npos);
      CHECK(std::string(err.what()).find("degenerate") != std::string::npos);
    }
  }
  SUBCASE("non-finite query") {
    Q(1, 2) = std::numeric_limits<double>::quiet_NaN();
    try {
      embed(exec::seq, m, Q);
      FAIL("no ArgumentError");
    } catch (const ArgumentError& err) {
      CHECK(std::string(err.what()).find("point 1") != std::string::npos);
    }
  }
  SUBCASE("empty mesh and wrong shapes") {
    TetMesh<> empty;
    empty.V = m.V;
    CHECK_THROWS_AS(embed(exec::seq, empty, Q), MeshError);
    Eigen::MatrixXd Q2(4, 2);
    Q2.setZero();
    CHECK_THROWS_AS(embed(exec::seq, m, Q2), ShapeError);
    const Embedding<> e = embed(exec::seq, m, Q);
    CHECK_THROWS_AS(deform(exec::seq, e, m.T, Eigen::MatrixXd::Zero(m.num_vertices(), 2)), ShapeError);
    CHECK_THROWS_AS(deform(exec::seq, e, m.T, m.V.topRows(5)), MeshError);
    Tets fewer = m.T.topRows(1);
    CHECK_THROWS_AS(deform(exec::seq, e, fewer, m.V), ArgumentError);
  }
  SUBCASE("no queries") {
    const Embedding<> e = embed(exec::seq, m, Points<>(0, 3));
    CHECK(e.size() == 0);
    CHECK(e.max_distance() == 0);
  }
}

TEST_CASE("float embedding agrees with double on inside points") {
  std::mt19937 rng(9);
  TetMesh<> m = test::box_tets(4, 4, 4, 0.25);
  test::jitter(m.V, 0.02, rng);
  TetMesh<float> mf{m.V.cast<float>(), m.T};
  std::uniform_real_distribution<double> u(0.01, 0.99);
  Points<> Q(300, 3);
  for (Index i = 0; i < Q.rows(); ++i) Q.row(i) << u(rng), u(rng), u(rng);
  const Embedding<> e = embed(exec::seq, m, Q);
  const Embedding<float> ef = embed(exec::seq, mf, Points<float>(Q.cast<float>()));
  const Points<float> X = deform(exec::seq, ef, mf.T, mf.V);
  CHECK((X.cast<double>() - Q).cwiseAbs().maxCoeff() < 1e-5);
  Index same = (ef.tet.array() == e.tet.array()).count();
  CHECK(same >= Q.rows() - 3);  // points within float rounding of a face may pick the neighbour
}
