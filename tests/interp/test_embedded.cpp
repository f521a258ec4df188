#include <simsr/interp/concepts.hpp>
#include <simsr/interp/embedded.hpp>
#include <simsr/io/npz.hpp>
#include <simsr/io/obj.hpp>

#include <doctest/doctest.h>
#include "../support/require.hpp"

#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>

#include "../mesh/fixtures.hpp"

using namespace simsr;
using interp::Embedded;

static_assert(interp::assert_interpolator<Embedded<>>());
static_assert(interp::Interpolator<Embedded<float>>);
static_assert(!interp::needs_neighborhoods_v<Embedded<>>);

namespace {

/// A jittered 5-tet box mesh and random HR points around it (about a third outside).
interp::UpsamplingProblem<> box_problem(std::mt19937& rng, Index m = 600) {
  interp::UpsamplingProblem<> p;
  p.lr = test::box_tets(4, 3, 3, 1.0, Vec3<>::Zero(), true);
  test::jitter(p.lr.V, 0.1, rng);
  std::uniform_real_distribution<double> u(-0.6, 4.6);
  p.hr.V.resize(m, 3);
  for (Index i = 0; i < m; ++i) p.hr.V.row(i) << u(rng), u(rng) * 0.75, u(rng) * 0.75;
  return p;
}

}  // namespace

TEST_CASE("Embedded reproduces affine displacement fields exactly at inside and extrapolated HR points") {
  std::mt19937 rng(21);
  auto p = box_problem(rng);
  Embedded<> e;
  e.fit(exec::seq, p);
  CHECK(e.num_lr() == p.lr.num_vertices());
  CHECK(e.num_hr() == p.hr.num_vertices());
  REQUIRE(e.embedding().num_outside() > 100);
  REQUIRE(e.embedding().num_inside() > 100);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Matrix3d A = Eigen::Matrix3d::Random();
    const Eigen::RowVector3d b = Eigen::RowVector3d::Random();
    const Points<> lr_disp = (p.lr.V * A.transpose()).rowwise() + b;
    const Points<> expect = (p.hr.V * A.transpose()).rowwise() + b;
    Points<> hr_disp(p.hr.V.rows(), 3);
    e.apply(exec::seq, lr_disp, hr_disp);
    CHECK((hr_disp - expect).cwiseAbs().maxCoeff() < 1e-12);
    Points<> hr_omp(p.hr.V.rows(), 3);
    e.apply(exec::omp, lr_disp, hr_omp);
    CHECK(hr_omp == hr_disp);
  }
  // A nonlinear field is not reproduced (the test above can fail).
  Points<> lr_sq = p.lr.V.array().square().matrix();
  Points<> hr_disp(p.hr.V.rows(), 3);
  e.apply(exec::seq, lr_sq, hr_disp);
  CHECK((hr_disp - Points<>(p.hr.V.array().square().matrix())).cwiseAbs().maxCoeff() > 1e-3);
}

TEST_CASE("Embedded under omp and with clamped outside weights") {
  std::mt19937 rng(22);
  auto p = box_problem(rng);
  Embedded<> eo;
  eo.fit(exec::omp, p);
  Embedded<> es;
  es.fit(exec::seq, p);
  CHECK(eo.embedding().tet == es.embedding().tet);
  CHECK(eo.embedding().weights == es.embedding().weights);
  const Points<> lr_disp = Points<>::Random(p.lr.V.rows(), 3);
  Points<> a(p.hr.V.rows(), 3), b(p.hr.V.rows(), 3);
  eo.apply(exec::omp, lr_disp, a);
  es.apply(exec::seq, lr_disp, b);
  CHECK(a == b);
  CHECK((a - deform(exec::seq, es.embedding(), p.lr.T, lr_disp)).cwiseAbs().maxCoeff() == 0);

  EmbeddingOptions o;
  o.outside = OutsideMode::clamp;
  Embedded<> ec(o);
  ec.fit(exec::seq, p);
  // Identity displacement (= rest positions): clamped outside points land on the mesh, at `distance`.
  Points<> pos(p.hr.V.rows(), 3);
  ec.apply(exec::seq, p.lr.V, pos);
  const auto& emb = ec.embedding();
  for (Index q = 0; q < pos.rows(); ++q) {
    if (emb.inside[q])
      CHECK((pos.row(q) - p.hr.V.row(q)).norm() < 1e-12);
    else
      CHECK(std::abs((pos.row(q) - p.hr.V.row(q)).norm() - emb.distance[q]) < 1e-12);
  }
}

TEST_CASE("Embedded checks shapes and fails on bad meshes") {
  std::mt19937 rng(23);
  auto p = box_problem(rng, 50);
  Embedded<> e;
  Points<> lr(p.lr.V.rows(), 3), hr(50, 3);
  lr.setZero();
  CHECK_THROWS_AS(e.apply(exec::seq, lr, hr), ShapeError);  // not fitted
  e.fit(exec::seq, p);
  e.apply(exec::seq, lr, hr);
  CHECK(hr.cwiseAbs().maxCoeff() == 0);
  Points<> hr_short(49, 3), lr_short(p.lr.V.rows() - 1, 3);
  CHECK_THROWS_AS(e.apply(exec::seq, lr, hr_short), ShapeError);
  CHECK_THROWS_AS(e.apply(exec::seq, lr_short, hr), ShapeError);
  Eigen::MatrixXd lr2(p.lr.V.rows(), 2);
  CHECK_THROWS_AS(e.apply(exec::seq, lr2, hr), ShapeError);

  auto bad = p;
  bad.lr.T.row(3) << bad.lr.T(3, 0), bad.lr.T(3, 0), bad.lr.T(3, 1), bad.lr.T(3, 2);
  CHECK_THROWS_AS(Embedded<>{}.fit(exec::seq, bad), MeshError);
  auto nan = p;
  nan.hr.V(17, 1) = std::nan("");
  try {
    Embedded<>{}.fit(exec::seq, nan);
    FAIL("no ArgumentError");
  } catch (const ArgumentError& err) {
    CHECK(std::string(err.what()).find("point 17") != std::string::npos);
  }
}

TEST_CASE("bunny: Embedded baseline on the official paired frames") {
  const std::filesystem::path dir = std::filesystem::path(SIMSR_DATA_DIR) / "bunny";
  if (!std::filesystem::exists(dir / "train_frames.npz")) {
    SIMSR_MISSING("bunny data not found under " << dir.string());
    return;
  }
  interp::UpsamplingProblem<> p{io::read_obj_tets(dir / "lrestshape.obj"), io::read_obj_triangles(dir / "hrestshape.obj"), {}, {}};
  REQUIRE(p.lr.num_tets() == 4896);
  REQUIRE(p.hr.num_vertices() == 2503);
  Embedded<> e;
  e.fit(exec::omp, p);
  const auto& emb = e.embedding();
  const double h = 0.0125;  // lattice spacing of the LR mesh (data README)
  const double diag = (p.hr.V.colwise().maxCoeff() - p.hr.V.colwise().minCoeff()).norm();
  MESSAGE("bunny embedding: " << emb.num_inside() << " HR vertices inside, " << emb.num_outside()
                              << " outside, max outside distance " << emb.max_distance() << " (" << emb.max_distance() / h
                              << " lattice spacings)");
  // The lattice keeps every cell overlapping the volume: no surface point is half a cell away from it.
  CHECK(emb.max_distance() < h / 2);
  CHECK(emb.num_inside() + emb.num_outside() == 2503);

  // Defining property on the real meshes, outside vertices included: affine LR fields → the same field on HR.
  const Eigen::Matrix3d A = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix() * 1.3 -
                            Eigen::Matrix3d::Identity();
  const Eigen::RowVector3d b(0.01, -0.02, 0.03);
  Points<> hr_disp(p.hr.V.rows(), 3);
  e.apply(exec::omp, Points<>((p.lr.V * A.transpose()).rowwise() + b), hr_disp);
  CHECK((hr_disp - (Points<>((p.hr.V * A.transpose()).rowwise() + b))).cwiseAbs().maxCoeff() < 1e-12 * diag);

  const io::NpzArrays z = io::read_npz(dir / "train_frames.npz");
  const auto& low = z.at("lowres");
  const auto& high = z.at("highres");
  REQUIRE(low.num_frames() == high.num_frames());
  double sum_emb = 0, sum_rest = 0, worst_ratio = 0, worst_max = 0;
  Index frames_beaten = 0;
  std::ostringstream table;
  for (Index f = 0; f < low.num_frames(); ++f) {
    const Points<> lf = low.frame_points(f), hf = high.frame_points(f);
    e.apply(exec::omp, Points<>(lf - p.lr.V), hr_disp);
    const VecX<> err = (p.hr.V + hr_disp - hf).rowwise().norm() / diag;
    const VecX<> rest = (p.hr.V - hf).rowwise().norm() / diag;
    sum_emb += err.mean();
    sum_rest += rest.mean();
    worst_ratio = std::max(worst_ratio, err.mean() / rest.mean());
    worst_max = std::max(worst_max, err.maxCoeff());
    if (err.mean() < rest.mean() && err.maxCoeff() < rest.maxCoeff()) ++frames_beaten;
    if (f % 32 == 0)
      table << "\n  frame " << f << ": Embedded mean " << err.mean() << " max " << err.maxCoeff() << " | HR at rest mean "
            << rest.mean() << " max " << rest.maxCoeff();
  }
  const Index nf = low.num_frames();
  MESSAGE("bunny Embedded error / bbox diagonal (" << diag << "), every 32nd frame:" << table.str()
                                                   << "\n  all " << nf << " frames: mean Embedded " << sum_emb / nf
                                                   << ", mean HR-at-rest " << sum_rest / nf << ", ratio " << sum_emb / sum_rest
                                                   << ", worst per-frame ratio " << worst_ratio << ", worst vertex " << worst_max);
  // Embedded carries the LR motion, so it beats "HR stays at rest" in mean and max on every frame,
  // and explains at least half of the motion over the whole sequence; what remains is the LR/HR
  // simulation discrepancy that the learned methods target.
  CHECK(frames_beaten == nf);
  CHECK(sum_emb < 0.5 * sum_rest);
}

TEST_CASE("Embedded::apply's body over MatrixSpan (the accessor DeviceEmbedded gives it on a device) equals apply, bitwise, under seq and omp") {
  std::mt19937 rng(29);
  auto p = box_problem(rng, 900);
  Embedded<> e;
  e.fit(exec::omp, p);
  Points<> lr(p.lr.num_vertices(), 3), ref(e.num_hr(), 3), seq(e.num_hr(), 3), omp(e.num_hr(), 3);
  std::normal_distribution<double> N;
  for (Index i = 0; i < lr.size(); ++i) lr.data()[i] = N(rng);
  e.apply(exec::seq, lr, ref);
  using Body = interp::detail::EmbeddedApply<double, MatrixSpan<const double>, MatrixSpan<double>>;
  const MatrixSpan<const double> in{lr.data(), lr.rows(), 3, 3};
  exec::parallel_for(exec::seq, e.num_hr(), Body{e.embedding().weights.data(), e.lr_vertex_ids().data(), in, MatrixSpan<double>{seq.data(), seq.rows(), 3, 3}});
  exec::parallel_for(exec::omp, e.num_hr(), Body{e.embedding().weights.data(), e.lr_vertex_ids().data(), in, MatrixSpan<double>{omp.data(), omp.rows(), 3, 3}});
  CHECK(seq == ref);
  CHECK(omp == ref);
}
