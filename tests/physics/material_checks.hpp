#pragma once
// Finite-difference and definiteness checks shared by the material tests.

#include <doctest/doctest.h>

#include <simsr/physics/materials/materials.hpp>
#include <simsr/physics/tet_elements.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace simsr::physics::testing {

using Mat3d = Mat3<double>;
using Mat9d = Mat9<double>;

inline Mat3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector4d q(n(rng), n(rng), n(rng), n(rng));
  return Eigen::Quaterniond(q.normalized()).toRotationMatrix();
}

inline Mat3d with_singular_values(std::mt19937& rng, double s1, double s2, double s3) {
  return random_rotation(rng) * Eigen::Vector3d(s1, s2, s3).asDiagonal() * random_rotation(rng).transpose();
}

/// A named family of deformation gradients.
struct Sample {
  const char* kind;
  Mat3d F;
  /// At J = J0 exactly ψ is C² but not C³, so central differences of P carry an O(h) error.
  bool straddles_threshold = false;
};

/// Random, stretched/compressed, near-degenerate (σ ≈ 1e-3), repeated-σ and inverted F, including
/// J just above and below the default inversion threshold 0.1 and across it.
inline std::vector<Sample> deformation_samples(unsigned seed, bool include_flip_singularity = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), s(0.3, 2.0);
  std::vector<Sample> r;
  r.push_back({"identity", Mat3d::Identity()});
  r.push_back({"rotation", random_rotation(rng)});
  for (int i = 0; i < 40; ++i) {
    Mat3d F = Mat3d::Identity();
    for (int k = 0; k < 9; ++k) F(k % 3, k / 3) += 0.6 * u(rng);
    r.push_back({"random", F});
  }
  for (int i = 0; i < 20; ++i) r.push_back({"stretch", with_singular_values(rng, s(rng), s(rng), s(rng))});
  for (int i = 0; i < 20; ++i) r.push_back({"inverted", with_singular_values(rng, s(rng), s(rng), -s(rng))});
  for (int i = 0; i < 10; ++i) {
    r.push_back({"near-degenerate", with_singular_values(rng, s(rng), s(rng), 1e-3)});
    r.push_back({"near-degenerate inverted", with_singular_values(rng, s(rng), s(rng), -1e-3)});
  }
  for (int i = 0; i < 5; ++i) {
    r.push_back({"repeated", with_singular_values(rng, 1.2, 1.2, 0.8)});
    r.push_back({"repeated", with_singular_values(rng, 0.7, 1.1, 1.1)});
    r.push_back({"repeated", with_singular_values(rng, 0.9, 0.9, 0.9)});
    r.push_back({"repeated inverted", with_singular_values(rng, 1.2, 1.2, -0.8)});
    r.push_back({"repeated rank-deficient", with_singular_values(rng, 1.1, 1.1, 0.0)});
    if (include_flip_singularity) r.push_back({"repeated inverted |s2|=|s3|", with_singular_values(rng, 1.2, 0.8, -0.8)});
    r.push_back({"J above threshold", with_singular_values(rng, 1.0, 0.5, 0.2 + 1e-4)});
    r.push_back({"J below threshold", with_singular_values(rng, 1.0, 0.5, 0.2 - 1e-4)});
    r.push_back({"J at threshold", with_singular_values(rng, 1.0, 0.5, 0.2), true});
  }
  return r;
}

/// Central differences of f along each of F's 9 entries (column-major k ↔ F(k % 3, k / 3)).
template <class Fn>
auto fd_over_entries(const Mat3d& F, double h, Fn&& f) {
  std::array<std::decay_t<decltype(f(F))>, 9> d;
  for (int k = 0; k < 9; ++k) {
    Mat3d Fp = F, Fm = F;
    Fp(k % 3, k / 3) += h;
    Fm(k % 3, k / 3) -= h;
    d[std::size_t(k)] = (f(Fp) - f(Fm)) / (2 * h);
  }
  return d;
}

/// Central differences of ψ: ∂ψ/∂F.
template <class M>
Mat3d fd_stress(const M& m, const Mat3d& F, const typename M::Element& e, double h) {
  const auto d = fd_over_entries(F, h, [&](const Mat3d& G) { return m.energy(G, e); });
  Mat3d P;
  for (int k = 0; k < 9; ++k) P(k % 3, k / 3) = d[std::size_t(k)];
  return P;
}

/// Central differences of P: ∂vec(P)/∂vec(F).
template <class M>
Mat9d fd_stress_derivative(const M& m, const Mat3d& F, const typename M::Element& e, double h) {
  const auto d = fd_over_entries(F, h, [&](const Mat3d& G) -> Mat3d { return m.stress(G, e); });
  Mat9d D;
  for (int k = 0; k < 9; ++k) D.col(k) = Eigen::Map<const Vec9<double>>(d[std::size_t(k)].data());
  return D;
}

/// max|A − B| / max(max|B|, scale).
template <class A, class B>
double relative_error(const A& a, const B& b, double scale) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(b.cwiseAbs().maxCoeff(), scale);
}

struct FdReport {
  double stress = 0;      ///< worst relative error of P against FD of ψ
  double derivative = 0;  ///< worst relative error of exact ∂P/∂F against FD of P
  double at_threshold = 0;  ///< the same where the FD stencil straddles J = J0
};

/// Checks P against FD of ψ and exact ∂P/∂F against FD of P (tolerance `tol` relative to
/// max(|·|, scale)) and that the projected derivative is symmetric and PSD, for every sample.
template <class M>
FdReport check_derivatives(const M& m, const std::vector<Sample>& samples, const typename M::Element& e, double scale,
                           double tol = 1e-6) {
  FdReport worst;
  for (const Sample& s : samples) {
    const std::string kind = s.kind;
    CAPTURE(kind);
    CAPTURE(s.F);
    const double h = 1e-6 * std::max(1.0, s.F.norm());
    const Mat3d P = m.stress(s.F, e);
    const double es = relative_error(P, fd_stress(m, s.F, e, h), scale);
    CHECK(es < tol);
    const Mat9d D = m.stress_derivative(s.F, e, Definiteness::exact);
    const double ed = relative_error(D, fd_stress_derivative(m, s.F, e, h), scale);
    CHECK(ed < (s.straddles_threshold ? 10 * tol : tol));
    worst.stress = std::max(worst.stress, es);
    double& w = s.straddles_threshold ? worst.at_threshold : worst.derivative;
    w = std::max(w, ed);
    const Mat9d Dp = m.stress_derivative(s.F, e, Definiteness::project);
    CHECK(relative_error(Dp, Dp.transpose().eval(), scale) < 1e-12);
    const double emin = Eigen::SelfAdjointEigenSolver<Mat9d>(Dp).eigenvalues().minCoeff();
    CHECK(emin >= -1e-10 * std::max(Dp.cwiseAbs().maxCoeff(), scale));
  }
  MESSAGE("worst FD error: stress " << worst.stress << ", derivative " << worst.derivative
                                    << " (stencil across J0: " << worst.at_threshold << ")");
  return worst;
}

/// A material's own element_stiffness (the eigen-mode route) equals vol·(D⊗I)ᵀ ∂P/∂F (D⊗I)
/// through its 9×9 stress_derivative, exact and projected, on every sample with random shape
/// gradients; exactly symmetric. Returns the worst relative difference.
template <class M>
double check_element_stiffness(const M& m, const std::vector<Sample>& samples, const typename M::Element& e, double scale,
                               unsigned seed = 5) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), v(0.1, 3.0);
  double worst = 0;
  for (const Sample& s : samples) {
    const std::string kind = s.kind;
    CAPTURE(kind);
    CAPTURE(s.F);
    Mat3d Dm;
    do {
      for (int k = 0; k < 9; ++k) Dm(k % 3, k / 3) = u(rng);
    } while (std::abs(Dm.determinant()) < 0.05);
    const ShapeGradients<double> D = shape_gradients(Mat3d(Dm.inverse()));
    const double vol = v(rng);
    for (const Definiteness d : {Definiteness::exact, Definiteness::project}) {
      const Mat12<double> K = m.element_stiffness(s.F, e, d, D, vol);
      const Mat12<double> reference = element_stiffness(m.stress_derivative(s.F, e, d), D, vol);
      const double err = relative_error(K, reference, scale * vol * D.squaredNorm());
      CHECK(err < 1e-12);
      CHECK(K == K.transpose());
      worst = std::max(worst, err);
    }
  }
  MESSAGE("element stiffness from the eigen-modes against the 9x9 route: worst relative difference " << worst);
  return worst;
}

/// Where the exact derivative is already PSD the projected one equals it.
template <class M>
void check_projection_keeps_psd(const M& m, const Mat3d& F, const typename M::Element& e, double scale) {
  CAPTURE(F);
  const Mat9d D = m.stress_derivative(F, e, Definiteness::exact);
  const double emin = Eigen::SelfAdjointEigenSolver<Mat9d>(D).eigenvalues().minCoeff();
  REQUIRE(emin >= -1e-10 * scale);
  CHECK(relative_error(m.stress_derivative(F, e, Definiteness::project), D, scale) < 1e-10);
}

/// ψ(I) = 0 and P(I) = 0.
template <class M>
void check_rest_state(const M& m, const typename M::Element& e, double scale) {
  CHECK(std::abs(m.energy(Mat3d::Identity(), e)) <= 1e-12 * scale);
  CHECK(m.stress(Mat3d::Identity(), e).cwiseAbs().maxCoeff() <= 1e-12 * scale);
}

/// At F = I + εG, P ≈ λ tr(ε_s) I + 2μ ε_s.
template <class M>
void check_linear_elasticity(const M& m, double mu, double lambda, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double eps = 1e-6;
  for (int t = 0; t < 10; ++t) {
    Mat3d G;
    for (int k = 0; k < 9; ++k) G(k % 3, k / 3) = u(rng);
    const Mat3d es = 0.5 * (G + G.transpose());
    const Mat3d expected = lambda * es.trace() * Mat3d::Identity() + 2 * mu * es;
    const Mat3d P = m.stress(Mat3d::Identity() + eps * G, {}) / eps;
    CHECK(relative_error(P, expected, mu) < 1e-4);
  }
}

/// Along F(t) = R diag(1, 1, t) Qᵀ, dψ/dt < 0 for t in [t0, t1]: un-inverting lowers the energy.
template <class M>
void check_uninversion(const M& m, const typename M::Element& e, unsigned seed, double t0, double t1) {
  std::mt19937 rng(seed);
  const Mat3d R = random_rotation(rng), Q = random_rotation(rng);
  const Mat3d dF = R * Eigen::Vector3d(0, 0, 1).asDiagonal() * Q.transpose();
  for (double t = t0; t <= t1 + 1e-12; t += 0.01) {
    CAPTURE(t);
    const Mat3d F = R * Eigen::Vector3d(1, 1, t).asDiagonal() * Q.transpose();
    CHECK(m.stress(F, e).cwiseProduct(dF).sum() < 0);
  }
}

}  // namespace simsr::physics::testing
