#include <doctest/doctest.h>
#include "../support/require.hpp"

#include "bunny_fixture.hpp"
#include "random_points.hpp"

#include <simsr/interp/idw.hpp>
#include <simsr/interp/mls.hpp>
#include <simsr/io/npy.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/io/obj.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/QR>

using namespace simsr;
using namespace simsr::interp;

namespace {

/// nx×ny×nz lattice of spacing h, each vertex jittered by up to ±jitter·h per coordinate.
Points<> jittered_lattice(int nx, int ny, int nz, double h, double jitter, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-jitter * h, jitter * h);
  Points<> V(nx * ny * nz, 3);
  Index v = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) V.row(v++) << i * h + u(rng), j * h + u(rng), k * h + u(rng);
  return V;
}

using simsr::test::random_points;

using simsr::test::brute_neighborhoods;

UpsamplingProblem<> point_problem(Points<> L, Points<> H, Index k) {
  UpsamplingProblem<> p;
  p.lr.V = std::move(L);
  p.hr.V = std::move(H);
  p.neighborhoods = brute_neighborhoods(p.lr.V, p.hr.V, k);
  return p;
}

/// Per frame, per HR vertex and component, the weighted least-squares problem of Eq. 13 with the
/// unscaled re-centred basis, solved by Householder QR on √W·B (independent of MLS's eigen path).
Points<> direct_mls(const UpsamplingProblem<>& p, const Points<>& dX, double sigma, bool linear_3d, int r, Index k) {
  const auto& nb = *p.neighborhoods;
  Points<> out(p.num_hr(), 3);
  for (Index j = 0; j < p.num_hr(); ++j) {
    Eigen::VectorXd sw(k);
    for (Index n = 0; n < k; ++n) sw(n) = std::sqrt(std::exp(-nb.distances(j, n) * nb.distances(j, n) / (sigma * sigma)));
    if (linear_3d) {
      Eigen::MatrixXd B(k, 4), rhs(k, 3);
      for (Index n = 0; n < k; ++n) {
        const Index i = nb.indices(j, n);
        B.row(n) << 1, p.lr.V(i, 0) - p.hr.V(j, 0), p.lr.V(i, 1) - p.hr.V(j, 1), p.lr.V(i, 2) - p.hr.V(j, 2);
        B.row(n) *= sw(n);
        rhs.row(n) = sw(n) * dX.row(i);
      }
      out.row(j) = B.colPivHouseholderQr().solve(rhs).row(0);
    } else {
      for (int c = 0; c < 3; ++c) {
        Eigen::MatrixXd B(k, r + 1);
        Eigen::VectorXd rhs(k);
        for (Index n = 0; n < k; ++n) {
          const Index i = nb.indices(j, n);
          const double t = p.lr.V(i, c) - p.hr.V(j, c);
          for (int q = 0; q <= r; ++q) B(n, q) = sw(n) * std::pow(t, q);
          rhs(n) = sw(n) * dX(i, c);
        }
        out(j, c) = B.colPivHouseholderQr().solve(rhs)(0);
      }
    }
  }
  return out;
}

}  // namespace

TEST_CASE("MLS (as written, Eq. 12-16) reproduces constants and fields linear/quadratic per coordinate") {
  std::mt19937 rng(7);
  auto p = point_problem(jittered_lattice(7, 6, 5, 1.0, 0.3, rng), random_points(300, 0.5, 4.5, rng), 20);
  MLS<> mls;
  mls.fit(exec::seq, p);
  CHECK(mls.info().systems_at_degree[2] == 3 * p.num_hr());  // no fallback on a jittered lattice
  Points<> dX(p.num_lr(), 3), dx(p.num_hr(), 3);
  dX.rowwise() = Eigen::RowVector3d(0.3, -1.2, 2.5);
  mls.apply(exec::seq, dX, dx);
  for (Index j = 0; j < p.num_hr(); ++j) CHECK((dx.row(j) - Eigen::RowVector3d(0.3, -1.2, 2.5)).norm() < 1e-12);
  // Δx depends on x only (quadratic), Δy on y, Δz on z: exact for r = 2 (the basis is 1-D per component)
  const auto field = [](const Points<>& X) {
    Points<> F(X.rows(), 3);
    for (Index i = 0; i < X.rows(); ++i) {
      const double x = X(i, 0), y = X(i, 1), z = X(i, 2);
      F.row(i) << 0.3 + 0.2 * x - 0.1 * x * x, -0.5 * y + 0.07 * y * y, 0.4 * z - 1.0;
    }
    return F;
  };
  dX = field(p.lr.V);
  mls.apply(exec::seq, dX, dx);
  CHECK((dx - field(p.hr.V)).cwiseAbs().maxCoeff() < 1e-10);
  // a field mixing coordinates is not reproduced by the per-coordinate basis (the test can fail)
  for (Index i = 0; i < p.num_lr(); ++i) dX.row(i) << p.lr.V(i, 1), 0, 0;
  mls.apply(exec::seq, dX, dx);
  double worst = 0;
  for (Index j = 0; j < p.num_hr(); ++j) worst = std::max(worst, std::abs(dx(j, 0) - p.hr.V(j, 1)));
  CHECK(worst > 1e-3);
}

TEST_CASE("MLS 3-D linear reproduces linear fields exactly") {
  std::mt19937 rng(8);
  auto p = point_problem(jittered_lattice(6, 6, 6, 0.5, 0.3, rng), random_points(200, 0.2, 2.3, rng), 20);
  MLS<> mls(MLSOptions{.basis = MlsBasis::linear_3d});
  mls.fit(exec::seq, p);
  CHECK(mls.info().rank_deficient == 0);
  Eigen::Matrix3d G;
  G << 0.1, -0.4, 0.2, 0.3, 0.0, -0.7, 1.1, 0.5, 0.2;
  const Eigen::RowVector3d t(0.5, -0.25, 2.0);
  Points<> dX = (p.lr.V * G.transpose()).rowwise() + t, dx(p.num_hr(), 3);
  mls.apply(exec::seq, dX, dx);
  const Points<> expect = (p.hr.V * G.transpose()).rowwise() + t;
  CHECK((dx - expect).cwiseAbs().maxCoeff() < 1e-11);
}

TEST_CASE("MLS equals the weighted least-squares problem solved directly per frame") {
  std::mt19937 rng(9);
  auto p = point_problem(jittered_lattice(6, 5, 5, 1.0, 0.35, rng), random_points(150, 0.0, 4.0, rng), 20);
  Points<> dX = random_points(p.num_lr(), -1, 1, rng), dx(p.num_hr(), 3);
  for (const bool lin : {false, true})
    for (const int r : {0, 1, 2}) {
      if (lin && r != 1) continue;
      MLSOptions o;
      o.basis = lin ? MlsBasis::linear_3d : MlsBasis::per_coordinate;
      o.degree = r;
      o.sigma = 1.3;
      MLS<> mls(o);
      mls.fit(exec::seq, p);
      mls.apply(exec::seq, dX, dx);
      const Points<> ref = direct_mls(p, dX, o.sigma, lin, r, 20);
      INFO("linear_3d = ", lin, ", r = ", r);
      CHECK((dx - ref).cwiseAbs().maxCoeff() < 1e-10);
    }
}

TEST_CASE("MLS on a flat lattice layer: singular moment matrices fall back, never NaN") {
  std::mt19937 rng(10);
  Points<> L = jittered_lattice(8, 8, 1, 1.0, 0.2, rng);
  L.col(2).setConstant(0.5);  // every LR vertex at z = 0.5
  Points<> H = random_points(120, 1.0, 6.0, rng);
  H.col(2).setConstant(0.5);
  auto p = point_problem(L, H, 20);
  MLS<> mls;
  mls.fit(exec::seq, p);
  // z: all t = 0 → degree 0 for every vertex; x and y keep degree 2
  CHECK(mls.info().systems_at_degree[0] == p.num_hr());
  CHECK(mls.info().systems_at_degree[2] == 2 * p.num_hr());
  MLS<> lin(MLSOptions{.basis = MlsBasis::linear_3d});
  lin.fit(exec::seq, p);
  CHECK(lin.info().rank_deficient == p.num_hr());
  // in-plane linear field: exact also for the rank-deficient systems (HR vertices in the plane)
  Points<> dX(p.num_lr(), 3), dx(p.num_hr(), 3);
  for (Index i = 0; i < p.num_lr(); ++i) dX.row(i) << 1 + 0.2 * L(i, 0) - 0.3 * L(i, 1), 0.1 * L(i, 1), 2.0;
  for (auto* m : {&mls, &lin}) {
    m->apply(exec::seq, dX, dx);
    CHECK(dx.allFinite());
    for (Index j = 0; j < p.num_hr(); ++j) {
      CHECK(dx(j, 1) == doctest::Approx(0.1 * H(j, 1)).epsilon(1e-9));
      CHECK(dx(j, 2) == doctest::Approx(2.0).epsilon(1e-12));
    }
  }
  // two distinct heights only: the quadratic in z drops to degree 1
  Points<> L2 = L;
  for (Index i = 0; i < L2.rows(); ++i) L2(i, 2) = (i % 2) ? 0.5 : 1.5;
  auto p2 = point_problem(L2, H, 20);
  MLS<> m2;
  m2.fit(exec::seq, p2);
  CHECK(m2.info().systems_at_degree[1] == p2.num_hr());
}

TEST_CASE("MLS: seq and omp give identical bits; shapes and options are checked") {
  std::mt19937 rng(11);
  auto p = point_problem(jittered_lattice(6, 6, 5, 1.0, 0.3, rng), random_points(400, 0.0, 5.0, rng), 20);
  Points<> dX = random_points(p.num_lr(), -1, 1, rng), a(p.num_hr(), 3), b(p.num_hr(), 3);
  for (const auto basis : {MlsBasis::per_coordinate, MlsBasis::linear_3d}) {
    MLS<> s(MLSOptions{.basis = basis}), o(MLSOptions{.basis = basis});
    s.fit(exec::seq, p);
    o.fit(exec::omp, p);
    CHECK((s.coefficients().array() == o.coefficients().array()).all());
    s.apply(exec::seq, dX, a);
    o.apply(exec::omp, dX, b);
    CHECK((a.array() == b.array()).all());
  }
  MLS<> m;
  m.fit(exec::seq, p);
  Points<> wrong(p.num_hr() - 1, 3);
  CHECK_THROWS_AS(m.apply(exec::seq, dX, wrong), ShapeError);
  CHECK_THROWS_AS(MLS<>(MLSOptions{.degree = 4}).fit(exec::seq, p), ArgumentError);
  CHECK_THROWS_AS(MLS<>(MLSOptions{.k = 30}).fit(exec::seq, p), ArgumentError);
  UpsamplingProblem<> bare;  // no neighbourhoods
  bare.lr = p.lr;
  bare.hr = p.hr;
  CHECK_THROWS_WITH_AS(MLS<>().fit(exec::seq, bare), doctest::Contains("ensure_neighborhoods"), ArgumentError);
}

using simsr::test::Bunny;
using simsr::test::load_bunny;

TEST_CASE("MLS on the bunny: both variants beat the rest shape") {
  Bunny b;
  if (!load_bunny(b, {10, 100, 200, 250})) {
    SIMSR_MISSING("bunny data not found in " << SIMSR_DATA_DIR);
    return;
  }
  for (const auto basis : {MlsBasis::per_coordinate, MlsBasis::linear_3d}) {
    MLS<> mls(MLSOptions{.basis = basis});
    mls.fit(exec::omp, b.problem);
    Points<> dx(b.problem.num_hr(), 3);
    double mean = 0, worst = 0, rest = 0;
    for (std::size_t f = 0; f < b.lr_frames.size(); ++f) {
      mls.apply(exec::omp, b.lr_frames[f], dx);
      const Eigen::VectorXd e = (dx - b.hr_frames[f]).rowwise().norm();
      mean += e.mean() / double(b.lr_frames.size());
      worst = std::max(worst, e.maxCoeff());
      rest += b.hr_frames[f].rowwise().norm().mean() / double(b.lr_frames.size());
      CHECK(e.mean() < b.hr_frames[f].rowwise().norm().mean());  // beats "HR stays at rest"
    }
    MESSAGE("bunny MLS ", std::string(basis == MlsBasis::per_coordinate ? "as written (r = 2)" : "3-D linear"), ": mean error ", mean,
            ", max ", worst, " (rest shape: mean ", rest, "), sigma ", mls.info().sigma, ", fallbacks ",
            mls.info().systems_at_degree[0] + mls.info().systems_at_degree[1] + mls.info().rank_deficient);
  }
}

TEST_CASE("NeighborGather's body over strided MatrixSpans (DeviceNeighborGather's accessor) equals MLS's and IDW's apply, bitwise, seq and omp") {
  std::mt19937 rng(13);
  auto p = point_problem(jittered_lattice(6, 5, 4, 1.0, 0.3, rng), random_points(250, 0.5, 3.5, rng), 20);
  MLS<> per_coordinate, linear(MLSOptions{.basis = MlsBasis::linear_3d});
  per_coordinate.fit(exec::seq, p);
  linear.fit(exec::seq, p);
  IDW<> idw;
  idw.fit(exec::seq, p);
  CHECK(per_coordinate.gather().per_component);
  CHECK_FALSE(idw.gather().per_component);
  std::normal_distribution<double> N;
  Points<> lr(p.num_lr(), 3);
  for (Index i = 0; i < lr.size(); ++i) lr.data()[i] = N(rng);
  // the LR input and HR output in wider rows (stride 5), as a device array may be laid out
  Eigen::Matrix<double, Eigen::Dynamic, 5, Eigen::RowMajor> wide_lr(p.num_lr(), 5), wide_hr(p.num_hr(), 5);
  wide_lr.leftCols(3) = lr;
  for (const interp::detail::NeighborGather<double>* g : {&per_coordinate.gather(), &linear.gather(), &idw.gather()}) {
    Points<> ref(p.num_hr(), 3);
    g->apply(exec::seq, lr, ref);
    for (const bool omp : {false, true}) {
      wide_hr.setConstant(-7.0);
      const interp::detail::NeighborGatherRow<double> body{g->indices.data(), g->weights.data(), g->k(), g->per_component,
                                                           {wide_lr.data(), p.num_lr(), 3, 5}, {wide_hr.data(), p.num_hr(), 3, 5}};
      if (omp)
        exec::parallel_for(exec::omp, p.num_hr(), body);
      else
        exec::parallel_for(exec::seq, p.num_hr(), body);
      CHECK(Points<>(wide_hr.leftCols(3)) == ref);
      CHECK((wide_hr.rightCols(2).array() == -7.0).all());  // the padding untouched
    }
  }
  Points<> a(p.num_hr(), 3);
  idw.apply(exec::omp, lr, a);
  Points<> b(p.num_hr(), 3);
  idw.gather().apply(exec::seq, lr, b);
  CHECK(a == b);
}
