#include <doctest/doctest.h>
#include "../support/require.hpp"

#include "bunny_fixture.hpp"
#include "random_points.hpp"

#include <simsr/interp/rbf.hpp>
#include <simsr/io/npy.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/io/obj.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <sys/wait.h>

using namespace simsr;
using namespace simsr::interp;

namespace {

/// nx×ny×nz jittered lattice of spacing h split into 6 tets per cube (Freudenthal).
TetMesh<> lattice_tets(int nx, int ny, int nz, double h, double jitter, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-jitter * h, jitter * h);
  TetMesh<> t;
  t.V.resize(nx * ny * nz, 3);
  const auto id = [&](int i, int j, int k) { return VIndex(i + nx * (j + ny * k)); };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) t.V.row(id(i, j, k)) << i * h + u(rng), j * h + u(rng), k * h + u(rng);
  std::vector<std::array<VIndex, 4>> tets;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k + 1 < nz; ++k)
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i)
        for (const auto& p : perms) {
          int c[3] = {i, j, k};
          std::array<VIndex, 4> tet;
          tet[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) ++c[p[s]], tet[s + 1] = id(c[0], c[1], c[2]);
          tets.push_back(tet);
        }
  t.T.resize(Index(tets.size()), 4);
  for (std::size_t e = 0; e < tets.size(); ++e)
    for (int c = 0; c < 4; ++c) t.T(Index(e), c) = tets[e][std::size_t(c)];
  return t;
}

using simsr::test::random_points;

/// All-pairs shortest paths over the tets' corner pairs (Floyd–Warshall): the truth for A.2's
/// geodesic LR–LR distances.
Eigen::MatrixXd floyd_warshall(const TetMesh<>& t) {
  const Index n = t.V.rows();
  Eigen::MatrixXd D = Eigen::MatrixXd::Constant(n, n, std::numeric_limits<double>::infinity());
  for (Index i = 0; i < n; ++i) D(i, i) = 0;
  for (Index e = 0; e < t.T.rows(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        if (a != b) D(t.T(e, a), t.T(e, b)) = (t.V.row(t.T(e, a)) - t.V.row(t.T(e, b))).norm();
  for (Index k = 0; k < n; ++k)
    for (Index i = 0; i < n; ++i)
      for (Index j = 0; j < n; ++j) D(i, j) = std::min(D(i, j), D(i, k) + D(k, j));
  return D;
}

/// Problem whose neighbourhoods are the k Euclidean-nearest LR vertices (stand-ins for §3.2's).
UpsamplingProblem<> make_problem(TetMesh<> lr, Points<> H, Index k) {
  UpsamplingProblem<> p;
  p.lr = std::move(lr);
  p.hr.V = std::move(H);
  p.neighborhoods = simsr::test::brute_neighborhoods(p.lr.V, p.hr.V, k);
  return p;
}

double max_abs(const Points<>& a, const Points<>& b) { return (a - b).cwiseAbs().maxCoeff(); }

/// Closed torus (major radius R, minor r) around `centre`, nu×nv vertices, 2·nu·nv triangles.
TriMesh<> torus(int nu, int nv, double R, double r, const Eigen::RowVector3d& centre) {
  TriMesh<> t;
  t.V.resize(nu * nv, 3);
  t.F.resize(2 * nu * nv, 3);
  const double tau = 2 * std::acos(-1.0);
  const auto id = [&](int a, int b) { return VIndex((a % nu) * nv + (b % nv)); };
  for (int a = 0; a < nu; ++a)
    for (int b = 0; b < nv; ++b) {
      const double u = tau * a / nu, v = tau * b / nv;
      t.V.row(id(a, b)) = centre + Eigen::RowVector3d((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u),
                                                      r * std::sin(v));
      t.F.row(2 * id(a, b)) << id(a, b), id(a + 1, b), id(a + 1, b + 1);
      t.F.row(2 * id(a, b) + 1) << id(a, b), id(a + 1, b + 1), id(a, b + 1);
    }
  return t;
}

/// LR lattice (5×5×3, spacing 1) and an HR torus around it, with the §3.2 neighbourhoods (mapping
/// by assignment, k = 20): what RbfDistance::geodesic is fitted on.
UpsamplingProblem<> surface_problem(std::mt19937& rng, int nu = 30, int nv = 14) {
  UpsamplingProblem<> p;
  p.lr = lattice_tets(5, 5, 3, 1.0, 0.2, rng);
  p.hr = torus(nu, nv, 2.0, 1.2, Eigen::RowVector3d(2, 2, 1));
  p.ensure_neighborhoods(exec::seq, 20);
  return p;
}

/// All-pairs shortest paths over the HR triangles' edges (Floyd–Warshall): the truth for the
/// geodesic (surface) distances.
Eigen::MatrixXd surface_floyd_warshall(const TriMesh<>& t) {
  const Index n = t.V.rows();
  Eigen::MatrixXd D = Eigen::MatrixXd::Constant(n, n, std::numeric_limits<double>::infinity());
  for (Index i = 0; i < n; ++i) D(i, i) = 0;
  for (Index f = 0; f < t.F.rows(); ++f)
    for (int a = 0; a < 3; ++a) {
      const Index u = t.F(f, a), v = t.F(f, (a + 1) % 3);
      D(u, v) = D(v, u) = (t.V.row(u) - t.V.row(v)).norm();
    }
  for (Index k = 0; k < n; ++k)
    for (Index j = 0; j < n; ++j) {
      const double djk = D(j, k);
      if (djk == std::numeric_limits<double>::infinity()) continue;
      for (Index i = 0; i < n; ++i) D(i, j) = std::min(D(i, j), D(i, k) + djk);  // column-major inner loop
    }
  return D;
}

}  // namespace

TEST_CASE("RBF (Euclidean) matches scipy.interpolate.RBFInterpolator to 1e-8") {
#ifndef SIMSR_SOURCE_DIR
  SIMSR_MISSING("SIMSR_SOURCE_DIR undefined: no scipy peer script");
#else
  const std::filesystem::path peer = std::filesystem::path(SIMSR_SOURCE_DIR) / "scripts/peers/rbf_peer.py";
  if (!std::filesystem::exists("/usr/bin/python3") || std::system("/usr/bin/python3 -c 'import scipy.interpolate' 2>/dev/null") != 0) {
    SIMSR_MISSING("/usr/bin/python3 with scipy (python3-scipy) not available for the RBF peer");
    return;
  }
  const std::filesystem::path dir = std::filesystem::path(SIMSR_TEST_TMP_DIR) / "interp_rbf_peer";
  std::filesystem::create_directories(dir);
  std::mt19937 rng(21);
  UpsamplingProblem<> p;
  p.lr.V = random_points(60, 0.0, 1.0, rng);
  p.hr.V = random_points(45, -0.1, 1.1, rng);
  const Points<> values = random_points(60, -1.0, 1.0, rng);
  io::write_npy(dir / "c.npy", p.lr.V);
  io::write_npy(dir / "v.npy", values);
  io::write_npy(dir / "q.npy", p.hr.V);
  const double sigma = 0.3;
  std::ostringstream eps;
  eps.precision(17);
  eps << 1.0 / sigma;
  for (const int degree : {-1, 0, 1}) {
    const std::string out = (dir / ("p" + std::to_string(degree + 1) + ".npy")).string();
    const std::string cmd = "/usr/bin/python3 " + peer.string() + " --centres " + (dir / "c.npy").string() + " --values " +
                            (dir / "v.npy").string() + " --queries " + (dir / "q.npy").string() + " --epsilon " +
                            eps.str() + " --degree " + std::to_string(degree) + " --out " + out;
    const int rc = std::system(cmd.c_str());
    if (WIFEXITED(rc) && WEXITSTATUS(rc) == 77) {
      SIMSR_MISSING("scipy missing: " << peer << " exited 77");
      return;
    }
    REQUIRE(rc == 0);
    const Points<> ref = io::read_npy(out).to_matrix<double>();
    RBFOptions o;
    o.distance = RbfDistance::euclidean;
    o.sigma = sigma;
    o.degree = degree;
    RBF<> rbf(o);
    rbf.fit(exec::seq, p);
    Points<> dx(p.num_hr(), 3);
    rbf.apply(exec::seq, values, dx);
    INFO("degree ", degree, ", rcond ", rbf.info().rcond);
    const double err = max_abs(dx, ref);
    MESSAGE("RBF vs scipy (N = 60, M = 45, degree ", degree, "): max |difference| ", err, " (values up to ",
            ref.cwiseAbs().maxCoeff(), ")");
    CHECK(err < 1e-8);
  }
#endif
}

TEST_CASE("RBF reproduces constants (degree 0) and linear fields (degree 1), and interpolates its centres") {
  std::mt19937 rng(22);
  auto p = make_problem(lattice_tets(5, 5, 4, 1.0, 0.25, rng), random_points(80, 0.3, 3.5, rng), 20);
  // HR vertices coincident with LR vertices 0, 7, 33
  for (const Index i : {0, 7, 33}) p.hr.V.row(i) = p.lr.V.row(i);
  const Index n = p.num_lr(), m = p.num_hr();
  Points<> dX(n, 3), dx(m, 3);
  auto ps = surface_problem(rng);
  for (const auto dist : {RbfDistance::geodesic, RbfDistance::lr_mesh_geodesic, RbfDistance::euclidean}) {
    auto& q = dist == RbfDistance::geodesic ? ps : p;
    RBFOptions o;
    o.distance = dist;
    o.degree = 0;
    RBF<> rbf(o);
    rbf.fit(exec::seq, q);
    Points<> cX(q.num_lr(), 3), cx(q.num_hr(), 3);
    cX.rowwise() = Eigen::RowVector3d(0.4, -2.0, 1.5);
    rbf.apply(exec::seq, cX, cx);
    CHECK(max_abs(cx.rowwise() - Eigen::RowVector3d(0.4, -2.0, 1.5), Points<>::Zero(q.num_hr(), 3)) < 1e-9);
  }
  Eigen::Matrix3d G;
  G << 0.2, -0.1, 0.4, 0.0, 0.3, -0.2, 0.5, 0.1, 0.1;
  dX = (p.lr.V * G.transpose()).rowwise() + Eigen::RowVector3d(1, 2, 3);
  RBFOptions o;
  o.distance = RbfDistance::euclidean;
  o.degree = 1;
  RBF<> lin(o);
  lin.fit(exec::seq, p);
  lin.apply(exec::seq, dX, dx);
  CHECK(max_abs(dx, (p.hr.V * G.transpose()).rowwise() + Eigen::RowVector3d(1, 2, 3)) < 1e-9);
  // without a tail the paper's RBF does not reproduce constants between centres (the test can fail)
  o.degree = -1;
  RBF<> plain(o);
  plain.fit(exec::seq, p);
  dX.rowwise() = Eigen::RowVector3d(1, 1, 1);
  plain.apply(exec::seq, dX, dx);
  CHECK(max_abs(dx, Points<>::Ones(m, 3)) > 1e-3);
  // centres: exact at the coincident HR vertices for random values, every degree
  dX = random_points(n, -1, 1, rng);
  for (const int degree : {-1, 0, 1}) {
    o.degree = degree;
    RBF<> r(o);
    r.fit(exec::seq, p);
    r.apply(exec::seq, dX, dx);
    for (const Index i : {0, 7, 33}) CHECK((dx.row(i) - dX.row(i)).norm() < 1e-10);
  }
}

TEST_CASE("RBF lr_mesh_geodesic equals the direct solve with Floyd-Warshall LR distances, on every path") {
  std::mt19937 rng(23);
  auto p = make_problem(lattice_tets(5, 4, 4, 1.0, 0.3, rng), random_points(70, 0.2, 3.2, rng), 20);
  const Index n = p.num_lr(), m = p.num_hr(), k = 20;
  const Eigen::MatrixXd D = floyd_warshall(p.lr);
  const double sigma = 1.1;
  Eigen::MatrixXd Phi(n, n);
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < n; ++j) Phi(i, j) = std::exp(-D(i, j) * D(i, j) / (sigma * sigma));
  Eigen::MatrixXd Phi_hl = Eigen::MatrixXd::Zero(m, n);  // truncated to the neighbourhoods
  for (Index j = 0; j < m; ++j)
    for (Index q = 0; q < k; ++q) {
      const double d = p.neighborhoods->distances(j, q);
      Phi_hl(j, p.neighborhoods->indices(j, q)) = std::exp(-d * d / (sigma * sigma));
    }
  const auto lu = Phi.fullPivLu();
  for (int frame = 0; frame < 2; ++frame) {
    const Points<> dX = random_points(n, -1, 1, rng);
    const Eigen::MatrixXd W = lu.solve(Eigen::MatrixXd(dX));
    const Points<> ref = Phi_hl * W;
    Points<> dx(m, 3);
    RBFOptions o;
    o.distance = RbfDistance::lr_mesh_geodesic;
    o.sigma = sigma;
    RBF<> dense(o);  // precomputed M×N operator
    dense.fit(exec::seq, p);
    CHECK(dense.info().precomputed_operator);
    dense.apply(exec::seq, dX, dx);
    CHECK(max_abs(dx, ref) < 1e-10);
    o.max_operator_bytes = 0;  // keep the LU, solve per frame
    RBF<> solve(o);
    solve.fit(exec::seq, p);
    CHECK(!solve.info().precomputed_operator);
    solve.apply(exec::seq, dX, dx);
    CHECK(max_abs(dx, ref) < 1e-10);
    o.solver = RbfSolver::sparse;  // truncated Φ_LL, sparse LDLᵀ
    o.truncation = 1e-13;
    RBF<> sparse(o);
    sparse.fit(exec::seq, p);
    CHECK(sparse.info().sparse);
    CHECK(sparse.info().lr_nonzeros < n * (n + 1) / 2);  // truncation dropped entries
    sparse.apply(exec::seq, dX, dx);
    CHECK(max_abs(dx, ref) < 1e-8);
  }
}

TEST_CASE("RBF geodesic: one surface metric - the dense solve with Floyd-Warshall surface distances, exact at mapped vertices") {
  std::mt19937 rng(25);
  auto p = surface_problem(rng);
  const Index n = p.num_lr(), m = p.num_hr();
  const auto& map = p.neighborhoods->lr_to_hr;
  const Eigen::MatrixXd D = surface_floyd_warshall(p.hr);
  // default σ: the mean distance from each mapped vertex to the nearest other one
  double spacing = 0;
  for (Index i = 0; i < n; ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    for (Index k = 0; k < n; ++k)
      if (k != i) nearest = std::min(nearest, D(map[i], map[k]));
    spacing += nearest / double(n);
  }
  RBF<> def;
  def.fit(exec::seq, p);
  CHECK(def.info().sigma == doctest::Approx(spacing).epsilon(1e-12));
  const double truncation = 1e-12;
  for (const double sigma : {spacing, 1.3 * spacing}) {
    const double radius = sigma * std::sqrt(std::log(1 / truncation));
    const auto phi = [&](double d) { return d <= radius ? std::exp(-d * d / (sigma * sigma)) : 0.0; };
    for (const int degree : {-1, 0, 1}) {
      // reference: Eq. 10–11 with surface distances between mapped positions, truncated alike,
      // the tail's monomials at the mapped positions
      const Index q = degree < 0 ? 0 : degree == 0 ? 1 : 4;
      Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + q, n + q), E = Eigen::MatrixXd::Zero(m, n + q);
      const auto mono = [&](Index v) {
        Eigen::RowVectorXd r(q);
        if (q > 0) r(0) = 1;
        if (q > 1) r.tail(3) = p.hr.V.row(v);
        return r;
      };
      for (Index i = 0; i < n; ++i) {
        for (Index k = 0; k < n; ++k) K(i, k) = phi(D(map[i], map[k]));
        K.block(i, n, 1, q) = mono(map[i]);
        K.block(n, i, q, 1) = mono(map[i]).transpose();
      }
      for (Index j = 0; j < m; ++j) {
        for (Index k = 0; k < n; ++k) E(j, k) = phi(D(j, map[k]));
        E.block(j, n, 1, q) = mono(j);
      }
      const auto lu = K.fullPivLu();
      const Points<> dX = random_points(n, -1, 1, rng);
      Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n + q, 3);
      rhs.topRows(n) = dX;
      const Points<> ref = E * lu.solve(rhs);
      for (const int path : {0, 1, 2}) {
        RBFOptions o;
        o.sigma = sigma;
        o.degree = degree;
        o.truncation = truncation;
        if (path == 1) o.max_operator_bytes = 0;
        if (path == 2) o.solver = RbfSolver::sparse;
        RBF<> rbf(o);
        rbf.fit(exec::omp, p);
        CHECK(rbf.info().cutoff_radius == doctest::Approx(radius));
        Points<> dx(m, 3);
        rbf.apply(exec::omp, dX, dx);
        INFO("sigma ", sigma, ", degree ", degree, ", path ", path, ", rcond ", rbf.info().rcond);
        CHECK(max_abs(dx, ref) < 1e-8 * (1 + ref.cwiseAbs().maxCoeff()));
        double at_centres = 0;
        for (Index i = 0; i < n; ++i) at_centres = std::max(at_centres, (dx.row(map[i]) - dX.row(i)).norm());
        CHECK(at_centres < 1e-9);
      }
    }
  }
  // the inconsistent metric does not reproduce the centres at their mapped vertices
  RBFOptions o;
  o.distance = RbfDistance::lr_mesh_geodesic;
  RBF<> lr_mesh(o);
  lr_mesh.fit(exec::seq, p);
  const Points<> dX = random_points(n, -1, 1, rng);
  Points<> dx(m, 3);
  lr_mesh.apply(exec::seq, dX, dx);
  double at_centres = 0;
  for (Index i = 0; i < n; ++i) at_centres = std::max(at_centres, (dx.row(map[i]) - dX.row(i)).norm());
  CHECK(at_centres > 0.1);
}

TEST_CASE("RBF surface distances are the 20-neighbourhood distances bit for bit, under seq and omp") {
  std::mt19937 rng(26);
  auto p = surface_problem(rng);
  const auto& nb = *p.neighborhoods;
  const auto g = neighbors::surface_edge_graph(p.hr.V, p.hr.F);
  const std::span<const VIndex> map(nb.lr_to_hr.data(), std::size_t(nb.lr_to_hr.size()));
  const double radius = 1.5;  // a limit that cuts rows short
  std::vector<interp::detail::DistanceRow> seq_rows(std::size_t(p.num_lr())), omp_rows(seq_rows.size());
  interp::detail::surface_rows(exec::seq, g, map, radius, [&](Index s, const interp::detail::DistanceRow& r) { seq_rows[std::size_t(s)] = r; });
  interp::detail::surface_rows(exec::omp, g, map, radius, [&](Index s, const interp::detail::DistanceRow& r) { omp_rows[std::size_t(s)] = r; });
  CHECK(seq_rows == omp_rows);
  Index found = 0, inside = 0;
  for (Index j = 0; j < p.num_hr(); ++j)
    for (Index c = 0; c < nb.k(); ++c) {
      if (nb.distances(j, c) > radius) continue;
      ++inside;
      const auto& row = seq_rows[std::size_t(nb.indices(j, c))];
      const auto it = std::lower_bound(row.begin(), row.end(), std::pair<VIndex, double>(VIndex(j), -1.0));
      found += it != row.end() && it->first == j && it->second == nb.distances(j, c);
    }
  CHECK(inside > 0);
  CHECK(found == inside);
  // and nothing beyond the radius
  for (const auto& row : seq_rows)
    for (const auto& e : row) CHECK_UNARY(e.second <= radius);
}

TEST_CASE("RBF: singular systems, shapes, options; seq and omp give identical bits") {
  std::mt19937 rng(24);
  auto p = make_problem(lattice_tets(5, 5, 5, 1.0, 0.25, rng), random_points(300, 0.0, 4.0, rng), 20);
  auto ps = surface_problem(rng);
  Points<> dX = random_points(ps.num_lr(), -1, 1, rng), a(ps.num_hr(), 3), b(ps.num_hr(), 3);
  for (const auto solver : {RbfSolver::dense, RbfSolver::sparse}) {
    RBFOptions o;
    o.solver = solver;
    o.degree = 1;
    RBF<> s(o), t(o);
    s.fit(exec::seq, ps);
    t.fit(exec::omp, ps);
    s.apply(exec::seq, dX, a);
    t.apply(exec::omp, dX, b);
    CHECK((a.array() == b.array()).all());
    s.apply(exec::omp, dX, b);
    CHECK((a.array() == b.array()).all());
  }
  // geodesic mode: what it needs, as typed errors
  {
    auto no_map = ps;
    no_map.neighborhoods->lr_to_hr.resize(0);
    CHECK_THROWS_WITH_AS(RBF<>().fit(exec::seq, no_map), doctest::Contains("lr_to_hr"), ArgumentError);
    auto two = ps;
    two.neighborhoods->lr_to_hr[3] = two.neighborhoods->lr_to_hr[4];
    CHECK_THROWS_WITH_AS(RBF<>().fit(exec::seq, two), doctest::Contains("one-to-one"), ArgumentError);
    auto flat = ps;
    flat.hr.F.resize(0, 3);
    CHECK_THROWS_WITH_AS(RBF<>().fit(exec::seq, flat), doctest::Contains("no triangles"), ArgumentError);
    auto none = ps;
    none.neighborhoods.reset();
    CHECK_THROWS_AS(RBF<>().fit(exec::seq, none), ArgumentError);
  }
  dX = random_points(p.num_lr(), -1, 1, rng);
  a.resize(p.num_hr(), 3), b.resize(p.num_hr(), 3);
  for (const auto solver : {RbfSolver::dense, RbfSolver::sparse}) {
    RBFOptions o;
    o.distance = RbfDistance::lr_mesh_geodesic;
    o.solver = solver;
    o.degree = 1;
    RBF<> s(o), t(o);
    s.fit(exec::seq, p);
    t.fit(exec::omp, p);
    s.apply(exec::seq, dX, a);
    t.apply(exec::omp, dX, b);
    CHECK((a.array() == b.array()).all());
    s.apply(exec::omp, dX, b);
    CHECK((a.array() == b.array()).all());
  }
  RBF<> r;
  r.fit(exec::seq, ps);
  Points<> wrong(ps.num_lr() + 1, 3);
  a.resize(ps.num_hr(), 3);
  CHECK_THROWS_AS(r.apply(exec::seq, wrong, a), ShapeError);
  CHECK_THROWS_AS(RBF<>(RBFOptions{.degree = 2}).fit(exec::seq, p), ArgumentError);
  // a duplicated LR vertex makes two rows of Φ_LL equal (Euclidean: the duplicate is at distance 0)
  auto dup = p;
  dup.lr.V.row(5) = dup.lr.V.row(6);
  RBFOptions e;
  e.distance = RbfDistance::euclidean;
  CHECK_THROWS_WITH_AS(RBF<>(e).fit(exec::seq, dup), doctest::Contains("numerically singular"), ArgumentError);
  e.solver = RbfSolver::sparse;
  CHECK_THROWS_AS(RBF<>(e).fit(exec::seq, dup), ArgumentError);
  // a far too wide Gaussian: Φ_LL is numerically rank deficient
  e.solver = RbfSolver::dense;
  e.sigma_scale = 40;
  CHECK_THROWS_WITH_AS(RBF<>(e).fit(exec::seq, p), doctest::Contains("numerically singular"), ArgumentError);
}

using simsr::test::Bunny;
using simsr::test::load_bunny;

/// lr_mesh_geodesic on the bunny (mean error 0.15 vs 0.0049 at rest) is left out for time (a dense
/// 1747² LU); its inconsistency is checked on the torus above.
TEST_CASE("RBF on the bunny: geodesic (one surface metric) and Euclidean beat the rest shape") {
  Bunny b;
  if (!load_bunny(b, {10, 100, 200, 250})) {
    SIMSR_MISSING("bunny data not found in " << SIMSR_DATA_DIR);
    return;
  }
  const auto& map = b.problem.neighborhoods->lr_to_hr;
  const std::pair<RbfDistance, int> cases[] = {{RbfDistance::geodesic, -1}, {RbfDistance::geodesic, 0},
                                               {RbfDistance::euclidean, -1}};
  for (const auto& [dist, degree] : cases) {
    RBFOptions o;
    o.distance = dist;
    o.degree = degree;
    o.max_operator_bytes = 0;  // LU solves per frame: a quicker fit for four frames
    // geodesic Φ_LL has ~30 entries a row within the truncation radius: the sparse LDLᵀ is quick
    // (the dense path agrees, see the Floyd-Warshall case); Euclidean and LR-mesh rows are dense
    if (dist == RbfDistance::geodesic) o.solver = RbfSolver::sparse;
    RBF<> rbf(o);
    rbf.fit(exec::omp, b.problem);
    Points<> dx(b.problem.num_hr(), 3);
    double mean = 0, worst = 0, rest = 0, at_centres = 0;
    for (std::size_t f = 0; f < b.lr_frames.size(); ++f) {
      rbf.apply(exec::omp, b.lr_frames[f], dx);
      const Eigen::VectorXd e = (dx - b.hr_frames[f]).rowwise().norm();
      const double rest_f = b.hr_frames[f].rowwise().norm().mean();
      mean += e.mean() / double(b.lr_frames.size());
      worst = std::max(worst, e.maxCoeff());
      rest += rest_f / double(b.lr_frames.size());
      CHECK(e.allFinite());
      for (Index i = 0; i < b.problem.num_lr(); ++i)
        at_centres = std::max(at_centres, (dx.row(map[i]) - b.lr_frames[f].row(i)).norm());
      // one metric for Φ_LL and Φ_HL: the interpolant beats "HR stays at rest" in every frame
      CHECK(e.mean() < 0.6 * rest_f);
    }
    const std::string name = dist == RbfDistance::geodesic ? "geodesic" : "euclidean";
    MESSAGE("bunny RBF ", name, " degree ", degree, ": mean error ", mean, ", max ", worst, " (rest shape: mean ", rest,
            "), sigma ", rbf.info().sigma, ", rcond ", rbf.info().rcond, ", max |dx - dX| at mapped vertices ", at_centres);
    if (dist == RbfDistance::geodesic) CHECK(at_centres < 1e-9);  // Δx^H at lr_to_hr[i] is ΔX^L_i
  }
}

TEST_CASE("RBF::apply's operator body over strided MatrixSpans (DeviceRbf's accessor) equals apply, bitwise, seq and omp") {
  std::mt19937 rng(31);
  auto p = make_problem(lattice_tets(4, 4, 3, 1.0, 0.3, rng), random_points(60, 0.2, 2.8, rng), 20);
  RBFOptions o;
  o.distance = RbfDistance::lr_mesh_geodesic;
  o.sigma = 1.1;
  RBF<> rbf(o);
  rbf.fit(exec::seq, p);
  REQUIRE(rbf.info().precomputed_operator);
  CHECK(rbf.evaluation_operator().rows() == p.num_hr());
  CHECK(rbf.evaluation_operator().cols() == p.num_lr());
  const Points<> dX = random_points(p.num_lr(), -1, 1, rng);
  Points<> ref(p.num_hr(), 3);
  rbf.apply(exec::seq, dX, ref);
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> wide_lr(p.num_lr(), 4), wide_hr(p.num_hr(), 4);
  wide_lr.leftCols(3) = dX;
  for (const bool omp : {false, true}) {
    wide_hr.setConstant(3.0);
    const interp::detail::DenseOperatorRow<double> body{rbf.evaluation_operator().data(), p.num_lr(), {wide_lr.data(), p.num_lr(), 3, 4},
                                                        {wide_hr.data(), p.num_hr(), 3, 4}};
    if (omp)
      exec::parallel_for(exec::omp, p.num_hr(), body);
    else
      exec::parallel_for(exec::seq, p.num_hr(), body);
    CHECK(Points<>(wide_hr.leftCols(3)) == ref);
    CHECK((wide_hr.col(3).array() == 3.0).all());
  }
  o.max_operator_bytes = 0;  // the factor kept: no operator to copy
  RBF<> solve(o);
  solve.fit(exec::seq, p);
  CHECK(solve.evaluation_operator().size() == 0);
}
