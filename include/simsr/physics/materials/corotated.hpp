#pragma once
/// \file
/// Fixed corotated material (Stomakhin et al. 2012, eq. 2 with the constitutive model of §3).

#include <algorithm>
#include <cmath>

#include "isotropic.hpp"

namespace simsr::physics {

/// ψ = μ Σ(σ_i − 1)² + λ/2 (J − 1)²  [Pa] at signed singular values σ: polynomial in σ, so it is
/// defined for every F without an inversion threshold. Linearizes at F = I to linear elasticity
/// with Lamé parameters μ, λ.
///
/// The twist eigenvalue (g_i + g_j)/(σ_i + σ_j) = 2μ(1 − 2/(σ_i + σ_j)) + λ(J − 1)σ_k is
/// genuinely singular where σ_i + σ_j = 0 (an inverted element with |σ₂| = |σ₃|, where ψ is not
/// C¹ because the signed polar rotation jumps). As Stomakhin does, its denominator is clamped
/// to ≥ `twist_guard` = 1e-6; the exact ∂P/∂F is therefore bounded but not exact within 1e-6 of
/// that set (P and ψ are unaffected).
template <class S = Scalar>
class Corotated {
 public:
  using scalar_type = S;
  using Element = NoElementData;

  static constexpr S twist_guard = S(1e-6);

  /// μ, λ in Pa; requires μ > 0 and λ + 2μ/3 > 0.
  static Corotated from_lame(S mu, S lambda) { return Corotated(mu, lambda); }

  /// Young's modulus E > 0 (Pa) and Poisson ratio ν ∈ (−1, 0.5).
  static Corotated from_young_poisson(S E, S nu) {
    detail::check_parameter(E > S(0) && std::isfinite(E), "Corotated", "Young's modulus E", E, "must be > 0");
    detail::check_parameter(nu > S(-1) && nu < S(0.5), "Corotated", "Poisson ratio nu", nu, "must lie in (-1, 0.5)");
    return Corotated(E / (S(2) * (S(1) + nu)), E * nu / ((S(1) + nu) * (S(1) - S(2) * nu)));
  }

  S mu() const { return mu_; }
  S lambda() const { return lambda_; }

  S energy(const Mat3<S>& F, const Element& = {}) const {
    const Vec3<S> s = signed_svd(F).sigma;
    const S dJ = s.prod() - S(1);
    return mu_ * (s.array() - S(1)).square().sum() + S(0.5) * lambda_ * dJ * dJ;
  }

  /// P = 2μ(F − R) + λ(J − 1) cof F with R = UVᵀ the signed polar rotation.
  Mat3<S> stress(const Mat3<S>& F, const Element& = {}) const {
    const SignedSvd<S> svd = signed_svd(F);
    return S(2) * mu_ * (F - svd.U * svd.V.transpose()) + lambda_ * (svd.sigma.prod() - S(1)) * cofactor(F);
  }

  Mat9<S> stress_derivative(const Mat3<S>& F, const Element&, Definiteness definiteness) const {
    const SignedSvd<S> svd = signed_svd(F);
    return isotropic_stress_derivative(svd, principal(svd.sigma), definiteness);
  }

  /// Singular-value derivatives at σ (the twist term guarded as documented above).
  PrincipalDerivatives<S> principal(const Vec3<S>& s) const {
    const S J = s.prod();
    PrincipalDerivatives<S> d;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      const S dJi = s(j) * s(k);
      d.g(i) = S(2) * mu_ * (s(i) - S(1)) + lambda_ * (J - S(1)) * dJi;
      d.H(i, i) = S(2) * mu_ + lambda_ * dJi * dJi;
      d.H(i, j) = d.H(j, i) = lambda_ * dJi * s(i) * s(k) + lambda_ * (J - S(1)) * s(k);
      // pair (j, k) has third index i
      d.minus(i) = S(2) * mu_ - lambda_ * (J - S(1)) * s(i);
      d.plus(i) = S(2) * mu_ * (S(1) - S(2) / std::max(s(j) + s(k), twist_guard)) + lambda_ * (J - S(1)) * s(i);
    }
    return d;
  }

 private:
  Corotated(S mu, S lambda) : mu_(mu), lambda_(lambda) {
    detail::check_parameter(mu > S(0) && std::isfinite(mu), "Corotated", "shear modulus mu", mu, "must be > 0");
    detail::check_parameter(lambda + S(2) * mu / S(3) > S(0) && std::isfinite(lambda), "Corotated", "Lame lambda",
                            lambda, "must give a positive bulk modulus lambda + 2 mu / 3");
  }

  S mu_;
  S lambda_;
};

}  // namespace simsr::physics
