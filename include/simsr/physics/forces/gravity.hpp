#pragma once
/// \file
/// Gravity as a potential (SPEC §3 external forces): the body force ρ g per unit rest volume,
/// lumped to vertices (each tet gives ρ |V_t| / 4 to each of its 4 vertices), so
///
///     E(x) = −Σ_i m_i g·x_i                                   (J)
///
///     physics::Gravity<> gravity(lr_rest, 1060.0, Vec3<>(0, -9.81, 0));   // soft tissue, y up
///
/// The energy is linear in x: the gradient is the constant −m_i g and the Hessian is zero.

#include <cmath>
#include <utility>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../../core/types.hpp"
#include "../../mesh/tet_mesh.hpp"
#include "../energy_term.hpp"
#include "detail/checks.hpp"

namespace simsr::physics {

/// Constant body force from lumped vertex masses m (#V, kg) and acceleration g (m/s²).
template <class S = Scalar>
class Gravity {
 public:
  using scalar_type = S;

  /// Masses lumped from the rest mesh: m_i = Σ_{t ∋ i} density · |V_t| / 4 (density in kg/m³;
  /// |V_t| the absolute rest volume, so a mis-oriented tet still weighs). Throws MeshError for a tet
  /// index out of range, ArgumentError for a negative or non-finite density or a non-finite g.
  Gravity(const TetMesh<S>& rest, S density, const Vec3<S>& g) : g_(g) {
    detail::require_nonnegative("Gravity: density", density);
    detail::require_finite_vector("Gravity: g", g);
    detail::require_tets(rest.T, rest.num_vertices());
    detail::require_finite_matrix("Gravity: rest positions", rest.V, rest.num_vertices(), 3);
    m_ = VecX<S>::Zero(rest.num_vertices());
    for (Index t = 0; t < rest.num_tets(); ++t) {
      const auto p = [&](int k) { return Vec3<S>(rest.V.row(rest.T(t, k)).transpose()); };
      const S quarter = density * std::abs((p(1) - p(0)).dot((p(2) - p(0)).cross(p(3) - p(0)))) / S(24);
      for (int k = 0; k < 4; ++k) m_[rest.T(t, k)] += quarter;
    }
  }

  /// Given vertex masses (#V, kg, each finite and ≥ 0).
  Gravity(VecX<S> masses, const Vec3<S>& g) : m_(std::move(masses)), g_(g) {
    detail::require_nonnegative_each("Gravity: masses", m_, m_.size());
    detail::require_finite_vector("Gravity: g", g);
  }

  Index num_vertices() const { return m_.size(); }
  const VecX<S>& masses() const { return m_; }  ///< #V, kg
  S total_mass() const { return m_.sum(); }
  const Vec3<S>& acceleration() const { return g_; }  ///< m/s²
  void set_acceleration(const Vec3<S>& g) {
    detail::require_finite_vector("Gravity: g", g);
    g_ = g;
  }
  /// Per-vertex forces m_i g (#V×3, N): minus the gradient.
  Points<S> forces() const { return m_ * g_.transpose(); }

  /// −Σ m_i g·x_i (J). Sequential (the policy is taken for the EnergyTerm form).
  template <exec::HostPolicy P>
  S energy(P, const Points<S>& x) const {
    detail::require_positions("Gravity: x", x, num_vertices());
    return -(m_.transpose() * (x * g_))(0);
  }
  /// g −= m_i g per vertex (N).
  template <exec::HostPolicy P>
  void add_gradient(P, const Points<S>& x, Points<S>& g) const {
    detail::require_positions("Gravity: x", x, num_vertices());
    detail::require_positions("Gravity: gradient", g, num_vertices());
    g.noalias() -= m_ * g_.transpose();
  }
  /// Adds nothing: the energy is linear.
  template <exec::HostPolicy P>
  void add_hessian(P, const Points<S>& x, BlockHessian<S>&, Definiteness) const {
    detail::require_positions("Gravity: x", x, num_vertices());
  }
  /// Adds nothing to the local–global solver's matrix either (a linear term).
  template <exec::HostPolicy P>
  void add_global_matrix(P, BlockHessian<S>&) const {}

 private:
  VecX<S> m_;
  Vec3<S> g_;
};

static_assert(assert_energy_term<Gravity<double>, double>());

}  // namespace simsr::physics
