#pragma once
/// \file
/// Compressible Mooney–Rivlin material, the isotropic part of the muscle model of Teran et al.
/// 2003 (§5) and of PhysBAM's face flesh (Sifakis et al. 2005).

#include <cmath>

#include "isotropic.hpp"

namespace simsr::physics {

/// ψ = μ10 (J^(−2/3) I1 − 3) + μ01 (J^(−4/3) I2 − 3) + κ/2 (ln J)²  [Pa], with J^(−2/3), J^(−4/3)
/// and ln J extended below J0 (isotropic.hpp). Small-strain shear modulus μ = 2(μ10 + μ01), bulk
/// modulus κ.
template <class S = Scalar>
class MooneyRivlin : public InvariantMaterial<MooneyRivlin<S>, S> {
 public:
  /// Energy and stress run in CUDA kernels too (DeviceMaterial).
  static constexpr bool device_callable = true;

  /// Defaults: PhysBAM's face flesh μ10 = 6e4 Pa, μ01 = 2e4 Pa (μ = 1.6e5 Pa); κ = 1.6e6 Pa = 10μ,
  /// i.e. small-strain Poisson ratio ν = (3κ − 2μ)/(6κ + 2μ) ≈ 0.452: nearly incompressible
  /// flesh while κ/μ = 10 keeps implicit solves well conditioned. J0 = 0.1 as for NeoHookean.
  /// Requires μ10, μ01 ≥ 0 with μ10 + μ01 > 0, κ > 0, J0 ∈ (0, 1).
  explicit MooneyRivlin(S mu10 = S(6e4), S mu01 = S(2e4), S kappa = S(1.6e6), S inversion_threshold = S(0.1))
      : mu10_(mu10), mu01_(mu01), kappa_(kappa), j0_(inversion_threshold) {
    detail::check_parameter(mu10 >= S(0) && std::isfinite(mu10), "MooneyRivlin", "mu10", mu10, "must be >= 0");
    detail::check_parameter(mu01 >= S(0) && std::isfinite(mu01), "MooneyRivlin", "mu01", mu01, "must be >= 0");
    detail::check_parameter(mu10 + mu01 > S(0), "MooneyRivlin", "mu10 + mu01", mu10 + mu01, "must be > 0");
    detail::check_parameter(kappa > S(0) && std::isfinite(kappa), "MooneyRivlin", "bulk modulus kappa", kappa,
                            "must be > 0");
    detail::check_parameter(j0_ > S(0) && j0_ < S(1), "MooneyRivlin", "inversion threshold J0", j0_,
                            "must lie in (0, 1)");
  }

  S mu10() const { return mu10_; }
  S mu01() const { return mu01_; }
  S kappa() const { return kappa_; }
  S inversion_threshold() const { return j0_; }

  /// Ψ(I1, I2, J) and its partials.
  SIMSR_HOST_DEVICE InvariantPartials<S> partials(const Invariants<S>& inv) const {
    const ScalarJet<S> a = extended_power(inv.J, S(-2) / S(3), j0_);
    const ScalarJet<S> b = extended_power(inv.J, S(-4) / S(3), j0_);
    const ScalarJet<S> L = extended_log(inv.J, j0_);
    InvariantPartials<S> p;
    p.psi = mu10_ * (a.value * inv.I1 - S(3)) + mu01_ * (b.value * inv.I2 - S(3)) +
            S(0.5) * kappa_ * L.value * L.value;
    p.d = Vec3<S>(mu10_ * a.value, mu01_ * b.value,
                  mu10_ * a.first * inv.I1 + mu01_ * b.first * inv.I2 + kappa_ * L.value * L.first);
    p.dd.setZero();
    p.dd(0, 2) = p.dd(2, 0) = mu10_ * a.first;
    p.dd(1, 2) = p.dd(2, 1) = mu01_ * b.first;
    p.dd(2, 2) = mu10_ * a.second * inv.I1 + mu01_ * b.second * inv.I2 +
                 kappa_ * (L.first * L.first + L.value * L.second);
    return p;
  }

 private:
  S mu10_;
  S mu01_;
  S kappa_;
  S j0_;
};

}  // namespace simsr::physics
