#pragma once
/// \file
/// The Material concept: a hyperelastic constitutive model as a policy (SPEC §3). A material is
/// a small parameter struct; what varies per element (fibre direction, activation) lives in its
/// `Element` type, which the elastic energy stores one per tet.
///
///     physics::NeoHookean<> m = physics::NeoHookean<>::from_young_poisson(1e5, 0.3);
///     double psi  = m.energy(F, {});                                   // J/m³ (per unit rest volume)
///     Mat3<> P    = m.stress(F, {});                                   // first Piola–Kirchhoff, ∂ψ/∂F
///     Mat9<> dPdF = m.stress_derivative(F, {}, Definiteness::project); // ∂vec(P)/∂vec(F), PSD
///
/// vec() is column-major (Eigen's storage of Mat3): vec(F)[i + 3j] = F(i, j).

#include <concepts>

#include <Eigen/Core>

#include "../../core/types.hpp"

namespace simsr::physics {

template <class S = Scalar>
using Mat9 = Eigen::Matrix<S, 9, 9>;

template <class S = Scalar>
using Vec9 = Eigen::Matrix<S, 9, 1>;

/// What stress_derivative returns.
enum class Definiteness {
  exact,    ///< the true ∂P/∂F (indefinite under compression or inversion)
  project,  ///< Teran et al. 2005's definiteness fix: the eigenvalues of the diagonalized blocks
            ///< clamped at zero, so every element Hessian is positive semi-definite (Newton needs it)
};

/// Per-element data of a material that has none (isotropic models).
struct NoElementData {};

/// A hyperelastic material: energy density ψ(F) per unit rest volume, P = ∂ψ/∂F and ∂P/∂F, all
/// defined for every F including degenerate and inverted ones (materials say how they extend).
template <class M>
concept Material = requires(const M& m, const Mat3<typename M::scalar_type>& F, const typename M::Element& e) {
  typename M::scalar_type;
  typename M::Element;
  { m.energy(F, e) } -> std::convertible_to<typename M::scalar_type>;
  { m.stress(F, e) } -> std::convertible_to<Mat3<typename M::scalar_type>>;
  { m.stress_derivative(F, e, Definiteness::project) } -> std::convertible_to<Mat9<typename M::scalar_type>>;
};

}  // namespace simsr::physics
