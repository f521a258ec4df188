#pragma once
/// \file
/// The rotation/stretch split of a deformation gradient and the rotation's axis–angle forms used
/// by TS-ACAP (Chen et al. 2023 supplement §2.1; Gao et al. 2019): T = R S with R a proper
/// rotation and S symmetric; R as an axis ω and an angle θ ∈ [0, π] (the principal choice,
/// before the consistency steps of rotation_consistency.hpp pick a sign and a multiple of 2π);
/// and back, a rotation vector ρ = Θ ω̂ with any Θ ∈ ℝ to R by Rodrigues' formula.

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "../core/types.hpp"
#include "../physics/materials/signed_svd.hpp"

namespace simsr::shell {

/// T = R S, R a proper rotation, S symmetric (positive definite when det T > 0; when det T < 0,
/// an inverted one-ring, S has one negative eigenvalue so that R stays a rotation).
template <class S>
struct PolarParts {
  Mat3<S> R;
  Mat3<S> stretch;
};

/// Polar decomposition from the signed SVD the materials use (physics/materials/signed_svd.hpp:
/// F = U diag(σ) Vᵀ with U, V proper rotations, σ₃ < 0 when det F < 0): R = U Vᵀ, S = V diag(σ) Vᵀ.
template <class S>
PolarParts<S> polar_decomposition(const Mat3<S>& T) {
  const physics::SignedSvd<S> svd = physics::signed_svd(T);
  PolarParts<S> out;
  out.R = svd.U * svd.V.transpose();
  out.stretch = svd.V * svd.sigma.asDiagonal() * svd.V.transpose();
  out.stretch = S(0.5) * (out.stretch + out.stretch.transpose()).eval();  // exactly symmetric
  return out;
}

/// A rotation's principal axis–angle: θ ∈ [0, π], ω a unit axis (Eigen's e_x when θ = 0, where
/// any axis would do).
template <class S>
struct AxisAngle {
  Vec3<S> axis;
  S angle;
};

template <class S>
AxisAngle<S> principal_axis_angle(const Mat3<S>& R) {
  const Eigen::AngleAxis<S> aa{Eigen::Quaternion<S>(R)};  // angle ∈ [0, π] (Eigen's convention)
  AxisAngle<S> out{aa.axis(), aa.angle()};
  if (out.angle > S(std::numbers::pi)) {  // guard against the other branch: (ω, θ) ≡ (−ω, 2π − θ)
    out.angle = S(2 * std::numbers::pi) - out.angle;
    out.axis = -out.axis;
  }
  return out;
}

/// R = exp([ρ]×) for a rotation vector ρ of any length (Rodrigues).
template <class S>
Mat3<S> rotation_from_vector(const Vec3<S>& rho) {
  const S t = rho.norm();
  if (t == S(0)) return Mat3<S>::Identity();
  return Eigen::AngleAxis<S>(t, rho / t).toRotationMatrix();
}

}  // namespace simsr::shell
