#include <simsr/mesh/generators.hpp>

#include <array>
#include <vector>

#include "gradient_check.hpp"

using namespace simsr;
using nn::Matrix;
using test::random_matrix;

namespace {

using Ld = long double;
using L3 = std::array<Ld, 3>;

L3 cross(const L3& u, const L3& v) { return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]}; }
Ld dot(const L3& u, const L3& v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; }

/// Plain-loop reference in long double: the loss (torch 1.13's clamped cosine, see the header) and
/// its gradient w.r.t. pred, scattered corner by corner.
struct NormalLossReference {
  Ld loss = 0;
  std::vector<Ld> grad;
};
template <class S>
NormalLossReference normal_loss_reference(const Matrix<double>& rest, const Tris& F, const Matrix<S>& P, const Matrix<S>& T, bool mean, Ld scale = 1,
                    Ld eps = 1e-8L) {
  const Index M = rest.rows(), B = P.rows() / M;
  NormalLossReference out;
  out.grad.assign(std::size_t(P.size()), 0);
  const Ld norm = mean ? Ld(B * F.rows()) : 1;
  for (Index b = 0; b < B; ++b)
    for (Index t = 0; t < F.rows(); ++t) {
      std::array<L3, 3> p, q;
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j) {
          const Index v = F(t, k);
          p[k][j] = Ld(rest(v, j)) + Ld(P(b * M + v, j));
          q[k][j] = Ld(rest(v, j)) + Ld(T(b * M + v, j));
        }
      auto normal = [](const std::array<L3, 3>& x) {
        return cross({x[1][0] - x[0][0], x[1][1] - x[0][1], x[1][2] - x[0][2]}, {x[2][0] - x[0][0], x[2][1] - x[0][1], x[2][2] - x[0][2]});
      };
      const L3 x = normal(p), y = normal(q);
      const Ld nx = std::sqrt(std::max(dot(x, x), eps * eps)), ny = std::sqrt(std::max(dot(y, y), eps * eps));
      const Ld c = dot(x, y) / (nx * ny);
      out.loss += (1 - c) / norm;
      L3 g;
      for (int j = 0; j < 3; ++j) g[j] = scale / norm * (c * x[j] / (nx * nx) - y[j] / (nx * ny));
      for (int k = 0; k < 3; ++k) {
        const L3 e = {p[(k + 2) % 3][0] - p[(k + 1) % 3][0], p[(k + 2) % 3][1] - p[(k + 1) % 3][1], p[(k + 2) % 3][2] - p[(k + 1) % 3][2]};
        const L3 d = cross(g, e);
        for (int j = 0; j < 3; ++j) out.grad[std::size_t((b * M + F(t, k)) * 3 + j)] += d[j];
      }
    }
  return out;
}

/// max |a − b| / max |b|
double rel_error(const Matrix<double>& a, const std::vector<Ld>& b) {
  double diff = 0, s = 0;
  for (Index i = 0; i < a.size(); ++i) {
    diff = std::max(diff, double(std::abs(Ld(a.data()[i]) - b[std::size_t(i)])));
    s = std::max(s, double(std::abs(b[std::size_t(i)])));
  }
  return s > 0 ? diff / s : diff;
}

/// Central differences of loss(P) against the analytic gradient (max-norm relative error).
double fd_error(nn::FaceNormalLoss<double>& loss, const Matrix<double>& P, const Matrix<double>& T, double scale, double h = 1e-6) {
  Matrix<double> d;
  loss.value_and_gradient(exec::seq, P, T, &d, scale);
  Matrix<double> x = P;
  double diff = 0, s = 0;
  for (Index i = 0; i < x.size(); ++i) {
    const double v = x.data()[i];
    x.data()[i] = v + h;
    const double lp = loss.value_and_gradient(exec::seq, x, T);
    x.data()[i] = v - h;
    const double lm = loss.value_and_gradient(exec::seq, x, T);
    x.data()[i] = v;
    const double num = scale * (lp - lm) / (2 * h);
    diff = std::max(diff, std::abs(num - d.data()[i]));
    s = std::max({s, std::abs(num), std::abs(d.data()[i])});
  }
  CHECK(s > 0);
  return diff / s;
}

Matrix<double> as_matrix(const Points<double>& V) { return V; }

}  // namespace

TEST_CASE("nn::FaceNormalLoss: value and gradient against a long-double reference and finite differences, B = 1 and 3") {
  std::mt19937_64 rng(501);
  const TriMesh<double> sphere = icosphere<double>(1);  // 42 vertices, 80 triangles
  const Matrix<double> rest = as_matrix(sphere.V);
  const Index M = rest.rows();
  for (const Index B : {Index(1), Index(3)})
    for (const auto reduction : {nn::Reduction::mean, nn::Reduction::sum}) {
      CAPTURE(B);
      const bool mean = reduction == nn::Reduction::mean;
      CAPTURE(mean);
      nn::FaceNormalLoss<double> loss(sphere.V, sphere.F, reduction);
      const Matrix<double> P = random_matrix(rng, B * M, 3, -0.08, 0.08), T = random_matrix(rng, B * M, 3, -0.08, 0.08);
      Matrix<double> d;
      const double l = loss.value_and_gradient(exec::seq, P, T, &d, 2.5);
      const NormalLossReference ref = normal_loss_reference(rest, sphere.F, P, T, mean, 2.5L);
      CHECK(l == doctest::Approx(double(ref.loss)).epsilon(1e-13));
      CHECK(l > 0);
      CHECK(rel_error(d, ref.grad) < 1e-12);
      CHECK(fd_error(loss, P, T, 2.5) < 1e-6);
      // mean = sum / (B·F)
      nn::FaceNormalLoss<double> other(sphere.V, sphere.F, mean ? nn::Reduction::sum : nn::Reduction::mean);
      const double lo = other.value_and_gradient(exec::seq, P, T);
      CHECK((mean ? lo / double(B * sphere.F.rows()) : lo * double(B * sphere.F.rows())) == doctest::Approx(l).epsilon(1e-13));
      // identical prediction and target: zero loss, zero gradient
      CHECK(loss.value_and_gradient(exec::seq, T, T, &d) == doctest::Approx(0.0).scale(1.0).epsilon(1e-14));
      CHECK(d.cwiseAbs().maxCoeff() < 1e-12);
    }
}

TEST_CASE("nn::FaceNormalLoss: random triangles (shared vertices, all orientations) against finite differences") {
  std::mt19937_64 rng(502);
  const Index M = 12, F = 30;
  const Matrix<double> rest = random_matrix(rng, M, 3);
  std::uniform_int_distribution<int> pick(0, int(M) - 1);
  Tris faces(F, 3);
  for (Index t = 0; t < F; ++t) {
    int a = pick(rng), b = pick(rng), c = pick(rng);
    while (b == a) b = pick(rng);
    while (c == a || c == b) c = pick(rng);
    faces.row(t) << a, b, c;
  }
  nn::FaceNormalLoss<double> loss(rest, faces, nn::Reduction::sum);
  const Matrix<double> P = random_matrix(rng, 2 * M, 3, -0.2, 0.2), T = random_matrix(rng, 2 * M, 3, -0.2, 0.2);
  Matrix<double> d;
  const double l = loss.value_and_gradient(exec::seq, P, T, &d, -0.7);
  const NormalLossReference ref = normal_loss_reference(rest, faces, P, T, false, -0.7L);
  CHECK(l == doctest::Approx(double(ref.loss)).epsilon(1e-13));
  CHECK(rel_error(d, ref.grad) < 1e-12);
  CHECK(fd_error(loss, P, T, -0.7) < 1e-6);
}

TEST_CASE("nn::FaceNormalLoss: a triangle rotated by θ costs 1 − cos θ") {
  Matrix<double> rest(3, 3);
  rest << 0, 0, 0, 1, 0, 0, 0.3, 0.8, 0;
  Tris faces(1, 3);
  faces << 0, 1, 2;
  nn::FaceNormalLoss<double> loss(rest, faces);
  for (const double theta : {0.0, 0.1, 0.7, 1.5, 2.0, 3.0}) {
    CAPTURE(theta);
    // rotation about the x axis, plus a translation (a rigid motion keeps |n|, turns n by θ)
    const Eigen::Matrix3d R = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitX()).toRotationMatrix();
    Matrix<double> P(3, 3);
    for (Index v = 0; v < 3; ++v) P.row(v) = (R * rest.row(v).transpose() - rest.row(v).transpose() + Eigen::Vector3d(0.2, -1, 3)).transpose();
    const Matrix<double> T = Matrix<double>::Zero(3, 3);
    CHECK(loss.value_and_gradient(exec::seq, P, T) == doctest::Approx(1 - std::cos(theta)).epsilon(1e-14).scale(1.0));
  }
  // B = 2 items rotated by different angles about an in-plane axis (⟂ n): the mean of both terms
  const double a = 0.4, b = 1.1;
  Matrix<double> P(6, 3);
  for (Index item = 0; item < 2; ++item) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(item ? b : a, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix();
    for (Index v = 0; v < 3; ++v) P.row(item * 3 + v) = (R * rest.row(v).transpose() - rest.row(v).transpose()).transpose();
  }
  CHECK(loss.value_and_gradient(exec::seq, P, Matrix<double>::Zero(6, 3)) == doctest::Approx((2 - std::cos(a) - std::cos(b)) / 2).epsilon(1e-14));
}

TEST_CASE("nn::FaceNormalLoss: degenerate normals mirror torch 1.13's cosine_similarity (eps = 1e-8)") {
  // Values printed by torch 1.13 (float64): (1 − F.cosine_similarity(cross(Pb−Pa, Pc−Pa), target
  // normals, dim=1, eps=1e-8)).mean() and its .backward() w.r.t. the displacements.
  Matrix<double> rest(3, 3);
  rest << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  Tris faces(1, 3);
  faces << 0, 1, 2;
  nn::FaceNormalLoss<double> loss(rest, faces);
  const Matrix<double> zero = Matrix<double>::Zero(3, 3);
  auto check = [&](const Matrix<double>& P, const Matrix<double>& T, double expected_loss, const Matrix<double>& expected_grad) {
    Matrix<double> d;
    CHECK(loss.value_and_gradient(exec::seq, P, T, &d) == doctest::Approx(expected_loss).epsilon(1e-12));
    for (Index i = 0; i < d.size(); ++i) {
      CAPTURE(i);
      CHECK(d.data()[i] == doctest::Approx(expected_grad.data()[i]).epsilon(1e-9).scale(1e-6));
    }
  };
  Matrix<double> P(3, 3), G(3, 3);
  // predicted triangle collapsed (c onto a): cos = 0, gradient −n̂_true/eps through the cross product
  P << 0, 0, 0, 0, 0, 0, 0, -1, 0;
  G << 0, 1e8, 0, 0, 0, 0, 0, -1e8, 0;
  check(P, zero, 1.0, G);
  // |n_pred| = 3e-9 < eps: cos = 0.3 (the norm is clamped alone) and torch's gradient 0.91e8, not 1e8
  P << 0, 0, 0, 0, 0, 0, 0, -1 + 3e-9, 0;
  G << 0.2730000019108851, 90999999.84294096, 0, -0.2730000019108851, 0, 0, 0, -90999999.84294096, 0;
  check(P, zero, 0.6999999973823492, G);
  P << 0, 0, 0, 0, 0, 0, 0, -1 + 3e-9, 2e-9;
  G << 0.26100000180617905, 90999999.84294096, -6000000.052353016, -0.26100000180617905, 0, 0, 0, -90999999.84294096, 6000000.052353016;
  check(P, zero, 0.6999999973823492, G);
  // target triangle collapsed: a constant term 1, no gradient
  Matrix<double> T(3, 3);
  T << 0, 0, 0, 0, 0, 0, 0, -1, 0;
  check(zero, T, 1.0, Matrix<double>::Zero(3, 3));
}

TEST_CASE("nn::FaceNormalLoss: seq == omp bitwise; warm calls allocate nothing") {
  std::mt19937_64 rng(503);
  const TriMesh<float> sphere = icosphere<float>(3);  // 642 vertices, 1280 triangles
  const Index M = sphere.V.rows(), B = 4;
  nn::FaceNormalLoss<float> loss(sphere.V, sphere.F);
  const Matrix<float> P = random_matrix(rng, B * M, 3, -0.02, 0.02).cast<float>(), T = random_matrix(rng, B * M, 3, -0.02, 0.02).cast<float>();
  Matrix<float> d1, d2;
  const double l1 = loss.value_and_gradient(exec::seq, P, T, &d1, 3.0), l2 = loss.value_and_gradient(exec::omp, P, T, &d2, 3.0);
  CHECK(l1 == l2);
  CHECK(test::bitwise_equal(d1, d2));
  CHECK(d1.cwiseAbs().maxCoeff() > 0);
  for (int policy = 0; policy < 2; ++policy) {
    const float* ptr = d1.data();
    const long before = simsr_test_malloc_count();
    const double l = policy ? loss.value_and_gradient(exec::omp, P, T, &d1, 3.0) : loss.value_and_gradient(exec::seq, P, T, &d1, 3.0);
    const double v = policy ? loss.value_and_gradient(exec::omp, P, T) : loss.value_and_gradient(exec::seq, P, T);
    const long allocations = simsr_test_malloc_count() - before;
    if (policy)
      SIMSR_CHECK_NO_ALLOCATION(exec::omp, allocations);
    else
      SIMSR_CHECK_NO_ALLOCATION(exec::seq, allocations);
    CHECK(d1.data() == ptr);
    CHECK(l == l1);
    CHECK(v == l1);
  }
  CHECK(test::bitwise_equal(d1, d2));
}

TEST_CASE("nn::FaceNormalLoss: errors name the array or the triangle") {
  Matrix<double> rest(4, 3);
  rest.setRandom();
  Tris faces(2, 3);
  faces << 0, 1, 2, 1, 3, 2;
  nn::FaceNormalLoss<double> loss(rest, faces);
  CHECK(loss.vertices() == 4);
  CHECK(loss.triangles() == 2);
  Matrix<double> P = Matrix<double>::Zero(8, 3), d;
  CHECK_THROWS_AS(loss.value_and_gradient(exec::seq, Matrix<double>::Zero(7, 3), Matrix<double>::Zero(7, 3)), ShapeError);
  CHECK_THROWS_AS(loss.value_and_gradient(exec::seq, Matrix<double>::Zero(8, 2), Matrix<double>::Zero(8, 2)), ShapeError);
  CHECK_THROWS_AS(loss.value_and_gradient(exec::seq, Matrix<double>::Zero(0, 3), Matrix<double>::Zero(0, 3)), ShapeError);
  CHECK_THROWS_AS(loss.value_and_gradient(exec::seq, P, Matrix<double>::Zero(4, 3)), ShapeError);
  CHECK_THROWS_AS(loss.value_and_gradient(exec::seq, P, P, &P), ArgumentError);
  CHECK_THROWS_AS(nn::FaceNormalLoss<double>(Matrix<double>::Zero(4, 2), faces), ShapeError);
  CHECK_THROWS_AS(nn::FaceNormalLoss<double>(rest, Tris(0, 3)), ArgumentError);
  CHECK_THROWS_AS(nn::FaceNormalLoss<double>(rest, faces, nn::Reduction::mean, 0.0), ArgumentError);
  Tris bad = faces;
  bad(1, 2) = 4;
  try {
    nn::FaceNormalLoss<double> b(rest, bad);
    FAIL("expected ArgumentError");
  } catch (const ArgumentError& e) {
    CHECK(std::string(e.what()).find("triangle 1") != std::string::npos);
    CHECK(std::string(e.what()).find("vertex 4") != std::string::npos);
  }
  bad(1, 2) = -1;
  CHECK_THROWS_AS(nn::FaceNormalLoss<double>(rest, bad), ArgumentError);
  // any integer matrix for the faces
  Eigen::Matrix<long, Eigen::Dynamic, Eigen::Dynamic> wide = faces.cast<long>();
  nn::FaceNormalLoss<double> from_long(rest, wide);
  CHECK(from_long.faces() == faces);
}
