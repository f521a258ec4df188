#pragma once
/// \file
/// Rotation-variant ("signed") SVD of a 3×3 deformation gradient (Irving et al. 2004, Teran et
/// al. 2005 §4): F = U diag(σ) Vᵀ with U and V proper rotations. Isotropic energies evaluated at
/// signed σ see an inverted element as one negative stretch, not as a reflection hidden in U or V.

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "../../core/host_device.hpp"
#include "../../core/types.hpp"

namespace simsr::physics {

/// F = U diag(sigma) Vᵀ; det U = det V = +1; |σ₁| ≥ |σ₂| ≥ |σ₃|, σ₁, σ₂ ≥ 0, and σ₃ < 0 exactly
/// when det F < 0 (σ₃ = 0 for rank-deficient F, with either sign of zero).
template <class S = Scalar>
struct SignedSvd {
  Mat3<S> U;
  Vec3<S> sigma;
  Mat3<S> V;
};

/// Signed SVD of F (Eigen's two-sided Jacobi SVD, accurate to rounding for every F, then a
/// reflection in U or V moved onto the smallest singular value).
template <class S>
SignedSvd<S> signed_svd(const Mat3<S>& F) {
  const Eigen::JacobiSVD<Mat3<S>> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  SignedSvd<S> r{svd.matrixU(), svd.singularValues(), svd.matrixV()};
  if (r.U.determinant() < S(0)) {
    r.U.col(2) = -r.U.col(2);
    r.sigma(2) = -r.sigma(2);
  }
  if (r.V.determinant() < S(0)) {
    r.V.col(2) = -r.V.col(2);
    r.sigma(2) = -r.sigma(2);
  }
  return r;
}

/// The same decomposition by one-sided (Hestenes) Jacobi, callable on a CUDA device (Eigen's
/// JacobiSVD is not): plane rotations of F's columns, accumulated in V, until every pair is
/// orthogonal to ε relative to its norms; σ_i are the column lengths, U the columns normalized
/// (completed to a rotation by cross products where σ vanishes), sorted descending, then a
/// reflection in U or V moved onto σ₃. Accurate to rounding like two-sided Jacobi (each rotation
/// is exact to ε, sweeps converge quadratically: at most 12 here). signed_svd_from_eigen's
/// fallback on a device; the host keeps Eigen's.
template <class S>
SIMSR_HOST_DEVICE SignedSvd<S> signed_svd_one_sided(const Mat3<S>& F) {
  constexpr S eps = std::numeric_limits<S>::epsilon();
  // F scaled by a power of two to entries in [½, 1) (exact): the squared column norms neither
  // overflow nor underflow whatever F's magnitude; σ scaled back at the end
  bool finite = true;  // (Eigen's allFinite is host code)
  for (int i = 0; i < 9; ++i) finite = finite && std::isfinite(F(i % 3, i / 3));
  if (!finite)  // a NaN or infinite entry: NaN values, as the Jacobi SVD's (nothing hidden)
    return {Mat3<S>::Identity(), Vec3<S>::Constant(std::numeric_limits<S>::quiet_NaN()), Mat3<S>::Identity()};
  const S largest = F.cwiseAbs().maxCoeff();
  if (largest == S(0)) return {Mat3<S>::Identity(), Vec3<S>::Zero(), Mat3<S>::Identity()};  // F = 0
  int exponent = 0;
  (void)std::frexp(largest, &exponent);
  const Mat3<S> G = F * std::ldexp(S(1), -exponent);
  Mat3<S> A = G, V = Mat3<S>::Identity();
  for (int sweep = 0; sweep < 12; ++sweep) {
    bool rotated = false;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        const S a = A.col(p).squaredNorm(), b = A.col(q).squaredNorm(), c = A.col(p).dot(A.col(q));
        if (!(std::abs(c) > eps * std::sqrt(a * b))) continue;  // orthogonal to rounding (or a zero column)
        // the rotation that diagonalizes [[a, c], [c, b]] (Rutishauser's stable form)
        const S zeta = (b - a) / (S(2) * c);
        const S t = (zeta >= S(0) ? S(1) : S(-1)) / (std::abs(zeta) + std::sqrt(S(1) + zeta * zeta));
        const S cs = S(1) / std::sqrt(S(1) + t * t), sn = cs * t;
        for (int r = 0; r < 3; ++r) {
          const S ap = A(r, p), aq = A(r, q), vp = V(r, p), vq = V(r, q);
          A(r, p) = cs * ap - sn * aq;
          A(r, q) = sn * ap + cs * aq;
          V(r, p) = cs * vp - sn * vq;
          V(r, q) = sn * vp + cs * vq;
        }
        rotated = true;
      }
    if (!rotated) break;
  }
  // sort the columns by length, descending
  Vec3<S> len(A.col(0).norm(), A.col(1).norm(), A.col(2).norm());
  int order[3] = {0, 1, 2};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2 - i; ++j)
      if (len(order[j]) < len(order[j + 1])) {
        const int k = order[j];
        order[j] = order[j + 1];
        order[j + 1] = k;
      }
  SignedSvd<S> r;
  for (int k = 0; k < 3; ++k) {
    r.V.col(k) = V.col(order[k]);
    r.sigma(k) = len(order[k]);
  }
  // U: the normalized columns, completed where σ is 0 (relative to σ₁) so that U is orthonormal
  const S tiny = eps * r.sigma(0);
  r.U.col(0) = A.col(order[0]) / r.sigma(0);  // σ₁ ≥ ½ after the scaling
  if (r.sigma(1) > tiny) {
    r.U.col(1) = A.col(order[1]) / r.sigma(1);
  } else {  // any unit vector orthogonal to u₁
    const Vec3<S> u0 = r.U.col(0);
    const Vec3<S> axis = std::abs(u0(0)) < S(0.5) ? Vec3<S>(1, 0, 0) : Vec3<S>(0, 1, 0);
    r.U.col(1) = u0.cross(axis).normalized();
  }
  r.U.col(2) = r.U.col(0).cross(r.U.col(1));
  // σ₃ carries det F's sign: u₃ is fixed by the cross product, so σ₃ = u₃·(F v₃) (made for V proper)
  if (r.V.determinant() < S(0)) r.V.col(2) = -r.V.col(2);
  r.sigma(2) = r.U.col(2).dot(G * r.V.col(2));
  // repeated values can come out an ulp out of order: keep the convention (as signed_svd_from_eigen)
  r.sigma(2) = std::copysign(std::min(std::abs(r.sigma(2)), r.sigma(1)), r.sigma(2));
  r.sigma *= std::ldexp(S(1), exponent);
  return r;
}

/// The same decomposition (the same conventions) from the closed-form eigen-decomposition of
/// C = FᵀF = V Σ² Vᵀ (Eigen's computeDirect) and U = F V Σ⁻¹, orthonormalized (Gram–Schmidt on
/// the first two columns, the third their cross product, so σ₃ = u₃·(F v₃) carries det F's sign;
/// the singular values are the lengths of F V's columns after it).
/// Cheaper than the two-sided Jacobi sweeps (bench_physics: the 73k-tet Hessian kernel 1.31×,
/// BM_kernel_73k/hessian against …/hessian_jacobi_svd). Squaring F halves the digits of its smallest
/// singular values and computeDirect's eigenvectors are less accurate than Jacobi's, so the result
/// is checked and signed_svd is returned instead wherever it fails: |σ₃| < ε^¼ σ₁ (≈ 1.2·10⁻⁴ in
/// double: a nearly flat or inverted-through-zero element), V not orthonormal to 64ε, or
/// U diag(σ) Vᵀ not F to 64ε‖F‖. Used by the isotropic element Hessians (isotropic.hpp), the
/// hottest SVD of a Newton iteration (issue #17 item 1); the other callers keep signed_svd.
/// Where the check fails it returns `fallback(F)`: signed_svd_from_eigen passes Eigen's two-sided
/// Jacobi (signed_svd) on the host and signed_svd_one_sided on a device.
template <class S, class Fallback>
SIMSR_HOST_DEVICE SignedSvd<S> signed_svd_from_eigen(const Mat3<S>& F, Fallback&& fallback) {
  constexpr S eps = std::numeric_limits<S>::epsilon();
  Eigen::SelfAdjointEigenSolver<Mat3<S>> eigen;
  eigen.computeDirect(F.transpose() * F);  // eigenvalues ascending
  SignedSvd<S> r;
  for (int k = 0; k < 3; ++k) {
    r.V.col(k) = eigen.eigenvectors().col(2 - k);
    r.sigma(k) = std::sqrt(std::max(eigen.eigenvalues()(2 - k), S(0)));
  }
  const S smallest_kept = std::sqrt(std::sqrt(eps)) * r.sigma(0);
  if (!(r.sigma(0) > S(0)) || !(r.sigma(2) >= smallest_kept) || !std::isfinite(r.sigma(0))) return fallback(F);
  if (r.V.determinant() < S(0)) r.V.col(2) = -r.V.col(2);
  if ((r.V.transpose() * r.V - Mat3<S>::Identity()).cwiseAbs().maxCoeff() > S(64) * eps) return fallback(F);
  // the singular values again from F V itself (σ from √λ would carry the squaring's rounding)
  const Mat3<S> FV = F * r.V;
  r.sigma(0) = FV.col(0).norm();
  r.U.col(0) = FV.col(0) / r.sigma(0);
  r.U.col(1) = FV.col(1) - r.U.col(0).dot(FV.col(1)) * r.U.col(0);
  r.sigma(1) = r.U.col(1).norm();
  r.U.col(1) /= r.sigma(1);
  r.U.col(2) = r.U.col(0).cross(r.U.col(1));
  r.sigma(2) = r.U.col(2).dot(FV.col(2));
  // repeated values can come out an ulp out of order: keep the convention (the check below bounds the change)
  r.sigma(1) = std::min(r.sigma(1), r.sigma(0));
  r.sigma(2) = std::copysign(std::min(std::abs(r.sigma(2)), r.sigma(1)), r.sigma(2));
  if ((r.U * r.sigma.asDiagonal() * r.V.transpose() - F).cwiseAbs().maxCoeff() > S(64) * eps * F.norm()) return fallback(F);
  return r;
}

/// signed_svd_from_eigen with the fallback of where it runs (see above).
template <class S>
SIMSR_HOST_DEVICE SignedSvd<S> signed_svd_from_eigen(const Mat3<S>& F) {
#if defined(__CUDA_ARCH__)
  return signed_svd_from_eigen(F, [](const Mat3<S>& G) { return signed_svd_one_sided(G); });
#else
  return signed_svd_from_eigen(F, [](const Mat3<S>& G) { return signed_svd(G); });
#endif
}

}  // namespace simsr::physics
