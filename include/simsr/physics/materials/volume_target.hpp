#pragma once
/// \file
/// SoftDECA's volume energy (softdeca supplement eq. 1) as a Material: ψ = w (det F − v)², with
/// the target determinant v (the supplement samples it in [0.5, 1.5]; v = 1 keeps the volume).
///
///     physics::ElasticEnergy<physics::VolumeTarget<>> volume(mesh, physics::VolumeTarget<>(w, v));
///
/// A polynomial in F: defined, smooth and exactly differentiated for every F, degenerate and
/// inverted ones included (no SVD in energy or stress). In singular values, g_i = 2w(J − v) σ_jσ_k
/// and the flip/twist eigenvalues are ∓2w(J − v)σ_k: indefinite wherever J ≠ v, so Newton needs
/// the definiteness fix away from the target.
///
/// For the local–global solver it is not a projective (distance-to-a-set) energy; its constant
/// stand-in in the prefactored matrix is `projective_stiffness()` = 6w·v^{4/3} per unit volume,
/// the largest eigenvalue of ∂²ψ/∂F² at the target's uniform stretch F = v^{1/3} I
/// (2w·vec(cof F)vec(cof F)ᵀ, cof F = v^{2/3} I, along vec(I)/√3), so near the target the unit
/// step does not overshoot along a volume change; its gradient enters every iteration exactly
/// (Liu, Bouaziz & Kavan 2017: projective dynamics as a quasi-Newton method).

#include <cmath>

#include "isotropic.hpp"

namespace simsr::physics {

/// ψ = w (J − v)² [Pa] (see the file comment).
template <class S = Scalar>
class VolumeTarget : public InvariantMaterial<VolumeTarget<S>, S> {
 public:
  /// w ≥ 0 (Pa; 0 switches the term off), v > 0 (the target det F).
  explicit VolumeTarget(S weight, S target = S(1)) : w_(weight), v_(target) {
    detail::check_parameter(weight >= S(0) && std::isfinite(weight), "VolumeTarget", "weight w", weight, "must be finite and >= 0");
    detail::check_parameter(target > S(0) && std::isfinite(target), "VolumeTarget", "target determinant v", target, "must be finite and > 0");
  }

  S weight() const { return w_; }
  S target() const { return v_; }

  InvariantPartials<S> partials(const Invariants<S>& inv) const {
    const S r = inv.J - v_;
    InvariantPartials<S> p;
    p.psi = w_ * r * r;
    p.d = Vec3<S>(S(0), S(0), S(2) * w_ * r);
    p.dd.setZero();
    p.dd(2, 2) = S(2) * w_;
    return p;
  }

  /// The per-unit-volume stiffness this term contributes to the local–global solver's constant
  /// matrix (see the file comment).
  S projective_stiffness() const { return S(6) * w_ * std::cbrt(v_ * v_ * v_ * v_); }

 private:
  S w_;
  S v_;
};

}  // namespace simsr::physics
