#include <doctest/doctest.h>
#include "../support/require.hpp"

#include "bunny_fixture.hpp"
#include "random_points.hpp"

#include <simsr/interp/idw.hpp>
#include <simsr/io/npy.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/io/obj.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <utility>
#include <vector>

using namespace simsr;
using namespace simsr::interp;

namespace {

using simsr::test::random_points;

/// Problem whose neighbourhoods are the k Euclidean-nearest LR vertices (stand-ins for §3.2's).
UpsamplingProblem<> make_problem(Points<> L, Points<> H, Index k) {
  UpsamplingProblem<> p;
  p.lr.V = std::move(L);
  p.hr.V = std::move(H);
  p.neighborhoods = simsr::test::brute_neighborhoods(p.lr.V, p.hr.V, k);
  return p;
}

}  // namespace

TEST_CASE("IDW: weights sum to 1, constants exact, exact hits, and the direct formula") {
  std::mt19937 rng(31);
  auto p = make_problem(random_points(120, 0, 1, rng), random_points(90, 0, 1, rng), 20);
  p.hr.V.row(4) = p.lr.V.row(17);  // an exact hit
  p = make_problem(p.lr.V, p.hr.V, 20);
  for (const double power : {1.0, 2.0, 3.5}) {
    IDW<> idw(IDWOptions{.power = power});
    idw.fit(exec::seq, p);
    for (Index j = 0; j < p.num_hr(); ++j) {
      CHECK(idw.weights().row(j).sum() == doctest::Approx(1.0).epsilon(1e-14));
      CHECK(idw.weights().row(j).minCoeff() >= 0);
    }
    CHECK(idw.indices()(4, 0) == 17);
    CHECK(idw.weights()(4, 0) == 1.0);
    CHECK(idw.weights().row(4).tail(19).cwiseAbs().maxCoeff() == 0.0);
    Points<> dX = random_points(p.num_lr(), -1, 1, rng), dx(p.num_hr(), 3);
    idw.apply(exec::seq, dX, dx);
    CHECK((dx.row(4) - dX.row(17)).norm() == 0.0);
    for (Index j = 0; j < p.num_hr(); ++j) {
      if (j == 4) continue;
      Eigen::RowVector3d num = Eigen::RowVector3d::Zero();
      double den = 0;
      for (Index n = 0; n < 20; ++n) {
        const Index i = p.neighborhoods->indices(j, n);
        const double w = 1 / std::pow((p.lr.V.row(i) - p.hr.V.row(j)).norm(), power);
        num += w * dX.row(i);
        den += w;
      }
      CHECK((dx.row(j) - num / den).norm() < 1e-13);
    }
    dX.rowwise() = Eigen::RowVector3d(-0.7, 0.1, 3.0);
    idw.apply(exec::seq, dX, dx);
    for (Index j = 0; j < p.num_hr(); ++j) CHECK((dx.row(j) - Eigen::RowVector3d(-0.7, 0.1, 3.0)).norm() < 1e-14);
  }
}

TEST_CASE("IDW: seq and omp identical bits; errors") {
  std::mt19937 rng(32);
  auto p = make_problem(random_points(200, 0, 1, rng), random_points(500, 0, 1, rng), 20);
  IDW<> idw;
  idw.fit(exec::seq, p);
  Points<> dX = random_points(p.num_lr(), -1, 1, rng), a(p.num_hr(), 3), b(p.num_hr(), 3);
  idw.apply(exec::seq, dX, a);
  idw.apply(exec::omp, dX, b);
  CHECK((a.array() == b.array()).all());
  Points<> wrong(3, 3);
  CHECK_THROWS_AS(idw.apply(exec::seq, wrong, a), ShapeError);
  CHECK_THROWS_AS(idw.apply(exec::seq, dX, wrong), ShapeError);
  CHECK_THROWS_AS(IDW<>(IDWOptions{.power = 0}).fit(exec::seq, p), ArgumentError);
  CHECK_THROWS_AS(IDW<>(IDWOptions{.k = 21}).fit(exec::seq, p), ArgumentError);
}

TEST_CASE("IDW on the bunny beats the rest shape") {
#ifdef SIMSR_DATA_DIR
  const std::filesystem::path dir = std::filesystem::path(SIMSR_DATA_DIR) / "bunny";
  if (!std::filesystem::exists(dir / "train_frames.npz")) {
    SIMSR_MISSING("bunny data not found in " << dir);
    return;
  }
  UpsamplingProblem<> p;
  p.lr = io::read_obj_tets(dir / "lrestshape.obj");
  p.hr = io::read_obj_triangles(dir / "hrestshape.obj");
  neighbors::UpsamplingNeighborhoods nb;
  nb.indices = io::read_npy(dir / "geo_dist_surf2tet_idx.npy").to_matrix<VIndex>().leftCols(20);
  nb.distances = io::read_npy(dir / "geo_dist_surf2tet.npy").to_matrix<double>().leftCols(20);
  p.neighborhoods = std::move(nb);
  io::NpzReader z(dir / "train_frames.npz");
  const auto lo = z.read("lowres").to_vector<double>(), hi = z.read("highres").to_vector<double>();
  const Index n = p.num_lr(), m = p.num_hr();
  IDW<> idw;
  idw.fit(exec::seq, p);
  Points<> dx(m, 3);
  double mean = 0, worst = 0, rest = 0;
  const std::vector<Index> frames{10, 100, 200, 250};
  for (const Index f : frames) {
    const Points<> dX = Eigen::Map<const Points<>>(lo.data() + f * n * 3, n, 3) - p.lr.V;
    const Points<> dH = Eigen::Map<const Points<>>(hi.data() + f * m * 3, m, 3) - p.hr.V;
    idw.apply(exec::omp, dX, dx);
    const Eigen::VectorXd e = (dx - dH).rowwise().norm();
    CHECK(e.mean() < dH.rowwise().norm().mean());
    mean += e.mean() / double(frames.size());
    worst = std::max(worst, e.maxCoeff());
    rest += dH.rowwise().norm().mean() / double(frames.size());
  }
  MESSAGE("bunny IDW (p = 2, k = 20): mean error ", mean, ", max ", worst, " (rest shape: mean ", rest, ")");
#else
  SIMSR_MISSING("SIMSR_DATA_DIR undefined");
#endif
}
