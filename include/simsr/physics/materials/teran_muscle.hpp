#pragma once
/// \file
/// Anisotropic active muscle (Teran et al. 2003 §5, as in PhysBAM's face of Sifakis et al. 2005):
/// Mooney–Rivlin flesh plus a fibre term along the rest fibre direction a.

#include <algorithm>
#include <cmath>
#include <string>

#include "fibre_curves.hpp"
#include "mooney_rivlin.hpp"

namespace simsr::physics {

/// A muscle tet's fibre: unit rest direction and activation ∈ [0, 1].
template <class S = Scalar>
struct MuscleFibre {
  Vec3<S> fibre = Vec3<S>::UnitX();
  S activation = S(0);
};

/// ψ = ψ_MR(F) + σ_max [W_p(λ) + α W_a(λ)], λ = ‖F a‖  [Pa], W_p, W_a the energies of the
/// passive and active fibre curves (fibre_curves.hpp), α the activation. The fibre stress
/// ψ_f' = σ_max (f_p + α f_a) ≥ 0 is a tension: activation lowers the energy of shorter fibres.
///
/// Fibre term: P_f = ψ_f' n aᵀ, n = F a/λ; ∂P_f/∂F = ψ_f'' v vᵀ + (ψ_f'/λ)(a aᵀ ⊗ I₃ − v vᵀ),
/// v = vec(n aᵀ) (the two terms are orthogonal, the second a projector: `project` clamps ψ_f''
/// and ψ_f'/λ at 0 separately). Both curves vanish for λ < min(1, 0.4 λ_ofl), so the fibre term
/// is constant there and contributes nothing to P and ∂P/∂F: the direction n is never formed
/// where λ → 0 would make it undefined.
template <class S = Scalar>
class TeranMuscle {
 public:
  using scalar_type = S;
  using Element = MuscleFibre<S>;
  /// Energy and stress run in CUDA kernels too (DeviceMaterial).
  static constexpr bool device_callable = true;

  /// σ_max = 3e5 Pa: Teran et al. 2003's maximum isometric muscle stress (0.3 MPa).
  explicit TeranMuscle(MooneyRivlin<S> isotropic = MooneyRivlin<S>(), S max_stress = S(3e5),
                       PassiveFibreCurve<S> passive = {}, ActiveFibreCurve<S> active = {})
      : iso_(isotropic), max_stress_(max_stress), passive_(passive), active_(active) {
    detail::check_parameter(max_stress >= S(0) && std::isfinite(max_stress), "TeranMuscle", "max_stress", max_stress,
                            "must be >= 0");
    passive_.check();
    active_.check();
  }

  const MooneyRivlin<S>& isotropic() const { return iso_; }
  S max_stress() const { return max_stress_; }
  const PassiveFibreCurve<S>& passive() const { return passive_; }
  const ActiveFibreCurve<S>& active() const { return active_; }

  /// ArgumentError unless the fibre is finite and of unit length (to 1e-6) and the activation
  /// lies in [0, 1]. The elastic energy calls it once per element at setup, not per evaluation.
  static void check(const Element& e) {
    const S n = e.fibre.norm();
    detail::check_parameter(std::isfinite(n) && std::abs(n - S(1)) <= S(1e-6), "TeranMuscle", "fibre length", n,
                            "must be 1 (use TeranMuscle::element to normalize)");
    detail::check_parameter(e.activation >= S(0) && e.activation <= S(1), "TeranMuscle", "activation", e.activation,
                            "must lie in [0, 1]");
  }

  /// Element data from any non-zero finite direction (normalized) and an activation in [0, 1].
  static Element element(const Vec3<S>& direction, S activation) {
    const S n = direction.norm();
    detail::check_parameter(std::isfinite(n) && n > S(0), "TeranMuscle", "fibre direction length", n,
                            "must be finite and > 0");
    Element e{direction / n, activation};
    check(e);
    return e;
  }

  SIMSR_HOST_DEVICE S energy(const Mat3<S>& F, const Element& e) const {
    const S lambda = (F * e.fibre).norm();
    return iso_.energy(F) + max_stress_ * (passive_.energy(lambda) + e.activation * active_.energy(lambda));
  }

  SIMSR_HOST_DEVICE Mat3<S> stress(const Mat3<S>& F, const Element& e) const {
    Mat3<S> P = iso_.stress(F);
    const Vec3<S> Fa = F * e.fibre;
    const S lambda = Fa.norm();
    if (lambda >= flat_below()) P += (fibre_stress(lambda, e.activation) / lambda) * Fa * e.fibre.transpose();
    return P;
  }

  Mat9<S> stress_derivative(const Mat3<S>& F, const Element& e, Definiteness definiteness) const {
    Mat9<S> D = iso_.stress_derivative(F, {}, definiteness);
    const FibreStiffness f = fibre_stiffness(F, e, definiteness);
    if (!f.active) return D;
    Vec9<S> v;
    for (int c = 0; c < 3; ++c) v.template segment<3>(3 * c) = e.fibre(c) * f.n;
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < 3; ++l) D.template block<3, 3>(3 * c, 3 * l).diagonal().array() += f.d1 * e.fibre(c) * e.fibre(l);
    D.noalias() += (f.d2 - f.d1) * v * v.transpose();
    return D;
  }

  /// vol·(D⊗I)ᵀ ∂P/∂F (D⊗I) without the 9×9 matrix: the Mooney–Rivlin part from its eigen-modes
  /// (isotropic_element_stiffness), the fibre part as vol g_a g_b (ψ_f'/λ I + (ψ_f'' − ψ_f'/λ) n nᵀ)
  /// for block (a,b) with g = D a (both terms of stress_derivative's fibre part pushed through D⊗I).
  SIMSR_HOST_DEVICE Mat12<S> element_stiffness(const Mat3<S>& F, const Element& e, Definiteness definiteness, const ShapeGradients<S>& D, S vol) const {
    Mat12<S> K = iso_.element_stiffness(F, {}, definiteness, D, vol);
    add_fibre_element_stiffness(F, e, definiteness, D, vol, K);
    return K;
  }

  /// K += the fibre term's part of element_stiffness (the Mooney–Rivlin part is the isotropic
  /// material's own: a caller may compute it another way, as bench_physics's SVD baseline does).
  SIMSR_HOST_DEVICE void add_fibre_element_stiffness(const Mat3<S>& F, const Element& e, Definiteness definiteness, const ShapeGradients<S>& D, S vol,
                                   Mat12<S>& K) const {
    const FibreStiffness f = fibre_stiffness(F, e, definiteness);
    if (!f.active) return;
    const Eigen::Matrix<S, 4, 1> g = D * e.fibre;
    const Mat3<S> nn = f.n * f.n.transpose();  // formed before scaling: exactly symmetric
    const Mat3<S> N = vol * (f.d1 * Mat3<S>::Identity() + (f.d2 - f.d1) * nn);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) K.template block<3, 3>(3 * a, 3 * b) += (g(a) * g(b)) * N;
  }

  /// ψ_f'(λ) = σ_max (f_p(λ) + α f_a(λ)), the fibre's first Piola stress magnitude [Pa].
  SIMSR_HOST_DEVICE S fibre_stress(S lambda, S activation) const {
    return max_stress_ * (passive_.value(lambda) + activation * active_.value(lambda));
  }

 private:
  /// The fibre term's ∂P/∂F = d2 v vᵀ + d1 (a aᵀ ⊗ I − v vᵀ), v = vec(n aᵀ): its direction and two
  /// coefficients (clamped at 0 for `project`); not `active` where the fibre term is flat.
  struct FibreStiffness {
    bool active = false;
    Vec3<S> n;
    S d1 = 0, d2 = 0;
  };
  SIMSR_HOST_DEVICE FibreStiffness fibre_stiffness(const Mat3<S>& F, const Element& e, Definiteness definiteness) const {
    const Vec3<S> Fa = F * e.fibre;
    const S lambda = Fa.norm();
    if (lambda < flat_below()) return {};
    FibreStiffness f{true, Fa / lambda, fibre_stress(lambda, e.activation) / lambda,
                     max_stress_ * (passive_.derivative(lambda) + e.activation * active_.derivative(lambda))};
    if (definiteness == Definiteness::project) {
      f.d2 = std::max(f.d2, S(0));
      f.d1 = std::max(f.d1, S(0));
    }
    return f;
  }

  /// Below this stretch both fibre curves vanish identically.
  SIMSR_HOST_DEVICE S flat_below() const { return std::min(S(1), ActiveFibreCurve<S>::lower * active_.optimal_length); }

  MooneyRivlin<S> iso_;
  S max_stress_;
  PassiveFibreCurve<S> passive_;
  ActiveFibreCurve<S> active_;
};

}  // namespace simsr::physics
