#pragma once
/// \file
/// Compressible Neo-Hookean material (Bonet & Wood 2008, eq. 6.28; the model of Teran et al. 2005).

#include <cmath>

#include "isotropic.hpp"

namespace simsr::physics {

/// ψ = μ/2 (I1 − 3) − μ ln J + λ/2 (ln J)²  [Pa = J/m³], ln J extended below J0 (isotropic.hpp).
/// Linearizes at F = I to linear elasticity with Lamé parameters μ, λ.
template <class S = Scalar>
class NeoHookean : public InvariantMaterial<NeoHookean<S>, S> {
 public:
  /// Energy and stress run in CUDA kernels too (DeviceMaterial).
  static constexpr bool device_callable = true;

  /// Default inversion threshold J0: the exact law holds down to 10 % of the rest volume, far
  /// beyond any physical compression of nearly incompressible flesh, while the extension's
  /// curvature (1/J0² = 100 for ln J) keeps the Hessian moderate.
  static constexpr S default_inversion_threshold = S(0.1);

  /// μ, λ in Pa; requires μ > 0, bulk modulus λ + 2μ/3 > 0, J0 ∈ (0, 1).
  static NeoHookean from_lame(S mu, S lambda, S inversion_threshold = default_inversion_threshold) {
    return NeoHookean(mu, lambda, inversion_threshold);
  }

  /// Young's modulus E > 0 (Pa) and Poisson ratio ν ∈ (−1, 0.5).
  static NeoHookean from_young_poisson(S E, S nu, S inversion_threshold = default_inversion_threshold) {
    detail::check_parameter(E > S(0) && std::isfinite(E), "NeoHookean", "Young's modulus E", E, "must be > 0");
    detail::check_parameter(nu > S(-1) && nu < S(0.5), "NeoHookean", "Poisson ratio nu", nu, "must lie in (-1, 0.5)");
    return NeoHookean(E / (S(2) * (S(1) + nu)), E * nu / ((S(1) + nu) * (S(1) - S(2) * nu)), inversion_threshold);
  }

  S mu() const { return mu_; }
  S lambda() const { return lambda_; }
  S inversion_threshold() const { return j0_; }

  /// Ψ(I1, I2, J) and its partials.
  SIMSR_HOST_DEVICE InvariantPartials<S> partials(const Invariants<S>& inv) const {
    const ScalarJet<S> L = extended_log(inv.J, j0_);
    const S dJ = (lambda_ * L.value - mu_) * L.first;
    InvariantPartials<S> p;
    p.psi = S(0.5) * mu_ * (inv.I1 - S(3)) - mu_ * L.value + S(0.5) * lambda_ * L.value * L.value;
    p.d = Vec3<S>(S(0.5) * mu_, S(0), dJ);
    p.dd.setZero();
    p.dd(2, 2) = lambda_ * L.first * L.first + (lambda_ * L.value - mu_) * L.second;
    return p;
  }

 private:
  NeoHookean(S mu, S lambda, S j0) : mu_(mu), lambda_(lambda), j0_(j0) {
    detail::check_parameter(mu > S(0) && std::isfinite(mu), "NeoHookean", "shear modulus mu", mu, "must be > 0");
    detail::check_parameter(lambda + S(2) * mu / S(3) > S(0) && std::isfinite(lambda), "NeoHookean", "Lame lambda",
                            lambda, "must give a positive bulk modulus lambda + 2 mu / 3");
    detail::check_parameter(j0 > S(0) && j0 < S(1), "NeoHookean", "inversion threshold J0", j0, "must lie in (0, 1)");
  }

  S mu_;
  S lambda_;
  S j0_;
};

}  // namespace simsr::physics
