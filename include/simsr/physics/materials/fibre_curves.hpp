#pragma once
/// \file
/// Muscle fibre curves of Blemker et al. 2005 (§2.2) as functions of the fibre stretch λ = ‖F a‖,
/// normalized by the maximum isometric stress σ_max: value f(λ), slope f'(λ) and the energy
/// W(λ) = ∫₁^λ f(s) ds (dimensionless; times σ_max gives Pa).

#include <algorithm>
#include <cmath>

#include "../../core/host_device.hpp"
#include "isotropic.hpp"

namespace simsr::physics {

/// Passive fibre stress: 0 for λ ≤ 1, P1 (exp(P2 (λ − 1)) − 1) for 1 < λ < λ*, then linear with
/// the value and slope of the exponential at λ* (C¹ there). At λ = 1 the curve is continuous but
/// its slope jumps from 0 to P1·P2 (Blemker's curve; W is C¹, its second derivative jumps).
template <class S = Scalar>
struct PassiveFibreCurve {
  S p1 = S(0.05);          ///< Blemker 2005's P1
  S p2 = S(6.6);           ///< Blemker 2005's P2
  S stretch_max = S(1.4);  ///< λ*, where the exponential turns linear

  /// ArgumentError unless p1 ≥ 0, p2 > 0, λ* > 1.
  void check() const {
    detail::check_parameter(p1 >= S(0) && std::isfinite(p1), "PassiveFibreCurve", "p1", p1, "must be >= 0");
    detail::check_parameter(p2 > S(0) && std::isfinite(p2), "PassiveFibreCurve", "p2", p2, "must be > 0");
    detail::check_parameter(stretch_max > S(1) && std::isfinite(stretch_max), "PassiveFibreCurve", "stretch_max",
                            stretch_max, "must be > 1");
  }

  SIMSR_HOST_DEVICE S value(S lambda) const {
    if (lambda <= S(1)) return S(0);
    if (lambda < stretch_max) return p1 * std::expm1(p2 * (lambda - S(1)));
    return value_max() + slope_max() * (lambda - stretch_max);
  }

  SIMSR_HOST_DEVICE S derivative(S lambda) const {
    if (lambda <= S(1)) return S(0);
    if (lambda < stretch_max) return p1 * p2 * std::exp(p2 * (lambda - S(1)));
    return slope_max();
  }

  /// ∫₁^λ value.
  SIMSR_HOST_DEVICE S energy(S lambda) const {
    if (lambda <= S(1)) return S(0);
    const auto exponential = [&](S l) { return p1 * (std::expm1(p2 * (l - S(1))) / p2 - (l - S(1))); };
    if (lambda < stretch_max) return exponential(lambda);
    const S d = lambda - stretch_max;
    return exponential(stretch_max) + d * (value_max() + S(0.5) * slope_max() * d);
  }

 private:
  SIMSR_HOST_DEVICE S value_max() const { return p1 * std::expm1(p2 * (stretch_max - S(1))); }
  SIMSR_HOST_DEVICE S slope_max() const { return p1 * p2 * std::exp(p2 * (stretch_max - S(1))); }
};

/// Active force–length curve, x = λ/λ_ofl: 1 − 4(x − 1)² around the optimum and c(x − 0.4)²,
/// c(x − 1.6)² towards the ends of its support [0.4, 1.6], zero outside. Blemker 2005's pieces
/// (c = 9, breakpoints 0.6, 1.4) are not C¹ (slopes 3.6 against 3.2); keeping the central
/// parabola and the support, the breakpoints 7/12, 17/12 and c = 100/11 make it C¹ (it differs from
/// Blemker's by at most 0.004).
template <class S = Scalar>
struct ActiveFibreCurve {
  S optimal_length = S(1);  ///< λ_ofl, the stretch of peak active force

  static constexpr S lower = S(0.4), upper = S(1.6);
  static constexpr S lower_break = S(7) / S(12), upper_break = S(17) / S(12);
  static constexpr S outer = S(100) / S(11);

  /// ArgumentError unless λ_ofl > 0.
  void check() const {
    detail::check_parameter(optimal_length > S(0) && std::isfinite(optimal_length), "ActiveFibreCurve",
                            "optimal_length", optimal_length, "must be > 0");
  }

  SIMSR_HOST_DEVICE S value(S lambda) const { return normalized_value(lambda / optimal_length); }

  SIMSR_HOST_DEVICE S derivative(S lambda) const {
    const S x = lambda / optimal_length;
    S d = S(0);
    if (x <= lower || x >= upper)
      d = S(0);
    else if (x < lower_break)
      d = S(2) * outer * (x - lower);
    else if (x <= upper_break)
      d = S(-8) * (x - S(1));
    else
      d = S(2) * outer * (x - upper);
    return d / optimal_length;
  }

  /// ∫₁^λ value = λ_ofl (G(λ/λ_ofl) − G(1/λ_ofl)) with G(x) = ∫₁^x of the normalized curve.
  SIMSR_HOST_DEVICE S energy(S lambda) const {
    return optimal_length * (antiderivative(lambda / optimal_length) - antiderivative(S(1) / optimal_length));
  }

 private:
  SIMSR_HOST_DEVICE static S normalized_value(S x) {
    if (x <= lower || x >= upper) return S(0);
    if (x < lower_break) return outer * (x - lower) * (x - lower);
    if (x <= upper_break) return S(1) - S(4) * (x - S(1)) * (x - S(1));
    return outer * (x - upper) * (x - upper);
  }

  SIMSR_HOST_DEVICE static S central(S x) { return (x - S(1)) - S(4) / S(3) * (x - S(1)) * (x - S(1)) * (x - S(1)); }

  SIMSR_HOST_DEVICE static S cube(S x) { return x * x * x; }

  SIMSR_HOST_DEVICE static S antiderivative(S x) {
    if (x < lower_break)
      return central(lower_break) - outer / S(3) * (cube(lower_break - lower) - cube((x > lower ? x : lower) - lower));
    if (x <= upper_break) return central(x);
    return central(upper_break) + outer / S(3) * (cube((x < upper ? x : upper) - upper) - cube(upper_break - upper));
  }
};

}  // namespace simsr::physics
