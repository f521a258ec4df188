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
#include <type_traits>

#include <Eigen/Core>

#include "../../core/types.hpp"

namespace simsr::physics {

template <class S = Scalar>
using Mat9 = Eigen::Matrix<S, 9, 9>;

template <class S = Scalar>
using Vec9 = Eigen::Matrix<S, 9, 1>;

/// A tet's element stiffness (12×12, vertex-major: rows 3a..3a+2 are vertex a's).
template <class S = Scalar>
using Mat12 = Eigen::Matrix<S, 12, 12>;

/// A tet's shape-function gradients D (4×3): F(i,j) = Σ_a x_a[i] D(a,j) (tet_elements.hpp).
template <class S = Scalar>
using ShapeGradients = Eigen::Matrix<S, 4, 3>;

/// What stress_derivative returns.
enum class Definiteness {
  exact,    ///< the true ∂P/∂F (indefinite under compression or inversion)
  project,  ///< Teran et al. 2005's definiteness fix: the eigenvalues of the diagonalized blocks
            ///< clamped at zero, so every element Hessian is positive semi-definite (Newton needs it)
};

/// Per-element data of a material that has none (isotropic models).
struct NoElementData {};

namespace detail {
template <class M>
concept HasMaterialTypes = requires {
  typename M::scalar_type;
  typename M::Element;
};
template <class M>
concept HasMaterialEnergy = HasMaterialTypes<M> && requires(const M& m, const Mat3<typename M::scalar_type>& F, const typename M::Element& e) {
  { m.energy(F, e) } -> std::convertible_to<typename M::scalar_type>;
};
template <class M>
concept HasMaterialStress = HasMaterialTypes<M> && requires(const M& m, const Mat3<typename M::scalar_type>& F, const typename M::Element& e) {
  { m.stress(F, e) } -> std::convertible_to<Mat3<typename M::scalar_type>>;
};
template <class M>
concept HasMaterialStressDerivative =
    HasMaterialTypes<M> && requires(const M& m, const Mat3<typename M::scalar_type>& F, const typename M::Element& e, Definiteness d) {
      { m.stress_derivative(F, e, d) } -> std::convertible_to<Mat9<typename M::scalar_type>>;
    };
}  // namespace detail

/// A hyperelastic material: energy density ψ(F) per unit rest volume, P = ∂ψ/∂F and ∂P/∂F, all
/// defined for every F including degenerate and inverted ones (materials say how they extend).
template <class M>
concept Material = detail::HasMaterialTypes<M> && detail::HasMaterialEnergy<M> && detail::HasMaterialStress<M> &&
                   detail::HasMaterialStressDerivative<M>;

/// `static_assert(assert_material<M>())`: a type that is not a Material stops the build with one
/// sentence naming the first thing it lacks (and nothing else: the function returns true once its
/// own assertion has spoken).
template <class M>
constexpr bool assert_material() {
  using namespace detail;
  constexpr int lacks = !HasMaterialTypes<M> ? 0 : !HasMaterialEnergy<M> ? 1 : !HasMaterialStress<M> ? 2 : !HasMaterialStressDerivative<M> ? 3 : -1;
  static_assert(lacks != 0, "this type is not a physics::Material: it lacks the member types scalar_type and Element (NoElementData for none)");
  static_assert(lacks != 1, "this type is not a physics::Material: it lacks energy(const Mat3& F, const Element&) const -> scalar_type (psi)");
  static_assert(lacks != 2, "this type is not a physics::Material: it lacks stress(const Mat3& F, const Element&) const -> Mat3 (P = dpsi/dF)");
  static_assert(lacks != 3, "this type is not a physics::Material: it lacks stress_derivative(const Mat3& F, const Element&, Definiteness) const -> Mat9");
  return true;
}

/// A Material whose energy and stress (and element_stiffness, for DeviceElasticEnergy::add_hessian)
/// are SIMSR_HOST_DEVICE, so that DeviceElasticEnergy can call them in a CUDA kernel: it says so
/// with `static constexpr bool device_callable = true;`
/// (NeoHookean, MooneyRivlin, TeranMuscle). An opt-in, since a C++ concept cannot see whether a
/// function is callable on the device; its element data must be plain bytes (copied as such).
template <class M>
concept DeviceMaterial = Material<M> && std::is_trivially_destructible_v<typename M::Element> && requires {
  requires M::device_callable;
};

/// `static_assert(assert_device_material<M>())`: one sentence where M is not a DeviceMaterial.
template <class M>
constexpr bool assert_device_material() {
  static_assert(DeviceMaterial<M>,
                "this material is not a physics::DeviceMaterial: its energy and stress must be SIMSR_HOST_DEVICE and it must declare "
                "static constexpr bool device_callable = true");
  return true;
}

namespace detail {
/// M's scalar_type and Element, or stand-ins when M lacks them (so a class that asserts
/// Material<M> reports that sentence and no follow-on error).
template <class M>
struct material_types {
  using scalar_type = Scalar;
  using Element = NoElementData;
};
template <HasMaterialTypes M>
struct material_types<M> {
  using scalar_type = typename M::scalar_type;
  using Element = typename M::Element;
};
}  // namespace detail

}  // namespace simsr::physics
