#pragma once
/// \file
/// Rotation-variant ("signed") SVD of a 3×3 deformation gradient (Irving et al. 2004, Teran et
/// al. 2005 §4): F = U diag(σ) Vᵀ with U and V proper rotations. Isotropic energies evaluated at
/// signed σ see an inverted element as one negative stretch, not as a reflection hidden in U or V.

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

}  // namespace simsr::physics
