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
template <class S>
SignedSvd<S> signed_svd_from_eigen(const Mat3<S>& F) {
  constexpr S eps = std::numeric_limits<S>::epsilon();
  Eigen::SelfAdjointEigenSolver<Mat3<S>> eigen;
  eigen.computeDirect(F.transpose() * F);  // eigenvalues ascending
  SignedSvd<S> r;
  for (int k = 0; k < 3; ++k) {
    r.V.col(k) = eigen.eigenvectors().col(2 - k);
    r.sigma(k) = std::sqrt(std::max(eigen.eigenvalues()(2 - k), S(0)));
  }
  const S smallest_kept = std::sqrt(std::sqrt(eps)) * r.sigma(0);
  if (!(r.sigma(0) > S(0)) || !(r.sigma(2) >= smallest_kept) || !std::isfinite(r.sigma(0))) return signed_svd(F);
  if (r.V.determinant() < S(0)) r.V.col(2) = -r.V.col(2);
  if ((r.V.transpose() * r.V - Mat3<S>::Identity()).cwiseAbs().maxCoeff() > S(64) * eps) return signed_svd(F);
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
  if ((r.U * r.sigma.asDiagonal() * r.V.transpose() - F).cwiseAbs().maxCoeff() > S(64) * eps * F.norm()) return signed_svd(F);
  return r;
}

}  // namespace simsr::physics
