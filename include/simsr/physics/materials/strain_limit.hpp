#pragma once
/// \file
/// SoftDECA's strain energy (softdeca supplement eq. 2, with its maximum strain ε) as a Material:
/// the squared distance of F to the set of deformation gradients whose principal stretches lie in
/// a band,
///
///     ψ(F) = w · min_{T ∈ C} ‖F − T‖²_F,   C = { U diag(s) Vᵀ : U, V ∈ SO(3), lo ≤ s_i ≤ hi },
///
/// which is w Σ_i (σ_i − clamp(σ_i, lo, hi))² at the signed singular values σ (signed_svd.hpp),
/// the nearest T being U diag(clamp(σ)) Vᵀ (Bouaziz et al. 2014, §5.1 strain limiting).
///
/// How ε limits the singular values: the band runs from the rest stretch 1 to ε,
/// [lo, hi] = [min(1, ε), max(1, ε)]. ε = 1 gives the supplement's E_str = min_R ‖F − R‖²
/// (as-rigid-as-possible); ε = 1.3 lets every principal stretch grow up to 1.3 for free and
/// resists only beyond it or any compression; ε = 0.7 lets it shrink down to 0.7 and resists any
/// stretch. So each ε in the sampled [0.7, 1.3] is a different material and ε moves it
/// monotonically from "may shrink" to "may stretch". An inverted element (σ₃ < 0) is always
/// outside the band and is pulled back through σ₃ = lo.
///
///     physics::ElasticEnergy<physics::StrainLimit<>> strain(mesh, physics::StrainLimit<>(w, eps));
///
/// ψ is C¹ everywhere, piecewise quadratic in σ, with curvature jumps where a σ_i crosses lo or
/// hi (finite differences across those are one-sided). In singular values: g_i = 2w(σ_i − c_i),
/// ∂²ψ/∂σ_i² = 2w outside the band and 0 inside, the flip eigenvalue 2w(1 − (c_i − c_j)/(σ_i − σ_j))
/// ∈ [0, 2w], and the twist eigenvalue 2w(1 − (c_i + c_j)/(σ_i + σ_j)), negative under
/// compression and singular where σ_i + σ_j = 0 (an inverted element with |σ₂| = |σ₃|); as for
/// the corotated material its denominator is guarded at ≥ `twist_guard`.

#include <algorithm>
#include <cmath>
#include <utility>

#include "isotropic.hpp"

namespace simsr::physics {

/// ψ = w dist²(F, C) with C the stretch band (see the file comment).
template <class S = Scalar>
class StrainLimit {
 public:
  using scalar_type = S;
  using Element = NoElementData;

  static constexpr S twist_guard = S(1e-6);

  /// Weight w ≥ 0 (Pa) and maximum strain ε > 0: the band [min(1, ε), max(1, ε)].
  StrainLimit(S weight, S max_strain = S(1))
      : StrainLimit(weight, std::min(S(1), checked_strain(max_strain)), std::max(S(1), checked_strain(max_strain)), 0) {}

  /// Weight w ≥ 0 and an explicit band 0 < lo ≤ hi.
  static StrainLimit from_band(S weight, S lo, S hi) { return StrainLimit(weight, lo, hi, 0); }

  S weight() const { return w_; }
  S lo() const { return lo_; }
  S hi() const { return hi_; }

  S clamp(S s) const { return std::clamp(s, lo_, hi_); }

  S energy(const Mat3<S>& F, const Element& = {}) const {
    const Vec3<S> s = signed_svd(F).sigma;
    S e = 0;
    for (int i = 0; i < 3; ++i) e += (s(i) - clamp(s(i))) * (s(i) - clamp(s(i)));
    return w_ * e;
  }

  /// The nearest member of C: U diag(clamp(σ)) Vᵀ (the local step of projective dynamics).
  Mat3<S> project(const Mat3<S>& F) const {
    const SignedSvd<S> svd = signed_svd(F);
    Vec3<S> c;
    for (int i = 0; i < 3; ++i) c(i) = clamp(svd.sigma(i));
    return svd.U * c.asDiagonal() * svd.V.transpose();
  }

  /// P = 2w (F − project(F)).
  Mat3<S> stress(const Mat3<S>& F, const Element& = {}) const { return S(2) * w_ * (F - project(F)); }

  /// ψ and P from one decomposition (ElasticEnergy's fused energy and gradient).
  std::pair<S, Mat3<S>> energy_and_stress(const Mat3<S>& F, const Element& = {}) const {
    const SignedSvd<S> svd = signed_svd(F);
    Vec3<S> c;
    S e = 0;
    for (int i = 0; i < 3; ++i) {
      c(i) = clamp(svd.sigma(i));
      e += (svd.sigma(i) - c(i)) * (svd.sigma(i) - c(i));
    }
    return {w_ * e, S(2) * w_ * (F - svd.U * c.asDiagonal() * svd.V.transpose())};
  }

  Mat9<S> stress_derivative(const Mat3<S>& F, const Element&, Definiteness definiteness) const {
    const SignedSvd<S> svd = signed_svd(F);
    return isotropic_stress_derivative(svd, principal(svd.sigma), definiteness);
  }

  /// Singular-value derivatives at σ (see the file comment).
  PrincipalDerivatives<S> principal(const Vec3<S>& s) const {
    Vec3<S> c;
    for (int i = 0; i < 3; ++i) c(i) = clamp(s(i));
    PrincipalDerivatives<S> d;
    d.H.setZero();
    for (int i = 0; i < 3; ++i) {
      d.g(i) = S(2) * w_ * (s(i) - c(i));
      d.H(i, i) = (s(i) < lo_ || s(i) > hi_) ? S(2) * w_ : S(0);
    }
    for (int i = 0; i < 3; ++i) {  // the pair (j, k) has third index i
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      d.minus(i) = S(2) * w_ * (S(1) - clamp_slope(s(j), s(k)));
      d.plus(i) = S(2) * w_ * (S(1) - (c(j) + c(k)) / std::max(s(j) + s(k), twist_guard));
    }
    return d;
  }

  /// The per-unit-volume stiffness of the local–global solver's constant matrix: ψ is
  /// (k/2)‖F − project(F)‖² with k = 2w, projective dynamics' own form.
  S projective_stiffness() const { return S(2) * w_; }

 private:
  StrainLimit(S weight, S lo, S hi, int) : w_(weight), lo_(lo), hi_(hi) {
    detail::check_parameter(weight >= S(0) && std::isfinite(weight), "StrainLimit", "weight w", weight, "must be finite and >= 0");
    detail::check_parameter(lo > S(0) && std::isfinite(lo), "StrainLimit", "band minimum lo", lo, "must be finite and > 0");
    detail::check_parameter(hi >= lo && std::isfinite(hi), "StrainLimit", "band maximum hi", hi, "must be finite and >= lo");
  }

  static S checked_strain(S eps) {
    detail::check_parameter(eps > S(0) && std::isfinite(eps), "StrainLimit", "maximum strain eps", eps, "must be finite and > 0");
    return eps;
  }

  /// (clamp(a) − clamp(b)) / (a − b), the clamp's own slope (1 inside the band, 0 outside) where
  /// a and b lie on one piece, so no difference of nearly equal numbers is divided.
  S clamp_slope(S a, S b) const {
    const auto piece = [&](S x) { return x < lo_ ? 0 : x > hi_ ? 2 : 1; };
    if (piece(a) == piece(b)) return piece(a) == 1 ? S(1) : S(0);
    return (clamp(a) - clamp(b)) / (a - b);
  }

  S w_;
  S lo_;
  S hi_;
};

}  // namespace simsr::physics
