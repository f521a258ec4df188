#include <doctest/doctest.h>

#include <simsr/mesh/generators.hpp>
#include <simsr/shell/ts_acap.hpp>

#include <algorithm>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>

#include "../support/error_of.hpp"

namespace shell_test_ts_acap {

using namespace simsr;
using namespace simsr::shell;
constexpr double pi = std::numbers::pi;

namespace {

/// The Poisson energy the decoder minimizes, Σ_i Σ_j w_ij ‖(p_i − p_j) − T_i (q_i − q_j)‖².
double poisson_energy(const TsAcap<double>& acap, const std::vector<Mat3<>>& T, const Points<>& p) {
  const Adjacency& A = acap.fit().adjacency();
  const Points<>& q = acap.fit().rest();
  double E = 0;
  for (Index i = 0; i < p.rows(); ++i)
    for (Index k = A.offsets[i]; k < A.offsets[i + 1]; ++k) {
      const Index j = A.neighbors[k];
      E += acap.fit().weights()[k] *
           (Vec3<>(p.row(i) - p.row(j)) - T[i] * Vec3<>(q.row(i) - q.row(j))).squaredNorm();
    }
  return E;
}

Vec3<> centroid(const Points<>& V) { return V.colwise().mean().transpose(); }

TsAcapFeatures<double> rest_features_of(const TsAcap<double>& acap) {
  TsAcapFeatures<double> f = TsAcapFeatures<double>::Zero(acap.num_vertices(), 9);
  f.col(3).setOnes(), f.col(6).setOnes(), f.col(8).setOnes();
  return f;
}

/// A sheet rolled (isometrically, as cloth bends) around an axis along y with curvature κ, then
/// turned by `spin` about a tilted axis.
Points<> roll(const Points<>& X, double kappa, double spin) {
  const Mat3<> R = Eigen::AngleAxisd(spin, Vec3<>(0.2, 1.0, 0.4).normalized()).toRotationMatrix();
  Points<> V(X.rows(), 3);
  for (Index i = 0; i < X.rows(); ++i) {
    const double x = X(i, 0), y = X(i, 1);
    const Vec3<> p = kappa > 1e-12 ? Vec3<>(std::sin(kappa * x) / kappa, y, (1 - std::cos(kappa * x)) / kappa) : Vec3<>(x, y, 0);
    V.row(i) = (R * p).transpose();
  }
  return V;
}

/// Encodes roll(κ = 0.2·t, spin = 0.22·t) for t = 0, 1/sub, …, 20 on a cells×cells sheet.
/// Returns the largest change of any feature between consecutive frames; `decode_error` gets the
/// largest distance of a decoded vertex from its input (at integer t), `max_angle` the largest |Φ|.
double roll_sequence(int cells, int sub, double& decode_error, double& max_angle) {
  const TriMesh<> m = square_sheet(1.0, cells);
  const TsAcap<double> acap(exec::seq, m.V, m.F);
  TsAcapState<double> state;
  TsAcapFeatures<double> previous;
  double jump = 0;
  decode_error = max_angle = 0;
  for (int k = 0; k <= 20 * sub; ++k) {
    const Points<> V = roll(m.V, 0.2 * k / sub, 0.22 * k / sub);
    const TsAcapFeatures<double> f = acap.encode(exec::seq, V, state);
    max_angle = std::max(max_angle, state.angle.cwiseAbs().maxCoeff());
    if (k % sub == 0)
      decode_error = std::max(decode_error, (acap.decode(exec::seq, f, centroid(V)) - V).rowwise().norm().maxCoeff());
    if (k > 0) jump = std::max(jump, (f - previous).cwiseAbs().maxCoeff());
    previous = f;
  }
  return jump;
}

}  // namespace

TEST_CASE("TsAcap: the rest frame's features are [0 0 0, 1 0 0 1 0 1]") {
  const TriMesh<> m = square_sheet(1.0, 8);
  const TsAcap<double> acap(exec::seq, m.V, m.F);
  TsAcapState<double> state;
  const TsAcapFeatures<double> f = acap.encode(exec::seq, m.V, state);
  Eigen::Matrix<double, 1, 9> rest;
  rest << 0, 0, 0, 1, 0, 0, 1, 0, 1;
  for (Index i = 0; i < f.rows(); ++i) CHECK((f.row(i) - rest).norm() < 1e-12);
}

TEST_CASE("TsAcap: a sheet spinning through 3.3 turns keeps continuous rotation vectors and round-trips to 1e-8") {
  const TriMesh<> m = square_sheet(1.0, 8);
  const TsAcap<double> acap(exec::seq, m.V, m.F);
  const Vec3<> axis = Vec3<>(0.3, -0.5, 1.0).normalized();
  TsAcapState<double> state;
  for (int k = 0; k <= 60; ++k) {
    const double angle = 0.35 * k, scale = 1 + 0.01 * k;  // up to 21 rad
    const Mat3<> R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    Points<> V = (scale * m.V * R.transpose()).eval();
    V.rowwise() += Eigen::RowVector3d(0.1 * k, -0.2 * k, 3.0);
    TsAcapFrameReport report;
    const TsAcapFeatures<double> f = acap.encode(exec::seq, V, state, &report);
    for (Index i = 0; i < f.rows(); ++i) {
      CHECK((f.row(i).head<3>().transpose() - angle * axis).norm() < 1e-9);  // the unwrapped angle, not mod 2π
      CHECK(f(i, 3) == doctest::Approx(scale).epsilon(1e-10));
    }
    const Points<> back = acap.decode(exec::seq, f, centroid(V));
    CHECK((back - V).cwiseAbs().maxCoeff() < 1e-8);
  }
}

TEST_CASE("TsAcap: decoding returns the least-squares positions of the fitted gradients (energy checks)") {
  const TriMesh<> m = square_sheet(1.0, 10);
  const TsAcap<double> acap(exec::seq, m.V, m.F);
  TsAcapState<double> state, state_omp;
  for (int k = 0; k <= 20; k += 4) {
    const Points<> V = roll(m.V, 0.2 * k, 0.22 * k);
    const TsAcapFeatures<double> f = acap.encode(exec::seq, V, state);
    CHECK(f == acap.encode(exec::omp, V, state_omp));  // seq and omp bitwise equal
    const Points<> back = acap.decode(exec::omp, f, centroid(V));
    const std::vector<Mat3<>> T = acap.gradients_from_features(exec::seq, f);
    // the decoded positions minimize the Poisson energy: no higher than at the input positions
    // (one feasible answer) and stationary (no random single-vertex move lowers it)
    const double E = poisson_energy(acap, T, back);
    CHECK(E <= poisson_energy(acap, T, V) * (1 + 1e-12) + 1e-15);
    std::mt19937 rng(k);
    std::normal_distribution<double> g;
    for (int t = 0; t < 5; ++t) {
      Points<> moved = back;
      moved.row(rng() % moved.rows()) += 1e-4 * Eigen::RowVector3d(g(rng), g(rng), g(rng));
      CHECK(poisson_energy(acap, T, moved) >= E);
    }
    CHECK((centroid(back) - centroid(V)).norm() < 1e-12);
  }
}

TEST_CASE("TsAcap: anchored decoding is the least-squares answer with the anchors fixed (a dense solve of the residuals)") {
  const TriMesh<> m = square_sheet(1.0, 5);  // 36 vertices
  TsAcap<double> acap(exec::seq, m.V, m.F);
  const Adjacency& A = acap.fit().adjacency();
  const Points<>& q = acap.fit().rest();
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 12; ++trial) {
    // a random anchor set of 1-5 distinct vertices
    std::vector<VIndex> all(static_cast<std::size_t>(m.V.rows()));
    std::iota(all.begin(), all.end(), VIndex(0));
    std::shuffle(all.begin(), all.end(), rng);
    const Index na = 1 + trial % 5;
    IndexVector anchors(na);
    for (Index a = 0; a < na; ++a) anchors[a] = all[std::size_t(a)];
    acap.set_anchors(anchors);
    // a rolled, turned and randomly perturbed frame (not a similarity: the fit is inexact)
    Points<> V = roll(m.V, 0.3 * trial, 0.5 * trial);
    for (Index i = 0; i < V.rows(); ++i) V.row(i) += 0.01 * Eigen::RowVector3d(g(rng), g(rng), g(rng));
    TsAcapState<double> state;
    const TsAcapFeatures<double> f = acap.encode(exec::seq, V, state);
    Points<> at(na, 3);
    for (Index a = 0; a < na; ++a) at.row(a) = V.row(anchors[a]) + 0.05 * Eigen::RowVector3d(g(rng), g(rng), g(rng));
    const Points<> p = acap.decode_anchored(exec::omp, f, at);
    for (Index a = 0; a < na; ++a) CHECK(p.row(anchors[a]) == at.row(a));
    // the reference: every residual √w_ij ((p_i − p_j) − T_i (q_i − q_j)) as a row of a dense
    // least-squares problem in the free vertices' coordinates, solved by QR
    const std::vector<Mat3<>> T = acap.gradients_from_features(exec::seq, f);
    std::vector<Index> col(std::size_t(m.V.rows()), -1);
    Index nf = 0;
    for (Index i = 0; i < m.V.rows(); ++i)
      if ((anchors.array() != VIndex(i)).all()) col[std::size_t(i)] = nf++;
    Eigen::MatrixXd L = Eigen::MatrixXd::Zero(Index(A.neighbors.size()), nf);
    Eigen::MatrixXd r(Index(A.neighbors.size()), 3);
    for (Index i = 0; i < m.V.rows(); ++i)
      for (Index k = A.offsets[i]; k < A.offsets[i + 1]; ++k) {
        const Index j = A.neighbors[k];
        const double s = std::sqrt(acap.fit().weights()[k]);
        Eigen::RowVector3d rhs = s * (T[std::size_t(i)] * Vec3<>(q.row(i) - q.row(j))).transpose();
        auto place = [&](Index v, double sign) {
          if (col[std::size_t(v)] >= 0) L(k, col[std::size_t(v)]) += sign * s;
          else for (Index a = 0; a < na; ++a) if (anchors[a] == v) rhs -= sign * s * at.row(a);
        };
        place(i, 1), place(j, -1);
        r.row(k) = rhs;
      }
    const Eigen::MatrixXd x = L.colPivHouseholderQr().solve(r);
    double worst = 0;
    for (Index i = 0; i < m.V.rows(); ++i)
      if (col[std::size_t(i)] >= 0) worst = std::max(worst, (p.row(i) - x.row(col[std::size_t(i)])).norm());
    CHECK(worst < 1e-10);
  }
  // a rigid motion with its anchors where the motion puts them decodes exactly
  const Mat3<> R = Eigen::AngleAxisd(2.5, Vec3<>(1, 2, 3).normalized()).toRotationMatrix();
  Points<> V = (m.V * R.transpose()).rowwise() + Eigen::RowVector3d(0.3, -1, 2);
  IndexVector corners(2);
  corners << 0, VIndex(m.V.rows() - 1);
  acap.set_anchors(corners);
  TsAcapState<double> state;
  Points<> at(2, 3);
  at << V.row(0), V.row(m.V.rows() - 1);
  CHECK((acap.decode_anchored(exec::seq, acap.encode(exec::seq, V, state), at) - V).cwiseAbs().maxCoeff() < 1e-12);
  // bad anchors are typed errors
  CHECK(!test::typed_error_of<MeshError>([&] { acap.set_anchors(IndexVector::Constant(1, VIndex(m.V.rows()))); }).empty());
  CHECK(!test::typed_error_of<MeshError>([&] { acap.set_anchors(IndexVector::Constant(2, VIndex(3))); }).empty());
  CHECK(!test::typed_error_of<ShapeError>([&] { acap.decode_anchored(exec::seq, rest_features_of(acap), Points<>::Zero(3, 3)); }).empty());
  const TsAcap<double> fresh(exec::seq, m.V, m.F);
  CHECK(!test::typed_error_of<ArgumentError>([&] { fresh.decode_anchored(exec::seq, rest_features_of(fresh), at); }).empty());
}

TEST_CASE("TsAcap: a rolling, turning sheet: features continuous in time past π, decoding error O(h²)") {
  double e6 = 0, e12 = 0, e24 = 0, angle = 0;
  const double jump = roll_sequence(12, 1, e12, angle);
  const double jump_fine = roll_sequence(12, 4, e12, angle);
  roll_sequence(6, 1, e6, angle);
  roll_sequence(24, 1, e24, angle);
  MESSAGE("rolling sheet: largest |angle| " << angle << " rad; largest feature change per frame " << jump << " (step 1), "
                                            << jump_fine << " (step 1/4); worst decoded vertex off by " << e6 << " / " << e12
                                            << " / " << e24 << " at 6 / 12 / 24 cells");
  CHECK(angle > 4.0);                      // well past π: the unwrapping is exercised
  CHECK(jump_fine < 0.3 * jump);           // a 4× finer step changes the features 4× less: no 2π jumps
  CHECK(e6 / e12 > 3.0);                   // the fit's error is the discretization's, halving with h²
  CHECK(e12 / e24 > 3.0);
  CHECK(e24 < 0.003);
}

TEST_CASE("TsAcap: bad input is a typed error") {
  TriMesh<> two = square_sheet(1.0, 2);
  const Index n = two.V.rows();
  Points<> V2(2 * n, 3);
  V2 << two.V, two.V.rowwise() + Eigen::RowVector3d(5, 0, 0);
  Tris F2(2 * two.F.rows(), 3);
  F2 << two.F, two.F.array() + VIndex(n);
  CHECK(test::typed_error_of<MeshError>([&] { TsAcap<double>(exec::seq, V2, F2); }).find("connected") != std::string::npos);
  const TsAcap<double> acap(exec::seq, two.V, two.F);
  TsAcapFeatures<double> f = TsAcapFeatures<double>::Zero(n - 1, 9);
  CHECK(!test::typed_error_of<ShapeError>([&] { acap.decode(exec::seq, f, Vec3<>::Zero()); }).empty());
  f = TsAcapFeatures<double>::Zero(n, 9);
  f(2, 4) = std::nan("");
  CHECK(!test::typed_error_of<ArgumentError>([&] { acap.decode(exec::seq, f, Vec3<>::Zero()); }).empty());
  TsAcapState<double> state;
  state.axis = Points<>::Zero(3, 3);
  state.angle = VecX<>::Zero(3);
  state.principal_angle = VecX<>::Zero(3);
  CHECK(!test::typed_error_of<ShapeError>([&] { acap.encode(exec::seq, two.V, state); }).empty());
}

}  // namespace shell_test_ts_acap

namespace shell_test_ts_acap {

TEST_CASE("lift_rotations_toward: the same rotations, each the form nearest the reference's (brute force over the forms)") {
  std::mt19937_64 rng(77);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> angle(-4 * pi, 4 * pi), noise(0, 0.6);
  std::uniform_int_distribution<int> cycles(-3, 3);
  auto rotation = [](const Vec3<>& rho) {
    const double t = rho.norm();
    return t > 0 ? Mat3<>(Eigen::AngleAxisd(t, rho / t).toRotationMatrix()) : Mat3<>(Mat3<>::Identity());
  };
  const Index n = 400;
  TsAcapFeatures<double> f(n, 9), ref(n, 9);
  for (Index i = 0; i < n; ++i) {
    const Vec3<> u = Vec3<>(g(rng), g(rng), g(rng)).normalized();
    const double t = i % 40 == 0 ? 0.0 : angle(rng);  // a few identities
    f.row(i).head<3>() = (u * t).transpose();
    for (int c = 3; c < 9; ++c) f(i, c) = g(rng);
    // the reference: the same rotation's form k cycles away, turned a little (a nearby rotation),
    // or, every fifth vertex, anything at all
    const Vec3<> w = Vec3<>(g(rng), g(rng), g(rng)).normalized();
    const Vec3<> near = (u * (t + 2 * pi * cycles(rng))) + noise(rng) * w;
    ref.row(i).head<3>() = (i % 5 == 0 ? Vec3<>(angle(rng) * w) : near).transpose();
    for (int c = 3; c < 9; ++c) ref(i, c) = g(rng);
  }
  TsAcapFeatures<double> lifted = f;
  const Index moved = lift_rotations_toward(lifted, ref);
  CHECK(moved > n / 2);
  CHECK(lifted.rightCols<6>() == f.rightCols<6>());
  Index checked = 0;
  for (Index i = 0; i < n; ++i) {
    INFO("vertex " << i);
    const Vec3<> rho = f.row(i).head<3>().transpose(), out = lifted.row(i).head<3>().transpose(), r = ref.row(i).head<3>().transpose();
    CHECK((rotation(out) - rotation(rho)).cwiseAbs().maxCoeff() < 1e-12);
    // every form of the rotation: u(t + 2πk) (a negative factor is the opposite axis); for the
    // identity any u, and the nearest form lies along r
    const double t = rho.norm();
    const Vec3<> u = t > 0 ? Vec3<>(rho / t) : r.normalized();
    double best = 1e300;
    for (int k = -8; k <= 8; ++k) best = std::min(best, (u * (t + 2 * pi * k) - r).norm());
    CHECK((out - r).norm() <= best + 1e-12);
    ++checked;
  }
  CHECK(checked == n);
  // nothing to move the second time
  TsAcapFeatures<double> again = lifted;
  CHECK(lift_rotations_toward(again, ref) == 0);
  CHECK(again == lifted);
  CHECK_THROWS_AS(lift_rotations_toward(lifted, TsAcapFeatures<double>(n - 1, 9)), ShapeError);
  TsAcapFeatures<double> bad = ref;
  bad(3, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(lift_rotations_toward(lifted, bad), ArgumentError);
}

}  // namespace shell_test_ts_acap
